"""The rig rules (MR004-MR011, mercmac/rig/checks.py): each found on a rig built for it, at
its place, and none on the bundled raster example (docs/rigs.md)."""
from __future__ import annotations

import pytest

from mercmac.compiler import checking
from mercmac.diagnostics import RULES
from mercmac.rig.open import accept
from mercmac.rig.open import open_rig
from helpers.rigs import DEAD_X, DEAD_Y, RASTER, WIRES, X, Y, controllers, write_rig

RIG_CODES = {r.code for r in RULES if r.code.startswith("MR")}


def _found(path, **options) -> list[tuple[str, str, int, int, str]]:
    """(code, file name, line, column, message) of every diagnostic `check` reports."""
    return [(d.rule.code, d.file.rsplit("/", 1)[-1], d.span.line, d.span.column, d.message)
            for findings in open_rig(str(path), checking.options(**options)).findings
            for d in findings.diagnostics]


def _codes(path) -> list[str]:
    return [code for code, *_ in _found(path)]


def test_the_raster_example_checks_clean():
    assert _found(RASTER) == []


def test_the_token_rig_of_these_tests_checks_clean(tmp_path):
    assert _found(write_rig(tmp_path)) == []


def test_an_address_out_of_range(tmp_path):
    found = _found(write_rig(tmp_path, WIRES + controllers(y="16")))
    assert ("MR004", "r.rig.toml", 7, 1) in [f[:4] for f in found]


def test_an_address_used_twice(tmp_path):
    found = _found(write_rig(tmp_path, WIRES + controllers(y="0")))
    assert [f[:4] for f in found if f[0] == "MR005"] == [("MR005", "r.rig.toml", 7, 1)]
    assert "y has address 0, as x has" in found[0][4]


def test_a_program_whose_target_differs_from_the_model(tmp_path):
    found = _found(write_rig(tmp_path, y=Y.replace("C-663", "C-863")))
    assert ("MR006", "r.rig.toml", 8, 1) in [f[:4] for f in found]


def test_each_program_is_checked_with_its_controllers_model(tmp_path):
    # no `target` line: DD (a C-863 gain, MS176E §6.4 DD) is refused on the rig's C-663
    path = write_rig(tmp_path, x=X.replace("target C-663\n", "").replace("MR 100,", "DD 10, MR 100,"))
    assert [f[:2] for f in _found(path)] == [("MM010", "x.mcm")]
    programs = {c: comp.program.target for c, comp in accept(
        str(write_rig(tmp_path, x=X.replace("target C-663\n", "")))).programs.items()}
    assert programs == {"x": "C-663", "y": "C-663"}


def test_sc_in_macro_0_of_a_chain(tmp_path):
    found = _found(write_rig(tmp_path, x=X.replace("autostart { goto go }",
                                                   "autostart { SC 0, goto go }")))
    assert [f[:4] for f in found if f[0] == "MR007"] == [("MR007", "x.mcm", 3, 13)]


def test_sc_in_macro_0_of_a_single_controller_is_fine(tmp_path):
    toml = controllers().split("[controllers.y]")[0]
    path = write_rig(tmp_path, toml, x="target C-663\nautostart { SC 0, MR 10 }\n")
    assert "MR007" not in _codes(path)


def test_an_input_driven_by_two_wires(tmp_path):
    toml = 'wires = ["x.out1 -> y.in1", "y.out2 -> x.in2",\n  "x.out2 -> y.in1"]\n'
    found = _found(write_rig(tmp_path, toml + controllers(),
                             x=X.replace("CN 1,", "CN 1, CN 2,")))
    assert [f[:4] for f in found if f[0] == "MR008"] == [("MR008", "r.rig.toml", 2, 3)]


def test_an_input_driven_by_a_wire_and_a_box_button(tmp_path):
    found = _found(write_rig(tmp_path, 'box = "x"\n' + WIRES + controllers()))
    assert [f[:4] for f in found if f[0] == "MR008"] == [("MR008", "r.rig.toml", 2, 29)]
    assert "button 2 of the C-170.PB box" in found[0][4]


def test_an_unconnected_box_button_drives_nothing(tmp_path):
    path = write_rig(tmp_path, 'box = "x"\nbox_buttons = [1]\n' + WIRES + controllers())
    assert "MR008" not in _codes(path)


