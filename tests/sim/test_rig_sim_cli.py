"""`mercmac sim RIG` (docs/rigs.md) through click's CliRunner and as a process:
named timeline lines, JSON per controller with the wires' edges, buttons by controller,
the joystick, --fail-on-hazard on a dead-locked rig, a VCD with a scope per controller."""
from __future__ import annotations

import json
import re

import pytest

from helpers.cli import cli, mercmac_process, sim
from helpers.paths import ROOT
from helpers.rigs import RASTER, rig_of

SPEC_KEYS = {"until_ms", "halted", "final", "reports", "outputs", "hazards", "events"}


def test_the_timeline_names_each_controller_and_shows_the_wires():
    result = sim(RASTER, "--buttons", "x:1@0-100ms", "--until", "3s")
    assert result.exit_code == 0, result.output
    lines = result.output.splitlines()
    assert any(" x  move to 20000 from 0" in line for line in lines)
    assert any(" y  move to 500 from 0" in line for line in lines)
    assert any("wire x.out1 -> y.in1 ON" in line for line in lines)
    # the wired input is the wire's line, not a "button" of y
    assert not any(" y  button" in line for line in lines)
    assert "x Summary" in result.output and "y Summary" in result.output


def test_json_has_one_spec_object_per_controller_and_the_edges():
    result = sim(RASTER, "--buttons", "x:1@0-100ms", "--until", "3s", "--format", "json")
    assert result.exit_code == 0, result.output
    out = json.loads(result.output)
    assert set(out["controllers"]) == {"x", "y"}
    for run in out["controllers"].values():
        assert SPEC_KEYS <= set(run) and run["until_ms"] == 3000
    assert out["controllers"]["y"]["final"]["position"] == 1000
    assert out["edges"][0] == {"t_ms": 1118, "wire": "x.out1 -> y.in1", "source": "x.out1",
                               "target": "y.in1", "level": True}


def test_buttons_without_a_name_go_to_the_box_controller():
    named = sim(RASTER, "--buttons", "x:1@0-100ms", "--until", "3s", "--format", "json")
    plain = sim(RASTER, "--buttons", "1@0-100ms", "--until", "3s", "--format", "json")
    assert plain.exit_code == 0 and plain.output == named.output
    idle = json.loads(sim(RASTER, "--until", "3s", "--format", "json").output)
    assert idle["edges"] == []  # without button 1 the scan never starts


def test_buttons_on_an_unknown_controller_are_a_usage_error():
    result = sim(RASTER, "--buttons", "z:1@0")
    assert result.exit_code == 2
    assert "no controller 'z'" in result.output and "x, y" in result.output


def test_fail_on_hazard_exits_1_on_a_dead_locked_rig(tmp_path):
    path = rig_of(tmp_path, "macro hello { WN 2, CN 1 }\nautostart { goto hello }\n",
                  "macro answer { WN 1, CN 2 }\nautostart { goto answer }\n",
                  '"x.out1 -> y.in1", "y.out2 -> x.in2"')
    result = sim(path, "--fail-on-hazard", "--until", "1s")
    assert result.exit_code == 1
    assert "dead-lock" in result.output and "hello (MC01)" in result.output
    assert "answer (MC01)" in result.output and "hazards found (--fail-on-hazard)" in result.output
    assert sim(path, "--until", "1s").exit_code == 0


def test_fail_on_hazard_exits_1_on_a_dead_lock_on_an_input_nothing_drives(tmp_path):
    # x waits on in3, which no wire and no box button drives
    path = rig_of(tmp_path, "autostart { WN 3, CN 1 }\n", "autostart { WN 1, CN 2 }\n",
                  '"x.out1 -> y.in1", "y.out2 -> x.in2"')
    assert cli("check", str(path)).exit_code == 0  # warnings and info, no errors
    result = sim(path, "--fail-on-hazard", "--until", "1s", "--format", "json")
    assert result.exit_code == 1
    out = json.loads(result.stdout)["controllers"]
    for name in ("x", "y"):
        (hazard,) = out[name]["hazards"]
        assert hazard["rule"] == "rig-deadlock" and "in3 ON (no wire or box button" in \
            hazard["message"]


