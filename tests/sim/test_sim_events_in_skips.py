"""JSON `events` inside skipped passes: the moves, arrivals, reports and macro
entries of fast-forwarded passes are listed as plain stepping lists them while there is room
(10,000: docs/simulator.md, "What sim writes"), then counted in `truncated`; the `fast-forward`
event stays as a marker."""
from __future__ import annotations

import json
from unittest import mock

import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from helpers.budgets import budget
from helpers.compiling import program_of
from helpers.rigs import RASTER
from mercmac.compiler import compile_file
from mercmac.rig.load import read_rig
from mercmac.sim.simulate import simulate
from mercmac.timespec import parse_buttons
from mercmac.cli import main
from mercmac.compiler.program import Macro, Op, Program
from mercmac.render.sim import run_json
from mercmac.sim import record as record_module
from mercmac.sim.simulate import Run, machine_for
from mercmac.vm import events as ev

LOOPS = {
    "jog reporting its target": "macro m { TT, MR 1, WS 0, goto m }\nautostart { goto m }\n",
    "positions before and after": "macro m { TP, MR 7, WS 0, TP, goto m }\n"
                                  "autostart { goto m }\n",
    "blink": "autostart {\n  every 500ms { CN 1, WA 500, CF 1 }\n}\n",
    "ping-pong of gotos": "macro a { WA 5, goto b }\nmacro b { WA 5, goto a }\n"
                          "autostart { goto a }\n",
    "inner skips": "autostart {\n  every 1s { CN 1, repeat 5 { WA 3, TP }, CF 1, MR 3, WS 0 }\n}\n",
}


def run(program: Program, mode: str, until_ms: int) -> dict:
    """The JSON of a run stepping ("off") or skipping ("all")."""
    machine, record = machine_for(program, fast_forward=mode)
    machine.power_on()
    machine.run_until(until_ms)
    return run_json(Run(machine, record, until_ms))


def stepped(events: list) -> list:
    return [e for e in events if e["kind"] != "fast-forward"]


@pytest.mark.parametrize("name", LOOPS)
def test_skipped_passes_list_the_events_stepping_lists(name):
    program = program_of(LOOPS[name])
    fast, plain = run(program, "all", 8_000), run(program, "off", 8_000)
    assert any(e["kind"] == "fast-forward" for e in fast["events"])  # it did skip
    assert "truncated" not in plain
    assert stepped(fast["events"]) == plain["events"]


@pytest.mark.parametrize("name", LOOPS)
def test_past_the_cap_the_events_of_skipped_passes_are_counted(name):
    # the cap at 1/20 of the real 10,000 and runs 1/20 as long: the same crossing of the cap
    # in every loop (the real cap is crossed by the CLI tests below), in seconds, not minutes
    program = program_of(LOOPS[name])
    until_ms = 150_000
    with mock.patch.object(record_module, "CAP", 500), \
            mock.patch.object(record_module, "RECENT", 500):
        fast, plain = run(program, "all", until_ms), run(program, "off", until_ms)
    assert "truncated" in plain or name == "blink"  # the cap is crossed
    markers = sum(e["kind"] == "fast-forward" for e in fast["events"])
    listed = stepped(fast["events"])
    assert listed == plain["events"][:len(listed)]
    # a marker past the cap is counted too; the short one of `blink` has room for all
    left_out = fast.get("truncated", {}).get("events", 0)
    with mock.patch.object(record_module, "CAP", 10**9):
        everything = run(program, "all", until_ms)["events"]
    dropped_markers = sum(e["kind"] == "fast-forward" for e in everything) - markers
    assert len(listed) + left_out - dropped_markers == \
        len(plain["events"]) + plain.get("truncated", {}).get("events", 0)


@pytest.mark.parametrize("name", LOOPS)
def test_a_pass_too_long_to_copy_is_still_counted_exactly(name):
    # with room to remember one event, no pass can be copied: the skip's own count
    # (FastForwarded.events, from the optimiser) tells how many each skipped pass made
    program = program_of(LOOPS[name])
    with mock.patch.object(record_module, "CAP", 10**9):
        plain = run(program, "off", 20_000)
        with mock.patch.object(record_module, "RECENT", 1):
            fast = run(program, "all", 20_000)
    listed = stepped(fast["events"])
    assert fast["truncated"]["events"] > 0  # counted, not listed
    assert len(listed) + fast["truncated"]["events"] == len(plain["events"])


