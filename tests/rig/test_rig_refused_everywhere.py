"""One rig, one answer (docs/rigs.md): `sim`, `describe`, `emulate --rig` and
`flash` refuse every rig that `check` finds errors in, each rule in turn, showing what
`check` shows, and exit 1 as `sim FILE` with errors does; nothing is simulated, described,
served or flashed. They used to run 19 of 168 such variants (addresses, models, SC in macro
0, an input driven twice, an impossible joystick); `emulate --rig` refused 4 rules only."""
from __future__ import annotations

import subprocess
import sys

import pytest

from helpers.cli import cli
from helpers.rigs import WIRES, X, Y, controllers, write_rig

JOYSTICK = WIRES + controllers() + "[joystick]\n"
# (the rule check reports, the rig file's TOML or None for the default, x.mcm, y.mcm)
VARIANTS = {
    "MR001 rig-file": (WIRES + controllers().replace("address = 1", "adress = 1"), X, Y),
    "MR002 rig-program": (WIRES + controllers().replace('"y.mcm"', '"none.mcm"'), X, Y),
    "MR003 rig-wire": ('wires = ["x.in1 -> y.in1"]\n' + controllers(), X, Y),
    "MR004 address-range": (WIRES + controllers(y="16"), X, Y),
    "MR005 address-repeated": (WIRES + controllers(y="0"), X, Y),
    "MR006 model-mismatch": (None, X, Y.replace("C-663", "C-863")),
    "MR007 select-networked": (None, X.replace("autostart {", "autostart { SC 0,"), Y),
    "MR008 input-driven-twice": ('wires = ["x.out1 -> y.in1", "y.out2 -> x.in2", '
                                 '"x.out2 -> y.in1"]\n' + controllers(),
                                 X.replace("CN 1,", "CN 1, CN 2,"), Y),
    "MR008 input-driven-twice (a box button)": ('box = "x"\n' + WIRES + controllers(), X, Y),
    "MR012 joystick-branch (no power)": (JOYSTICK + 'Y = "y"\n', X, Y),
    "MR012 joystick-branch (one socket)": (JOYSTICK + 'X = "x"\nY = "x"\n', X, Y),
    "MM003 a program's own error": (None, X, Y.replace("MR 10", "MR")),
}


@pytest.fixture(params=VARIANTS, ids=list(VARIANTS))
def refused(request, tmp_path):
    """A rig with one error, and what `check` says of it (its text, on standard output)."""
    toml, x, y = VARIANTS[request.param]
    path = write_rig(tmp_path, toml, x=x, y=y)
    checked = cli("check", path)
    assert checked.exit_code == _exit(request.param) and request.param.split()[0] in checked.stdout
    return path, checked.stdout


def _exit(variant: str) -> int:
    """1 for a rig with errors; 2 for a program that cannot be read (I/O, item 15)."""
    return 2 if variant.startswith("MR002") else 1


def _said_as_check(result, check_text: str) -> None:
    assert result.exit_code == (2 if "MR002" in check_text else 1), result.output
    assert check_text in result.stderr
    assert "Traceback" not in result.output


def test_sim_refuses_it_and_simulates_nothing(refused):
    path, check_text = refused
    result = cli("sim", path, "--until", "1s", catch=True)
    _said_as_check(result, check_text)
    assert result.stdout == ""  # no timeline, no summary


def test_describe_refuses_it_and_describes_nothing(refused):
    path, check_text = refused
    result = cli("describe", path, catch=True)
    _said_as_check(result, check_text)
    assert result.stdout == ""


def test_flash_refuses_it_before_the_port_opens(refused, data_dir):
    path, check_text = refused
    result = cli("flash", "/nonexistent/port", path, catch=True)  # a port never opened
    _said_as_check(result, check_text)
    assert "nothing was flashed" in result.stderr and "cannot open" not in result.output


def test_emulate_rig_refuses_it_and_serves_nothing(refused):
    path, check_text = refused
    # a process: a rig that is served would never end (in-process, the test would hang)
    done = subprocess.run([sys.executable, "-m", "mercmac", "emulate", "--rig", str(path)],
                          capture_output=True, text=True, timeout=30)
    assert done.returncode == (2 if "MR002" in check_text else 1), done.stderr
    assert check_text in done.stderr and "nothing is served" in done.stderr
    assert done.stdout == ""  # no "virtual chain ..." line, no pty


def test_warnings_alone_do_not_stop_a_run(tmp_path):
    """A warning (MR009: a wire from an output never set) is no error: the rig runs."""
    path = write_rig(tmp_path, y=Y.replace("CN 2,", "CF 2,"))
    assert "MR009" in cli("check", path).stdout
    assert cli("sim", path, "--until", "1s", catch=True).exit_code == 0
    assert cli("describe", path, catch=True).exit_code == 0


def _with_settings(folder, ignore: str, y: str = Y):
    folder.mkdir()
    (folder / "mercmac.toml").write_text(f"ignore = [{ignore}]\n", encoding="utf-8")
    return write_rig(folder, WIRES + controllers(y="0"), y=y)


def test_a_settings_file_applies_as_for_check(tmp_path):
    """The rig's settings file turns a rig rule off for `check`, and so for `sim`: one rig,
    one answer."""
    path = _with_settings(tmp_path / "a", '"address-repeated"')
    assert cli("check", path).exit_code == 0
    assert cli("sim", path, "--until", "1s", catch=True).exit_code == 0


def test_an_error_the_settings_turn_off_still_stops_a_run(tmp_path):
    """A program with an error is not run, the settings notwithstanding, as `sim FILE`
    (which reads no settings) refuses it; the error is shown, to say why."""
    path = _with_settings(tmp_path / "b", '"address-repeated", "bad-argument"',
                          y=Y.replace("MR 10", "MR"))
    assert cli("check", path).exit_code == 0
    result = cli("sim", path, "--until", "1s", catch=True)
    assert result.exit_code == 1 and "y.mcm:2:" in result.stderr and result.stdout == ""


def test_a_rig_file_that_cannot_be_read_is_said_as_check_says_it(tmp_path):
    missing = tmp_path / "none.rig.toml"
    said = cli("check", missing).stderr.strip()
    assert said.startswith("mercmac: cannot read")
    for args in (("sim", missing), ("describe", missing), ("emulate", "--rig", missing)):
        result = cli(*args, catch=True)
        assert result.exit_code == 2 and result.stderr.strip() == said, args


def test_accepted_programs_are_each_controllers_own_compilation(tmp_path):
    """Two controllers may run one file: each gets it compiled with its own model, the very
    compilation `check` made (not a second one)."""
    from mercmac.rig.open import accept

    program = "autostart { MR 100, WS 0, CN 1 }\n"  # no `target`: the rig's model decides
    toml = controllers().replace('"y.mcm"', '"x.mcm"').replace(
        'address = 1\nmodel = "C-663"', 'address = 1\nmodel = "C-863"')
    path = write_rig(tmp_path, toml, x=program)
    accepted = accept(str(path))
    assert {name: c.program.target for name, c in accepted.programs.items()} == {
        "x": "C-663", "y": "C-863"}
    assert [f.compilation for f in accepted.findings[1:]] == list(accepted.programs.values())