def test_the_joystick_moves_the_controller_of_its_branch(tmp_path):
    path = rig_of(tmp_path, "autostart { JN 8000 }\n", "autostart { JN 8000 }\n", "",
                  '[joystick]\nX = "x"\nY = "y"\n')
    result = sim(path, "--joystick", "x=+1@1s-2s,Y=-1@1s-2s", "--until", "4s",
                 "--format", "json")
    assert result.exit_code == 0, result.output
    out = json.loads(result.output)["controllers"]
    assert out["x"]["final"]["position"] > 7000 and out["y"]["final"]["position"] < -7000
    bad = sim(path, "--joystick", "x=2@1s")
    assert bad.exit_code == 2 and "from -1 to 1" in bad.output


def _docs_joystick_examples() -> set[tuple[str, str]]:
    """(rig file, `--joystick` spec) of the examples in the README and docs/rigs.md."""
    found = set()
    for page in (ROOT / "README.md", ROOT / "docs" / "rigs.md"):
        text = page.read_text(encoding="utf-8")
        found |= set(re.findall(r'mercmac sim (\S+) --joystick "([^"]+)"', text))
    return found


def test_the_docs_joystick_example_runs_on_the_bundled_raster():
    """It was refused (the raster had no [joystick] table); with one, +0.5 on x read as
    "joystick pressed" and -1 on branch Y showed nothing at all."""
    ((path, spec),) = _docs_joystick_examples()
    assert (ROOT / path) == RASTER and spec == "x=+0.5@1s-3s,Y=-1@4s"  # a controller, a branch
    result = sim(RASTER, "--joystick", spec)
    assert result.exit_code == 0, result.output
    lines = result.stdout.splitlines()
    off = "commands nothing, joystick control is off (no JN)"  # the raster never sends JN
    assert f"1.000 s  x  joystick at +0.50 (input 5 ON): {off}" in result.stdout
    assert f"3.000 s  x  joystick back in the middle (input 5 OFF): {off}" in result.stdout
    assert f"4.000 s  y  joystick at -1.00 (input 5 OFF): {off}" in result.stdout
    assert not any("joystick pressed" in line or "joystick released" in line for line in lines)
    shown = (ROOT / "docs" / "rigs.md").read_text(encoding="utf-8").split("```text\n", 1)[1]
    assert shown.split("```", 1)[0].splitlines() == [line for line in lines if "joystick" in line]
    out = json.loads(sim(RASTER, "--joystick", spec, "--format", "json").stdout)
    (moved,) = [e for e in out["controllers"]["y"]["events"] if e["kind"] == "joystick"]
    assert moved == {"t_ms": 4000, "kind": "joystick", "deflection": -1.0, "velocity": 0.0,
                     "jn": 0, "table": 1}


def test_the_timeline_says_the_velocity_a_deflection_commands(tmp_path):
    # JN 8000 through the cubic table (MS176E §6.4 JT, the factory default): half a
    # deflection is 8000 * 0.5**3 = 1000 steps/s (C-663s); full the other way, -8000
    path = rig_of(tmp_path, "autostart { JN 8000 }\n", "autostart { JN 8000 }\n", "",
                  '[joystick]\nX = "x"\nY = "y"\n')
    result = sim(path, "--joystick", "x=+0.5@1s-2s,Y=-1@1s-2s", "--until", "3s")
    assert result.exit_code == 0, result.output
    said = result.stdout
    assert "x  joystick at +0.50 (input 5 ON): commands +1,000 steps/s (JN 8000, cubic table)" \
        in said
    assert "y  joystick at -1.00 (input 5 OFF): commands -8,000 steps/s (JN 8000, cubic table)" \
        in said
    assert "x  joystick back in the middle (input 5 OFF): commands 0 steps/s" in said


@pytest.mark.parametrize("toml, words", [
    ("", "Y is a joystick branch, and the rig has no [joystick] table"),
    ('[joystick]\nX = "x"\n', 'the rig\'s [joystick] table has no branch Y (only X = "x")'),
])
def test_a_branch_the_rig_does_not_connect_is_said_to_be_a_branch(tmp_path, toml, words):
    """It said "the rig has no controller 'Y' (x, y)", as if Y were no spelling at all."""
    path = rig_of(tmp_path, "autostart { WA 1 }\n", "autostart { WA 1 }\n", "", toml)
    result = sim(path, "--joystick", "Y=-1@4s")
    assert result.exit_code == 2, result.output
    assert words in result.stderr and "Traceback" not in result.output