def test_a_wire_from_an_output_the_program_never_sets(tmp_path):
    found = _found(write_rig(tmp_path, y=Y.replace("CN 2,", "CF 2,")))
    assert ("MR009", "r.rig.toml", 1, 29) in [f[:4] for f in found]


def test_a_cp_pattern_or_a_trigger_mode_sets_an_output(tmp_path):
    toml = 'wires = ["x.out1 -> y.in1", "y.out4 -> x.in2"]\n' + controllers()
    path = write_rig(tmp_path, toml, x=X.replace("CN 1,", "CP 3,"),
                     y=Y.replace("CN 2,", "ZM 1,"))
    assert "MR009" not in _codes(path)


def test_an_input_read_that_nothing_drives(tmp_path):
    found = _found(write_rig(tmp_path, x=X.replace("WF 2,", "WF 2, XN 3,")))
    assert [f[:4] for f in found if f[0] == "MR010"] == [("MR010", "x.mcm", 2, 50)]
    assert "x reads input 3 (XN3)" in found[0][4]


def test_an_input_the_box_drives_is_driven(tmp_path):
    path = write_rig(tmp_path, 'box = "x"\nbox_buttons = [3]\n' + WIRES + controllers(),
                     x=X.replace("WF 2,", "WF 2, XN 3,"))
    assert "MR010" not in _codes(path)


def test_a_wait_cycle_in_the_wiring(tmp_path):
    found = _found(write_rig(tmp_path, x=DEAD_X, y=DEAD_Y))
    assert [f[:4] for f in found] == [("MR011", "r.rig.toml", 1, 29)]
    assert "x's go (MC01) waits for x.in2 before raising x.out1, and y's go (MC01) waits " \
        "for y.in1 before raising y.out2" in found[0][4]


def test_a_wf_on_a_line_no_one_raised_passes_at_once(tmp_path):
    assert _codes(write_rig(tmp_path, x=DEAD_X.replace("WN 2", "WF 2"), y=DEAD_Y)) == []


def test_a_wait_cycle_over_three_controllers(tmp_path):
    toml = ('wires = ["x.out1 -> y.in1", "y.out1 -> z.in1", "z.out1 -> x.in1"]\n' + controllers()
            + '[controllers.z]\naddress = 2\nmodel = "C-663"\nprogram = "z.mcm"\n')
    dead = "target C-663\nmacro go { WN 1, CN 1, goto go }\nautostart { goto go }\n"
    (tmp_path / "z.mcm").write_text(dead, encoding="utf-8")
    assert _codes(write_rig(tmp_path, toml, x=dead, y=dead)) == ["MR011"]


def test_a_side_that_sets_its_line_first_breaks_the_cycle(tmp_path):
    first = DEAD_X.replace("autostart { goto go }", "autostart { CN 1, goto go }")
    assert "MR011" not in _codes(write_rig(tmp_path, x=first, y=DEAD_Y))


def test_a_missing_program(tmp_path):
    path = write_rig(tmp_path)
    (tmp_path / "y.mcm").unlink()
    found = _found(path)
    assert [f[:4] for f in found] == [("MR002", "r.rig.toml", 9, 1)]


def test_program_diagnostics_come_with_the_programs_file(tmp_path):
    found = _found(write_rig(tmp_path, y=Y.replace("MR 10", "MR")))
    assert [f[:2] for f in found] == [("MM003", "y.mcm")]


def test_select_and_ignore_take_rig_rules(tmp_path):
    path = write_rig(tmp_path, WIRES + controllers(y="0"), x=DEAD_X, y=DEAD_Y)
    assert sorted(_codes(path)) == ["MR005", "MR011"]
    assert [f[0] for f in _found(path, select=["wait-cycle"])] == ["MR011"]
    assert [f[0] for f in _found(path, ignore=["MR011"])] == ["MR005"]


@pytest.mark.parametrize("code", sorted(RIG_CODES))
def test_every_rig_rule_has_a_story_citing_the_manual(code):
    r = next(r for r in RULES if r.code == code)
    assert "MS176E §" in r.explanation or code in ("MR001", "MR002"), code


