"""The VM's narrow surface, fast-forward's state keys, enums, and flashing a file."""
from __future__ import annotations

import ast
import json
import math

import pytest

from helpers.compiling import program_of
from mercmac.compiler import compile_source
from mercmac.compiler.program import Macro
from mercmac.ops import Op, Origin, Role
from mercmac.emulator.virtual import VirtualController
from mercmac.source import Source
from mercmac.upload import chain, flasher
from mercmac.upload.errors import Refused
from mercmac.vm import Machine, Options
from mercmac.vm import reports
from mercmac.vm.skips import Anchor, Loop
from mercmac.vm.machine import Wait
from mercmac.vm.models import DEFAULTS
from helpers.emulator import FAST_TIMING, serve
from helpers.paths import PACKAGE

VM = PACKAGE / "vm"
OUTSIDE_THE_CORE = ("mercmac.errors", "mercmac.cli", "mercmac.render", "mercmac.sim",
                    "mercmac.emulator", "mercmac.upload")


# -- the core raises its own errors and imports no application -------------------------

@pytest.mark.parametrize("path", sorted(VM.glob("*.py")), ids=lambda p: p.name)
def test_the_vm_imports_nothing_of_the_cli_or_the_applications(path):
    tree = ast.parse(path.read_text(encoding="utf-8"))
    imported = [node.module or "" for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)]
    imported += [a.name for node in ast.walk(tree) if isinstance(node, ast.Import) for a in node.names]
    assert not [m for m in imported if m.startswith(OUTSIDE_THE_CORE)]


# -- fast-forward: every field is in its part's state key or excluded with a reason ------

def parts():
    m = Machine(program_of("[MC00] TP,WA10,RP5\n"))
    m.power_on()
    m.run_until(3)
    return {"Machine": m, "Axis": m.axis, "Trigger": m.trigger, "Outputs": m.outputs,
            "Clock": m.clock}


@pytest.mark.parametrize("name", ["Machine", "Axis", "Trigger", "Outputs", "Clock"])
def test_every_field_is_in_the_state_key_or_left_out_with_a_reason(name):
    part = parts()[name]
    keyed, left_out = set(part.STATE_KEY), set(part.NOT_KEYED)
    assert not keyed & left_out, f"{name}: both keyed and left out: {keyed & left_out}"
    missing = set(vars(part)) - keyed - left_out
    assert not missing, (f"{name}: add {sorted(missing)} to STATE_KEY, or to NOT_KEYED with "
                         "the reason a pass may differ in it and still repeat exactly")
    assert not (keyed | left_out) - set(vars(part)), f"{name}: names no field"
    assert all(reason.strip() for reason in part.NOT_KEYED.values())


@pytest.mark.parametrize("name", ["Axis", "Trigger", "Outputs", "Clock"])
def test_a_parts_key_holds_no_value_the_part_could_change_in_place(name):
    part = parts()[name]
    hash(part.state_key())  # a list or dict in it would change with the part, and fail here


def test_a_new_field_fails_the_completeness_check():
    axis = parts()["Axis"]
    axis.backlash = 3  # a field someone adds and forgets
    assert set(vars(axis)) - set(axis.STATE_KEY) - set(axis.NOT_KEYED) == {"backlash"}


def other(value):
    """A different value of the same shape."""
    if isinstance(value, bool):
        return not value
    if isinstance(value, (int, float)):
        return value + 1 if math.isfinite(value) else 0
    if value is None:
        return (1, "x")
    if isinstance(value, list):
        return value + ["x"]
    if isinstance(value, dict):
        return {**value, "ZZ": 1}
    return value + ("x",)


@pytest.mark.parametrize("name", ["Axis", "Trigger", "Outputs", "Clock"])
def test_each_keyed_field_of_a_part_changes_its_key(name):
    part = parts()[name]
    for field in part.STATE_KEY:
        before = part.state_key()
        saved = getattr(part, field)
        setattr(part, field, other(saved))
        assert part.state_key() != before, f"{name}.{field} is not in its key"
        setattr(part, field, saved)


@pytest.mark.parametrize("field", Machine.STATE_KEY)
def test_each_keyed_field_of_the_machine_changes_its_key(field):
    m = parts()["Machine"]
    before = m._state_key(None)
    value = getattr(m, field)
    if field == "chunk":
        m.define(7, [Op("TP")])
        m.chunk = m.chunks[7]
    elif field == "ret":
        m.ret = (m.chunk, 2)
    elif field == "counters":
        m.counters = {**value, 9: {0: 1}}
    elif hasattr(value, "state_key"):  # a part: change its last keyed field (the axis's
        last = value.STATE_KEY[-1]     # first, its profile, gives no key at all)
        setattr(value, last, other(getattr(value, last)))
    else:
        setattr(m, field, other(value))
    assert m._state_key(None) != before


def test_the_jumping_rps_own_counter_stays_out_of_the_key():
    m = parts()["Machine"]
    slot, ip = m.chunk.slot, 2
    m.counters[slot] = {ip: 4}
    before = m._state_key(ip)
    m.counters[slot][ip] = 3
    assert m._state_key(ip) == before and m._state_key(None) != before


# -- the narrow surface the emulator, reports, scenarios and the box use ----------------

