"""`describe` counts repeats as the simulator runs them.

An `RP,RP` loop is not "forever": `RP n` runs the line n+1 times (a bare RP: 65,536) and a
second RP runs it all again, so `WA20,RP,RP` runs 4,294,967,296 times (docs/simulator.md,
"Repeat counters"). Each line below is macro 0 of a file; `sim` runs it to its end and
`describe` must give the same count and, where every command's time is known, the same duration.
"""
from __future__ import annotations

import json

import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from helpers.budgets import budget
from helpers.cli import cli
from mercmac.sim.record import CAP
from mercmac.timespec import format_span as duration, parse_duration

UNTIL = "36000d"  # far past every line below: each ends on its own
# line, how often its start runs (a report at the start counts the small ones)
LINES = [
    ("CN1,WA20,RP,RP", 65_536 ** 2),  # the `every 20ms` of the README: ends at 94,489,346 s
    ("TP,WA5,RP2,CN1,RP3", 3 * 4),  # two RPs with different counts
    ("TP,RP3,WA7,RP4,CN2,RP5", 4 * 5 * 6),  # three, with commands between them
    ("TP,CN1,WA20,RP5,RP7", 6 * 8),
    ("TP,CN1,RP9", 10),  # RP n with n given: n + 1 times
    ("TP,CN1,RP0", 1),
    ("TP,CN1,WA0,RP2", 3),  # WA0 still takes its cycle
    ("WA100,CF1,RP,CN1,RP3", 65_536 * 4),
    ("SV5000,MA100,CN1,WA250,RP,RP", 65_536 ** 2),  # a move does not hold the line up
]


def _simulated(write, line: str) -> dict:
    result = cli("sim", write(f"[MC00] {line}\n"), "--until", UNTIL, "--format", "json")
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


def _described(write, line: str, fmt: str = "json"):
    result = cli("describe", write(f"[MC00] {line}\n"), "--format", fmt)
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout) if fmt == "json" else result.stdout


@pytest.mark.parametrize("line, times", LINES, ids=[line for line, _ in LINES])
def test_the_count_and_the_duration_are_the_simulators(write, line, times):
    ran = _simulated(write, line)
    assert ran["ended_ms"] is not None  # the line ends: it is no endless loop
    if line.startswith("TP"):
        assert len(ran["reports"]) == times
    runs = _described(write, line)["macros"][0]["runs"]
    assert runs == {"times": times, "duration_ms": ran["ended_ms"], "exact": True}
    text = _described(write, line, "text")
    assert f"{times:,} time" in text and "forever" not in text
    assert duration(ran["ended_ms"] * 1000) in text


def test_the_readme_loop_says_how_long_it_runs(write):
    text = _described(write, "CN1,WA20,RP,RP", "text")
    assert "every 20 ms, 4,294,967,296 times (about 1,094 d): LED 1 on" in text
    assert _simulated(write, "CN1,WA20,RP,RP")["ended_ms"] == 94_489_346_048


def test_a_loop_of_calls_gives_the_count_only(write):
    """The calls wait for buttons: how long a pass takes is not known, how many there are is."""
    text = cli("describe", write("[MC00] EM1,EM2,WA20,RP,RP\n[MC01] XN1,MR5,WF1\n"
                                 "[MC02] XN2,MR-5,WF2\n")).stdout
    assert "every 20 ms, 4,294,967,296 times: run MC01" in text
    assert "forever" not in text and "about" not in text


def test_a_loop_that_may_end_sooner_says_up_to(write):
    cases = {"XN1,CN1,WA20,RP,RP": "only while button 1 is held: every 20 ms, up to "
                                   "4,294,967,296 times: LED 1 on",
             "CN1,EM1,WA5,RP3": "the line runs up to 4 times"}  # MC01 calls on: no return
    for line, said in cases.items():
        text = cli("describe", write(f"[MC00] {line}\n[MC01] EM2\n[MC02] CN2\n")).stdout
        assert said in text, text
        runs = json.loads(cli("describe", write(f"[MC00] {line}\n[MC01] EM2\n[MC02] CN2\n"),
                              "--format", "json").stdout)["macros"][0]["runs"]
        assert runs["exact"] is False and runs["duration_ms"] is None


def test_the_call_graph_names_the_count(write, tmp_path):
    result = cli("describe", write("[MC00] EM1\n[MC01] CN1,WA20,RP5,RP7\n"),
                 "--graph", tmp_path / "g.dot")
    assert result.exit_code == 0, result.output
    assert "repeat 48 times" in (tmp_path / "g.dot").read_text()


_COMMANDS = st.sampled_from(["CN1", "WA0", "WA3", "WA17", "SV9000", "SA90000"])
_REPEATS = st.one_of(st.integers(0, 6).map(lambda n: f"RP{n}"), st.just("RP"))


@settings(max_examples=budget(40), deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.lists(st.one_of(_COMMANDS, _REPEATS), min_size=1, max_size=9))
def test_any_line_of_repeats_and_waits(write, ops):
    """Any mix of RP counts and timed commands. A bare RP (65,536 passes) at most twice,
    and no report or LED toggle in the line: the simulator fast-forwards identical passes
    only."""
    bare = sum(op == "RP" for op in ops)
    assume(any(op.startswith("RP") for op in ops) and bare <= 2)
    line = ",".join(ops) if bare else "TP," + ",".join(ops)  # TP: one report per pass
    runs = _described(write, line)["macros"][0]["runs"]
    assume(runs["duration_ms"] < parse_duration(UNTIL))  # else the run stops before its end
    assume(bare or runs["times"] <= 2 * CAP)  # passes with a report are simulated one by one
    ran = _simulated(write, line)
    assert runs["duration_ms"] == ran["ended_ms"] and runs["exact"]
    if not bare:  # the run lists the first CAP reports
        assert len(ran["reports"]) == min(runs["times"], CAP)
