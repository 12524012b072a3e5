"""`mercmac sim` through click's CliRunner and as a real subprocess (docs/cli.md)."""
from __future__ import annotations

import json
import subprocess
import sys

import pytest

from helpers.cli import sim
from helpers.paths import EXAMPLE4


def test_json_has_the_spec_shape(write):
    result = sim(write("[MC00] CN1,MA5555,WS0,TP,CP0,XN1,TT\n"), "--format", "json",
                 "--until", "2s")
    assert result.exit_code == 0, result.output
    out = json.loads(result.output)
    assert {"until_ms", "halted", "final", "reports", "outputs", "hazards"} <= set(out)
    assert out["until_ms"] == 2000 and out["halted"] is True
    assert set(out["final"]) == {"t_ms", "position", "target", "outputs", "velocity", "macro"}
    assert out["final"] == {"t_ms": 2000, "position": 5555, "target": 5555, "outputs": 0,
                            "velocity": 0, "macro": None}
    assert out["reports"] == [{"t_ms": out["reports"][0]["t_ms"], "text": "P:+0000005555"}]
    assert [o["pattern"] for o in out["outputs"]] == [1, 0]
    assert out["outputs"][0]["t_ms"] == 0
    assert "truncated" not in out


def test_json_truncates_at_10000_and_counts_the_rest(write):
    # TP,CN1,CF1,RP,RP: 4 ms a pass, one report and two LED changes per pass
    result = sim(write("[MC00] TP,CN1,CF1,RP,RP\n"), "--format", "json", "--until", "60s")
    out = json.loads(result.output)
    passes = 60_000 // 4
    assert len(out["reports"]) == len(out["outputs"]) == 10_000
    # all three counts once any list is cut (docs/simulator.md, "What sim writes"); the skipped
    # passes' events are counted too (a report and two LED changes a pass, the power-on entry, the
    # markers of skips past the cap)
    events = out["truncated"].pop("events")
    assert out["truncated"] == {"reports": passes - 10_000, "outputs": 2 * passes - 10_000}
    assert 0 <= events - (3 * passes + 1 - 10_000) < 10
    assert out["hazards"][0]["rule"] == "busy-loop" and out["hazards"][0]["line"] == 1
    assert out["final"]["macro"] == 0 and out["halted"] is False


def test_hazards_carry_time_and_line(write):
    result = sim(write("autostart {\n  JH 1000\n  MA 5000\n}\n"), "--format", "json")
    hazard = json.loads(result.output)["hazards"][0]
    assert hazard == {"t_ms": 1, "rule": "soft-limit-clamp", "line": 3, "slot": 0,
                      "macro": "autostart (MC00)", "message": hazard["message"]}
    assert "5000" in hazard["message"] and "1000" in hazard["message"]


def test_text_timeline_and_summary_plain_when_piped():
    result = sim(EXAMPLE4, "--buttons", "2@0-150ms,1@1s-1.2s", "--until", "3s")
    assert result.exit_code == 0
    text = result.output
    assert "\x1b[" not in text
    assert "button 1 pressed" in text and "LEDs ●○○○" in text
    assert "goto MC20" in text and "move to 100000" in text and "fast-forward" in text
    assert "Summary: ran to 3.000 s; still running MC20 at the end." in text


def test_trace_disassembles_with_macro_slot_and_line(write):
    result = sim(write("// x\n[MC00] CN1,WA20,EM3\n[MC03] XN2,TP\n"), "--trace")
    lines = result.output.splitlines()
    assert any("MC00" in line and "#01" in line and "WA" in line and "line 2" in line
               for line in lines)
    assert any("MC03" in line and "XN" in line and "in2" in line and "line 3" in line
               for line in lines)
    assert "Summary" in result.output


def test_vcd_is_written_with_pyvcd(write, tmp_path):
    out = tmp_path / "run.vcd"
    result = sim(write("[MC00] CN1,MR1000,WS0,CF1,EM2\n[MC02] WN3\n"), "--vcd", str(out),
                 "--buttons", "3@1s", "--until", "2s")
    assert result.exit_code == 0
    from vcd.reader import TokenKind, tokenize

    ids, changes = {}, []
    now = 0
    with open(out, "rb") as f:
        for token in tokenize(f):
            if token.kind is TokenKind.VAR:
                ids[token.var.id_code] = token.var.reference
            elif token.kind is TokenKind.CHANGE_TIME:
                now = token.time_change
            elif token.kind is TokenKind.CHANGE_SCALAR:
                changes.append((now, ids[token.scalar_change.id_code], token.scalar_change.value))
            elif token.kind is TokenKind.CHANGE_VECTOR:
                changes.append((now, ids[token.vector_change.id_code], token.vector_change.value))
    assert {"in1", "in3", "out1", "out4", "position", "target", "macro"} <= set(ids.values())
    assert (1_000_000, "in3", "1") in changes
    out1 = [(t, v) for t, name, v in changes if name == "out1"]
    assert out1[0] == (0, "1") and out1[-1][1] == "0"
    positions = [v for _, name, v in changes if name == "position"]
    assert positions[-1] == 1000 and len(positions) > 10
    assert [v for _, name, v in changes if name == "macro"][-1] in ("z", "Z")