def test_a_program_alone_has_its_joystick_on_branch_x(tmp_path):
    single = tmp_path / "a.mcm"
    single.write_text("autostart { JN 1000 }\n", encoding="utf-8")
    result = sim(single, "--joystick", "x=1@0")
    assert result.exit_code == 2 and "a program alone has one joystick, on branch X" in result.output
    assert sim(single, "--joystick", "X=1@0").exit_code == 0


def test_the_vcd_has_a_scope_per_controller(tmp_path):
    out = tmp_path / "raster.vcd"
    result = sim(RASTER, "--buttons", "x:1@0-100ms", "--until", "5s", "--vcd", out)
    assert result.exit_code == 0, result.output
    text = out.read_text(encoding="ascii")
    assert "$scope module x $end" in text and "$scope module y $end" in text
    times = [int(line[1:]) for line in text.splitlines() if line.startswith("#")]
    assert times == sorted(times) and times[-1] == 5_000_000


def test_an_hour_of_the_raster_as_a_process(tmp_path):
    done = mercmac_process("sim", str(RASTER), "--buttons", "x:1@0-100ms", "--until", "1h",
                           "--format", "json", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    out = json.loads(done.stdout)
    # 1 row (500 counts) per line: about 2.45 s a pair of lines
    assert out["controllers"]["y"]["final"]["target"] == 1_470_000
    assert len(out["edges"]) == 10_000 and out["truncated"]["edges"] > 0


def test_the_timeline_of_a_skipped_hour_never_goes_back():
    # the skip is one line per controller; the wire edges of its passes are in the JSON only
    result = sim(RASTER, "--buttons", "x:1@0-100ms", "--until", "1h")
    assert result.exit_code == 0, result.output
    times = [_seconds(m.group(1)) for m in map(DATED.match, result.output.splitlines()) if m]
    assert times == sorted(times) and times[-1] == 3600
    skips = [line for line in result.output.splitlines() if "fast-forward" in line]
    assert len(skips) == 2 and all("to 0:59:58.812" in line for line in skips)
    wires_after = [line for line in result.output.splitlines()
                   if DATED.match(line) and " wire " in line and _seconds(line.split()[0]) > 7]
    assert not wires_after
    # what the cap leaves out is told, counting no edge of the skipped passes
    assert "... 1 more line after 0:59:59.922" in result.output


DATED = re.compile(r" {2,}([\d:]+\.\d{3})(?: s)?  ")  # a timeline line's time column


def _seconds(clock: str) -> float:
    """'6.129' or '0:59:58.812' in seconds."""
    parts = [float(p) for p in clock.split(":")]
    return sum(p * 60 ** i for i, p in enumerate(reversed(parts)))


SCENARIO = """\
[[step]]
at = "0ms"
press = [1]
[[step]]
at = "100ms"
release = [1]
[[expect]]
controller = "y"
within = ["1s", "1.3s"]
position = 500
[[expect]]
controller = "x"
at = "1.5s"
macro = "scan"
[[expect]]
controller = "y"
at = "5s"
position = POSITION
"""


def test_a_scenario_expects_per_controller(tmp_path):
    good = tmp_path / "good.toml"
    good.write_text(SCENARIO.replace("POSITION", "[1900, 2100]"), encoding="utf-8")
    result = sim(RASTER, "--scenario", good)
    assert result.exit_code == 0, result.output
    assert "all 3 expectations met" in result.output
    bad = tmp_path / "bad.toml"
    bad.write_text(SCENARIO.replace("POSITION", "[100, 200]"), encoding="utf-8")
    failed = sim(RASTER, "--scenario", bad)
    assert failed.exit_code == 1
    assert "expectation 3 (at 5000 ms) on y failed: position is 2000" in failed.output


def test_a_scenario_naming_no_such_controller_is_refused(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text('[[expect]]\ncontroller = "z"\nat = "1s"\nrunning = true\n',
                    encoding="utf-8")
    result = sim(RASTER, "--scenario", path)
    assert result.exit_code == 2 and "no controller of that name (x, y)" in result.output


def test_a_controller_in_a_single_controllers_scenario_is_refused(tmp_path):
    program = tmp_path / "a.mcm"
    program.write_text("autostart { CN 1 }\n", encoding="utf-8")
    path = tmp_path / "s.toml"
    path.write_text('[[expect]]\ncontroller = "y"\nat = "1s"\noutputs = 1\n', encoding="utf-8")
    result = sim(program, "--scenario", path)
    assert result.exit_code == 2 and "is for a rig file" in result.output


def test_a_program_with_errors_is_not_simulated(tmp_path):
    path = rig_of(tmp_path, "autostart { MR }\n", "autostart { CN 1 }\n", "")
    result = sim(path)
    assert result.exit_code == 1
    assert "x.mcm:2:" in result.output and "Simulating" not in result.output


# -- what a person can press (docs/rigs.md) -----------------------------------------------------
# The raster's box is plugged into x with buttons 1 and 3 connected; x.in2 is wired from y.out2.

@pytest.mark.parametrize("press, words", [
    ("y:1@0-100ms", "the box is plugged into x"),  # the box is not on y
    ("x:2@1s", "driven by the wire y.out2 -> x.in2"),  # the run mixed both on one line
    ("x:4@1s", "button 4 of the box is not connected to x (box_buttons = [1, 3])"),
    ("x:1@0-100ms,x:1+2@2s", "driven by the wire y.out2 -> x.in2"),
])
def test_buttons_press_only_what_the_rig_lets_a_person_press(press, words):
    result = sim(RASTER, "--buttons", press, "--until", "3s")
    assert result.exit_code == 2, result.output
    assert words in result.stderr and result.stdout == "" and "Traceback" not in result.output


def test_the_joystick_inputs_are_pressed_only_where_a_branch_goes(tmp_path):
    path = rig_of(tmp_path, "autostart { WN 5, CN 1 }\n", "autostart { CN 1 }\n", "")
    result = sim(path, "--buttons", "x:5@1s", "--until", "3s")
    assert result.exit_code == 2, result.output
    assert "no joystick branch goes to x" in result.stderr and "Traceback" not in result.output


def test_the_joystick_inputs_are_pressed_where_a_branch_goes(tmp_path):
    path = rig_of(tmp_path, "autostart { every 20ms { when 6 { CN 1 } } }\n",
                  "autostart { CN 1 }\n", "", '[joystick]\nX = "x"\n')
    result = sim(path, "--buttons", "x:6@1s-2s", "--until", "3s", "--format", "json")
    assert result.exit_code == 0, result.output
    assert json.loads(result.output)["controllers"]["x"]["outputs"], result.output
    refused = sim(path, "--buttons", "y:6@1s", "--until", "3s")
    assert refused.exit_code == 2 and "no joystick branch goes to y" in refused.stderr


def test_buttons_on_a_rig_without_a_box_are_refused(tmp_path):
    path = rig_of(tmp_path, "autostart { WN 1, CN 1 }\n", "autostart { CN 1 }\n", "")
    for press in ("1@1s", "x:1@1s"):
        result = sim(path, "--buttons", press)
        assert result.exit_code == 2 and "the rig has no box" in result.stderr, press


@pytest.mark.parametrize("step, words", [
    ('controller = "y"\npress = [1]', "the box is plugged into x"),
    ("press = [2]", "driven by the wire y.out2 -> x.in2"),
    ('controller = "x"\nrelease = [2]', "driven by the wire y.out2 -> x.in2"),
])
def test_a_scenario_step_presses_only_what_the_rig_lets_a_person_press(tmp_path, step, words):
    path = tmp_path / "s.toml"
    path.write_text(f'[[step]]\nat = "1s"\n{step}\n[[expect]]\ncontroller = "x"\nat = "2s"\n'
                    'running = true\n', encoding="utf-8")
    result = sim(RASTER, "--scenario", path)
    assert result.exit_code == 2, result.output
    assert words in result.stderr and "at 1000 ms on" in result.stderr


def test_interactive_holds_only_what_the_box_can_press():
    result = sim(RASTER, "--interactive", "--hold", "1+2")
    assert result.exit_code == 2 and "--hold '1+2'" in result.stderr
    assert "driven by the wire y.out2 -> x.in2" in result.stderr
