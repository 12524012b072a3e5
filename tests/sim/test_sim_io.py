"""`mercmac sim`'s exact inputs and outputs: presses, JSON events, scenarios, exits."""
from __future__ import annotations

import json

import pytest

from helpers.cli import sim
from helpers.paths import JOG_BOX
from mercmac.timespec import Press, parse_buttons

LED = "[MC00] EM1,WA10,RP,RP\n[MC01] XN1,CN1,WF1,CF1,TP\n"  # LED 1 while button 1 is held


def run_json(*args) -> dict:
    result = sim(*args, "--format", "json")
    assert result.exit_code == 0, result.output
    return json.loads(result.output)


# ------------------------------------------------------------ overlapping presses
@pytest.mark.parametrize("spec, presses", [
    ("1@1s-2s,1@1.5s-3s", [Press((1,), 1000, 3000)]),
    ("1@1.5s-3s,1@1s-2s", [Press((1,), 1000, 3000)]),
    ("1@1s-2s,1@2s-3s", [Press((1,), 1000, 3000)]),  # touching: no release in between
    ("1@1s-2s,1@1.5s", [Press((1,), 1000, None)]),
    ("1@0-1s,1@2s-3s", [Press((1,), 0, 1000), Press((1,), 2000, 3000)]),
    ("2+3@0-1s,2@500ms-2s", [Press((3,), 0, 1000), Press((2,), 0, 2000)]),
    ("1@0-2s,2+3@5s-5.2s", [Press((1,), 0, 2000), Press((2, 3), 5000, 5200)]),
])
def test_overlapping_presses_of_one_button_merge(spec, presses):
    assert parse_buttons(spec) == presses


def test_a_merged_press_is_released_once_at_its_last_release(write):
    out = run_json(write(LED), "--buttons", "1@1s-2s,1@1.5s-3s", "--until", "4s")
    inputs = [(e["t_ms"], e["kind"]) for e in out["events"] if e["kind"] in ("press", "release")]
    assert inputs == [(1000, "press"), (3000, "release")]
    assert [o["pattern"] for o in out["outputs"]] == [1, 0] and out["outputs"][1]["t_ms"] >= 3000


# ------------------------------------------------------------ JSON events and trace
def test_json_events_carry_time_kind_macro_slot_and_line(write):
    out = run_json(write("[MC00] CN1,MA500,WS0,TP\n"), "--buttons", "2@1ms-2ms", "--until", "1s")
    assert list(out)[:8] == ["until_ms", "halted", "ended_ms", "final", "reports", "outputs",
                             "hazards", "events"]  # the old keys stay as they were
    kinds = [e["kind"] for e in out["events"]]
    for kind in ("macro-enter", "output", "press", "release", "move", "arrive", "report",
                 "macro-exit", "program-end"):
        assert kind in kinds, kind
    enter = out["events"][0]
    assert enter == {"t_ms": 0, "kind": "macro-enter", "macro": "MC00", "slot": 0, "via": "power-on"}
    report = next(e for e in out["events"] if e["kind"] == "report")
    assert report["text"] == "P:+0000000500" and report["slot"] == 0 and report["line"] == 1
    move = next(e for e in out["events"] if e["kind"] == "move")
    assert move["target"] == 500 and move["macro"] == "MC00" and move["arrival_ms"] > move["t_ms"]
    assert all(isinstance(e["t_ms"], (int, float)) for e in out["events"])
    assert "truncated" not in out


def test_json_events_name_source_macros(write):
    out = run_json(JOG_BOX, "--buttons", "1@100ms-400ms", "--until", "1s")
    entered = {e["macro"] for e in out["events"] if e["kind"] == "macro-enter"}
    assert {"autostart (MC00)", "setup (MC01)", "run (MC02)"} <= entered
    assert any(name.startswith("run.when@") for name in entered)


def test_json_events_are_capped_at_10000_with_a_count(write):
    presses = ",".join(f"1@{4 * i}-{4 * i + 1}" for i in range(6000))  # 12,000 input changes
    out = run_json(write("[MC00] TP\n"), "--buttons", presses, "--until", "25s")
    assert len(out["events"]) == 10_000
    total = 12_000 + 4  # and enter, report, exit, program end
    assert out["truncated"] == {"reports": 0, "outputs": 0, "events": total - 10_000}