def test_stored_macros_setting_and_error():
    m = Machine(program_of("[MC05] MR5000,WS100\n[MC00] EM5\n"))
    assert m.stored_macros() == {0: "EM5", 5: "MR5000,WS100"}
    assert m.setting("DP") == dict(DEFAULTS["C-863"].settings)["DP"] and m.setting("XX") == 0
    m.set_error(0x06)
    assert m.status().endswith(" 06")


def test_self_select_is_taken_once():
    m = Machine(program_of("[MC00] SC3\n"))
    m.power_on()
    m.run_until(5)
    assert m.take_self_select() == 3 and m.take_self_select() is None


def test_moving_label_inputs_and_clock():
    m = Machine(program_of("macro go { MR 100000, WS 0 }\nautostart { call go }\n"),
                cycle_ms=2)
    assert m.label is None and not m.moving() and m.cycle_ms == 2
    m.power_on()
    m.run_until(10)
    assert m.moving() and m.label == "go (MC01)" and m.now_us == 10_000
    m.set_input(3, True)
    assert m.input(3) and m.input_lines()[3] and not m.input_lines()[1]


def test_ve_reports_the_firmware_from_the_options():
    m = Machine(options=Options(firmware="1.06"))
    assert "Ver. 1.06," in reports.report("VE", None, m)
    assert "Ver. 2.30," in reports.report("VE", None, Machine())


def test_the_emulator_reports_its_firmware_without_editing_the_text():
    vc = VirtualController(firmware="1.06")
    assert vc.machine.options.firmware == "1.06"


# -- enumerations that read as their text ------------------------------------------------

def test_roles_and_origins_are_enums_that_print_and_dump_as_before():
    program = compile_source(Source("t.mcm", "macro a { when 1 { MR 5 }\n MR 6 }\n"
                                             "autostart { call a, goto a }\n")).program
    ems = [op for m in program.macros.values() for op in m.ops if op.mnemonic == "EM"]
    assert {type(op.role) for op in ems} == {Role}
    assert {op.role for op in ems} >= {Role.GOTO, Role.HOIST}
    assert {type(m.origin) for m in program.macros.values()} == {Origin}
    assert Origin.WHEN in {m.origin for m in program.macros.values()}
    assert f"{Origin.WHEN}" == str(Origin.WHEN) == "when" and Origin.WHEN == "when"
    assert json.dumps([Role.GOTO, Origin.PART]) == '["goto", "part"]'
    assert hash(Role.CALL) == hash("call") and Op("EM", 1, None, "raw") == Op("EM", 1, None, Role.RAW)
    assert repr(Macro(1, "MC01", origin="stored")) == "Macro(1, 'MC01', '', origin='stored')"


def test_waits_and_loop_anchors_are_enums():
    m = Machine(program_of("[MC00] WN1,RP3\n"))
    m.power_on()
    m.run_until(5)
    assert m.block[0] is Wait.WN
    m = Machine(program_of("[MC00] WA1,RP3\n"))
    m.power_on()
    m.run_until(2)
    assert Anchor(Loop.RP, 0, 1) in m.anchors.visits


# -- flashing a file is one importable call ---------------------------------------------

def test_flash_file_compiles_for_the_model_that_answers(tmp_path):
    source = tmp_path / "p.mcm"
    source.write_text("[MC03] MR200\n")
    seen = []

    class Watch(chain.Watch):
        def identified(self, part, warning):
            seen.append((part.identity.version.model, warning))

        def finished(self, result):
            seen.append("finished")

    with serve(macros={7: "TP"}) as (server, vc):
        result = chain.flash_chain(server.path, str(source), timing=FAST_TIMING,
                                   options=flasher.FlashOptions(backup=tmp_path / "b.mcm"),
                                   watch=Watch()).parts[0].result
        assert vc.macros == {3: "MR200", 7: "TP"}
    assert seen == [("C-863", None), "finished"] and result.backup == tmp_path / "b.mcm"


def test_flash_file_refuses_a_file_with_errors_for_the_model_that_answers(tmp_path):
    source = tmp_path / "p.mcm"
    source.write_text("[MC03] DC100\n")  # DC is a C-663 command
    refused = []

    class Watch(chain.Watch):
        def refused(self, findings):
            refused.append(findings[0].compilation.report.has_errors)

    with serve() as (server, vc):
        with pytest.raises(Refused, match="has errors for the C-863; nothing was flashed"):
            chain.flash_chain(server.path, str(source), timing=FAST_TIMING, watch=Watch())
        assert vc.md_count == 0
    assert refused == [True]


def test_flash_file_of_a_program_for_another_model(tmp_path):
    source = tmp_path / "p.mcm"
    source.write_text("target C-663\n[MC03] MR200\n")
    with serve() as (server, vc):
        with pytest.raises(Refused, match="targets the C-663"):
            chain.flash_chain(server.path, str(source), timing=FAST_TIMING)
        result = chain.flash_chain(server.path, str(source), timing=FAST_TIMING, force=True,
                                   options=flasher.FlashOptions(backup=tmp_path / "b.mcm"))
        result = result.parts[0].result
        assert vc.macros == {3: "MR200"} and result.identity.version.model == "C-863"