def test_scenario_pass_and_fail(write, tmp_path):
    program = write("[MC00] WN1,CN1,WF1,CF1,MR500,WS0\n")
    good = tmp_path / "good.toml"
    good.write_text('until = "3s"\n[[step]]\nat = "1s"\npress = [1]\n[[step]]\nat = "2s"\n'
                    'release = [1]\n[[expect]]\nwithin = ["1s", "1.1s"]\noutputs = 1\n'
                    '[[expect]]\nat = "2.5s"\nposition = [499, 501]\nrunning = false\n')
    result = sim(program, "--scenario", str(good))
    assert result.exit_code == 0 and "all 2 expectations met" in result.output
    bad = tmp_path / "bad.toml"
    bad.write_text('[[expect]]\nat = "1.5s"\noutputs = 1\nmacro = 0\n')
    result = sim(program, "--scenario", str(bad))
    assert result.exit_code == 1
    assert "expectation 1 (at 1500 ms) failed: outputs is 0, expected 1" in result.output


@pytest.mark.parametrize("toml, message", [
    ("[[expect]]\nat = 5\n", "one or more of"),
    ("[[step]]\npress = [1]\n", "write at ="),
    ("[[step]]\nat = \"1s\"\npress = [9]\n", "inputs are numbers 1-6"),
    ("until = \"soon\"\n", "not a duration"),
    ("[[expect]\n", "not valid TOML"),
    ("speed = 3\n", "unknown key"),
])
def test_bad_scenarios_are_usage_errors(write, tmp_path, toml, message):
    path = tmp_path / "s.toml"
    path.write_text(toml)
    result = sim(write("[MC00] TP\n"), "--scenario", str(path))
    assert result.exit_code == 2 and message in result.output
    assert "Traceback" not in result.output


@pytest.mark.parametrize("args, message", [
    (["--buttons", "7@1s"], "--buttons"),
    (["--buttons", "1@2s-1s"], "release time is before"),
    (["--until", "tomorrow"], "--until"),
    (["--hard-limits", "5"], "NEG,POS"),
    (["--hard-limits", "5,1"], "below"),
    (["--cycle", "0"], "command cycle"),
])
def test_bad_options_exit_2_with_a_message(write, args, message):
    result = sim(write("[MC00] TP\n"), *args)
    assert result.exit_code == 2 and message in result.output
    assert "Traceback" not in result.output


def test_missing_file_exits_2():
    result = sim("/nonexistent/x.mcm")
    assert result.exit_code == 2 and "x.mcm" in result.output


def test_file_with_errors_is_not_simulated(write):
    result = sim(write("[MC00] EMxx,TP\n"), "--format", "json")
    assert result.exit_code == 1
    assert "syntax" in result.output and "reports" not in result.output


def test_target_option_and_file_target(write):
    c663 = write("target C-663\n[MC00] TY\n")
    assert json.loads(sim(c663, "--format", "json").output)["reports"][0]["text"] == "Y:+0000020000"
    assert json.loads(sim(write("[MC00] TY\n"), "--format", "json", "--target", "C-663")
                      .output)["reports"][0]["text"] == "Y:+0000020000"
    assert json.loads(sim(write("[MC00] TY\n"), "--format", "json").output)["reports"][0]["text"] \
        == "Y:+0000045000"


def test_servo_off_reference_and_cycle_options(write):
    out = json.loads(sim(write("[MC00] MR100\n"), "--servo-off", "--format", "json").output)
    assert out["hazards"][0]["rule"] == "move-servo-off" and out["final"]["target"] == 0
    out = json.loads(sim(write("[MC00] FE0,WS0,TP\n"), "--reference-at", "3000", "--format",
                         "json").output)
    assert out["reports"][0]["text"] == "P:+0000003000"
    out = json.loads(sim(write("[MC00] TB,TB\n"), "--cycle", "2.5", "--format", "json").output)
    assert [r["t_ms"] for r in out["reports"]] == [0, 2.5]


def test_real_subprocess_long_loop_halts():
    done = subprocess.run([sys.executable, "-m", "mercmac", "sim", "-", "--until", "1500d",
                           "--format", "json"], input="[MC00] CN1,WA20,RP,RP\n",
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    out = json.loads(done.stdout)
    assert out["halted"] is True and out["ended_ms"] == 2**32 * 22 + 65536
    assert out["outputs"] == [{"t_ms": 0, "pattern": 1}]


def test_real_subprocess_text_and_errors():
    done = subprocess.run([sys.executable, "-m", "mercmac", "sim", EXAMPLE4, "--buttons",
                           "3@0-300ms", "--until", "1s"], capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 0 and "goto MC26" in done.stdout
    bad = subprocess.run([sys.executable, "-m", "mercmac", "sim", EXAMPLE4, "--buttons", "x"],
                         capture_output=True, text=True, timeout=60)
    assert bad.returncode == 2 and "mercmac: --buttons" in bad.stderr