@pytest.mark.parametrize("name", LOOPS)
def test_the_skips_own_count_is_what_the_copies_are(name):
    program = program_of(LOOPS[name])
    machine, record = machine_for(program, fast_forward="all")
    machine.power_on()
    machine.run_until(20_000)
    blocks = [b for b in record._recent if isinstance(b, record_module.Block)]
    skips = [e for e in record.events if isinstance(e, ev.FastForwarded)]
    assert blocks and len(blocks) == len(skips)
    assert [b.size for b in blocks] == [sum(s.events) for s in skips]


def test_the_json_of_the_cli_lists_the_passes_of_a_skip(tmp_path):
    (tmp_path / "jog.mcm").write_text(LOOPS["jog reporting its target"])
    result = CliRunner().invoke(main, ["sim", str(tmp_path / "jog.mcm"), "--until", "60s",
                                       "--format", "json"])
    assert result.exit_code == 0, result.output
    events = json.loads(result.output)["events"]
    skip = next(i for i, e in enumerate(events) if e["kind"] == "fast-forward")
    after = events[skip + 1:]
    assert {"report", "move", "arrive", "macro-enter"} <= {e["kind"] for e in after}
    targets = [e["target"] for e in events if e["kind"] == "move"]
    assert targets == list(range(1, len(targets) + 1))  # each pass one count on, skipped or not
    assert len(events) == 10_000 and json.loads(result.output)["truncated"]["events"] > 0


# -- the property: random loops give the events plain stepping gives -------------------
command = st.one_of(
    st.tuples(st.sampled_from(["MR"]), st.sampled_from([1, -3, 9, 400])),
    st.tuples(st.just("MA"), st.sampled_from([0, 500])),
    st.tuples(st.just("WS"), st.just(0)),
    st.tuples(st.just("WA"), st.sampled_from([0, 1, 3, 10])),
    st.tuples(st.sampled_from(["TP", "TT", "TE", "TS"]), st.none()),
    st.tuples(st.sampled_from(["CN", "CF"]), st.integers(1, 2)),
    st.tuples(st.just("EM"), st.integers(1, 2)),
    st.tuples(st.just("DH"), st.sampled_from([0, 77])),
)
tail = st.sampled_from([[("RP", 65535)], [("WA", 2), ("RP", 40), ("RP", 65535)], [("EM", 3)]])


@pytest.mark.slow
@settings(max_examples=budget(150), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(command, min_size=1, max_size=5), tail,
       st.dictionaries(st.integers(1, 2), st.lists(command, min_size=1, max_size=3),
                       max_size=2),
       st.integers(20, 6_000))
def test_random_loops_list_the_events_stepping_lists(body, loop, others, until_ms):
    slots = {0: [("EM", 3)], 3: body + loop}
    slots.update({s: [c for c in ops if c[0] != "EM"] or [("WA", 1)] for s, ops in others.items()})
    program = Program({s: Macro(s, f"MC{s:02d}", [Op(m, a) for m, a in ops])
                       for s, ops in slots.items()})
    fast, plain = run(program, "all", until_ms), run(program, "off", until_ms)
    if "truncated" in plain or "truncated" in fast:
        return
    assert stepped(fast["events"]) == plain["events"]


# -- a rig: the joint skip lists each controller's events as stepping does --------------
def rig_events(fast_forward: bool, until_ms: int) -> dict:
    rig = read_rig(str(RASTER)).rig
    programs = {c.name: compile_file(c.program, target=c.model).program for c in rig.controllers}
    result = simulate(rig, programs, presses={"x": parse_buttons("1@0-100ms")},
                          until_ms=until_ms, fast_forward="all" if fast_forward else "off")
    return {name: run_json(r) for name, r in result.runs.items()}


@pytest.mark.parametrize("until_ms", [30_000, 61_234])
def test_a_rig_skip_lists_each_controllers_events_as_stepping_does(until_ms):
    fast, plain = rig_events(True, until_ms), rig_events(False, until_ms)
    for name in ("x", "y"):
        assert "truncated" not in plain[name]
        assert len(fast[name]["events"]) > len(stepped(fast[name]["events"]))  # it skipped
        assert stepped(fast[name]["events"]) == plain[name]["events"]