def test_trace_with_json_lists_the_executed_instructions(write):
    out = run_json(write("[MC00] CN1,WA5,TP\n"), "--trace", "--until", "1s")
    assert [t["instruction"].split()[-3] for t in out["trace"]] == ["CN1", "WA5", "TP"]
    assert out["trace"][2]["t_ms"] == 6 and out["trace"][0]["line"] == 1
    assert "trace" not in run_json(write("[MC00] CN1,WA5,TP\n"), "--until", "1s")


# ------------------------------------------------------------ scenarios
def scenario(write, body: str) -> str:
    return write(body, "s.toml")


def test_scenarios_match_macros_by_name_and_their_hoisted_parts(write):
    path = scenario(write, 'until = "1s"\n[[step]]\nat = "500ms"\npress = [3]\n'
                    '[[expect]]\nat = "100ms"\nmacro = "setup"\n'
                    '[[expect]]\nwithin = ["400ms", "450ms"]\nmacro = "run"\n'
                    '[[expect]]\nwithin = ["500ms", "520ms"]\nmacro = "run.when@22"\n')
    result = sim(JOG_BOX, "--scenario", path)
    assert result.exit_code == 0 and "all 3 expectations met" in result.output, result.output


def test_a_failed_macro_name_expectation_shows_the_running_macro(write):
    path = scenario(write, '[[expect]]\nat = "100ms"\nmacro = "run"\n')
    result = sim(JOG_BOX, "--scenario", path)
    assert result.exit_code == 1
    assert "macro is 'setup (MC01)', expected 'run'" in result.output


@pytest.mark.parametrize("body, words", [
    ('[[expect]]\nat = "1s"\nmacro = "rnu"\n', ["expect 1", '"rnu"', "did you mean 'run'"]),
    ('[[expect]]\nat = "1s"\noputs = 1\n', ["expect 1", '"oputs"', "did you mean 'outputs'"]),
    ('[[expect]]\nwithn = ["1s", "2s"]\noutputs = 1\n', ['"withn"', "did you mean 'within'"]),
    ('[[step]]\nat = "1s"\npres = [1]\n', ["step 1", '"pres"', "did you mean 'press'"]),
    ('[[step]]\npres = [1]\n', ["step 1", '"pres"', "did you mean 'press'"]),
    ('untill = "2s"\n', ['"untill"', "did you mean 'until'"]),
    ('[[expects]]\nat = "1s"\n', ['"expects"', "did you mean 'expect'"]),
])
def test_scenario_mistakes_name_the_key_and_the_nearest(write, body, words):
    result = sim(JOG_BOX, "--scenario", scenario(write, body))
    assert result.exit_code == 2 and "Traceback" not in result.output
    for word in words:
        assert word in result.output, (word, result.output)


def test_scenario_with_buttons_is_refused(write):
    path = scenario(write, '[[expect]]\nat = "1s"\noutputs = 0\n')
    result = sim(write(LED), "--scenario", path, "--buttons", "1@0-1s")
    assert result.exit_code == 2
    assert "--scenario and --buttons" in result.output and "[[step]]" in result.output
    assert sim(write(LED), "--scenario", path, "--buttons", "").exit_code == 0


# ------------------------------------------------------------ exit codes
def test_fail_on_hazard_exits_1_and_says_why(write):
    program = write("[MC00] MA1000,WS0\n")  # a move with the servo off is a hazard
    assert sim(program, "--servo-off", "--until", "1s").exit_code == 0
    result = sim(program, "--servo-off", "--until", "1s", "--fail-on-hazard")
    assert result.exit_code == 1 and "1 hazard found (--fail-on-hazard)" in result.output
    result = sim(program, "--servo-off", "--until", "1s", "--fail-on-hazard", "--format", "json")
    assert result.exit_code == 1 and '"move-servo-off"' in result.output
    assert sim(program, "--until", "1s", "--fail-on-hazard").exit_code == 0


def test_fail_on_hazard_in_a_passing_scenario(write):
    path = scenario(write, '[[expect]]\nat = "10ms"\nrunning = false\n')
    program = write("[MC00] MA1000\n")
    assert sim(program, "--servo-off", "--scenario", path).exit_code == 0
    assert sim(program, "--servo-off", "--scenario", path, "--fail-on-hazard").exit_code == 1


@pytest.mark.parametrize("args, words", [
    (["--hold", "2"], ["--hold is for --interactive", "--buttons"]),
    (["--interactive", "--hold", "7"], ["--hold '7'", "1-6"]),
])
def test_hold_is_refused_where_it_cannot_work(write, args, words):
    result = sim(write(LED), *args)
    assert result.exit_code == 2
    for word in words:
        assert word in result.output