def test_a_comment_in_the_program_turns_a_rig_rule_off_there(tmp_path):
    x = X.replace("WF 2,", "WF 2, XN 3,").replace("goto go }\nautostart",
                                                 "goto go } // mercmac: ignore[input-undriven]\nautostart")
    assert _codes(write_rig(tmp_path, x=x)) == []
    assert sorted(_codes(write_rig(tmp_path, x=x.replace("input-undriven", "input-undrivn")))) == \
        ["MM034", "MR010"]


def test_a_y_branch_without_an_x_branch_has_no_power(tmp_path):
    found = _found(write_rig(tmp_path, WIRES + '[joystick]\nY = "y"\n' + controllers()))
    assert [f[:4] for f in found] == [("MR012", "r.rig.toml", 3, 1)]
    assert "power" in found[0][4]


def test_two_branches_to_one_controller(tmp_path):
    found = _found(write_rig(tmp_path, WIRES + '[joystick]\nX = "x"\nY = "x"\n' + controllers()))
    assert [f[:4] for f in found] == [("MR012", "r.rig.toml", 4, 1)]


def test_a_joystick_on_both_branches_is_fine(tmp_path):
    assert _codes(write_rig(tmp_path, WIRES + '[joystick]\nX = "x"\nY = "y"\n' + controllers())) \
        == []


# x waits on in3, which no wire and no box button drives, before it raises
# the line y waits on: a sure dead-lock, reported at x's wait
STUCK_X = "target C-663\nautostart { WN 3, CN 1 }\n"
WAITING_Y = "target C-663\nautostart { WN 1, CN 2 }\n"


def test_a_sure_dead_lock_on_an_input_nothing_drives(tmp_path):
    found = sorted(_found(write_rig(tmp_path, x=STUCK_X, y=WAITING_Y)))
    assert [f[:4] for f in found] == [("MR010", "x.mcm", 2, 13), ("MR011", "x.mcm", 2, 13)]
    assert found[1][4] == (
        "dead-lock: x waits for x.in3 (WN3) in autostart (MC00), which no wire or box button "
        "drives; y waits for y.in1 (WN1) in autostart (MC00), from x.out1, which x does not "
        "raise before it waits too; no controller goes on")


def test_a_controller_that_ends_takes_part_in_a_sure_dead_lock(tmp_path):
    # y ends at once; x waits on in3 for good
    found = _found(write_rig(tmp_path, x=STUCK_X, y="target C-663\nautostart { CN 2 }\n"))
    (stuck,) = [f for f in found if f[0] == "MR011"]
    assert stuck[1:4] == ("x.mcm", 2, 13) and "; y ends; no controller goes on" in stuck[4]


def test_a_rig_of_one_waiting_on_an_input_nothing_drives(tmp_path):
    (tmp_path / "s.mcm").write_text("target C-663\nautostart { WN 4 }\n", encoding="utf-8")
    path = tmp_path / "one.rig.toml"
    path.write_text('[controllers.s]\naddress = 0\nmodel = "C-663"\nprogram = "s.mcm"\n',
                    encoding="utf-8")
    assert sorted(_codes(path)) == ["MR010", "MR011"]


@pytest.mark.parametrize("toml, x, y", [
    # a button of the box on x's in3: a person may press it
    ('box = "x"\nbox_buttons = [3]\n' + WIRES + controllers(), STUCK_X, WAITING_Y),
    # x raises out1 before it waits: y goes on, and what it does then is not followed
    (None, "target C-663\nautostart { CN 1, WN 3 }\n", WAITING_Y),
    # the wait stands behind a condition: it may not be reached
    (None, "target C-663\nautostart { XN 4, WN 3, CN 1 }\n", WAITING_Y),
    # y runs on in a loop without a wait: it may change anything
    (None, STUCK_X, "target C-663\nmacro go { TP, WA 10, goto go }\nautostart { goto go }\n"),
    # a repeated line with a call in it may go elsewhere the second time
    (None, "target C-663\nmacro m { CN 1 }\nautostart { EM 1, RP 2, WN 3 }\n", WAITING_Y),
    # a WF on a wired input may pass or wait: not sure
    (None, "target C-663\nautostart { WF 2, WN 3, CN 1 }\n", WAITING_Y),
])
def test_no_sure_dead_lock_where_a_wait_may_end(tmp_path, toml, x, y):
    assert "MR011" not in _codes(write_rig(tmp_path, toml, x=x, y=y))
