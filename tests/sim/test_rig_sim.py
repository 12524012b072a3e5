"""A rig on one clock (sim/simulate.py): wires at the same instant, the raster
example rasters, a rig built to dead-lock reports it with both macros, joint fast-forward
gives what stepping gives, and the joystick drives its branch's controller."""
from __future__ import annotations

import sys
from pathlib import Path

import pytest

from helpers.rigs import RASTER, rig_of, rig_of_one
from mercmac.compiler import compile_file
from mercmac.render import explain
from mercmac.rig.load import read_rig
from mercmac.sim.simulate import Hold, simulate
from mercmac.sim.simulate import simulate_program
from mercmac.timespec import parse_buttons
from mercmac.vm import events as ev

START = {"x": parse_buttons("1@0-100ms")}  # button 1 of the box on X starts the scan


def run(path: Path, **kw):
    rig = read_rig(str(path)).rig
    assert rig is not None
    programs = {c.name: compile_file(c.program, target=c.model).program for c in rig.controllers}
    return simulate(rig, programs, **kw)


def events(result, name: str, kind: type) -> list:
    return [e for e in result.runs[name].record.events if isinstance(e, kind)]


def test_an_output_reaches_the_wired_input_at_the_same_instant(tmp_path):
    # x raises out1 at its third command; y waits on in1 and answers at once
    path = rig_of(tmp_path, "autostart { WA 5, CN 1 }\n", "autostart { WN 1, CN 2 }\n",
                  '"x.out1 -> y.in1"')
    result = run(path, until_ms=100)
    (raised,) = events(result, "x", ev.OutputsChanged)
    (seen,) = events(result, "y", ev.InputChanged)
    (answer,) = events(result, "y", ev.OutputsChanged)
    assert seen.t == raised.t and (seen.input, seen.on) == (1, True)
    assert answer.t == raised.t  # the wait ends at t and y goes on at t itself
    assert [(e.t, str(e.wire), e.level) for e in result.edges] == [
        (raised.t, "x.out1 -> y.in1", True)]


def test_the_raster_example_rasters():
    result = run(RASTER, presses=START, until_ms=12_000, fast_forward="off")
    x_moves = [e.target for e in events(result, "x", ev.MoveStarted)]
    y_moves = [e.target for e in events(result, "y", ev.MoveStarted)]
    assert x_moves[:4] == [20000, 0, 20000, 0]  # X sweeps a line and back
    assert y_moves[:4] == [500, 1000, 1500, 2000]  # Y steps one row after each line
    # Y steps only while X rests at a line's end, and X sweeps only after Y's step
    x_ends = [e.t for e in events(result, "x", ev.MoveEnded)]
    y_starts = [e.t for e in events(result, "y", ev.MoveStarted)]
    y_ends = [e.t for e in events(result, "y", ev.MoveEnded)]
    x_starts = [e.t for e in events(result, "x", ev.MoveStarted)]
    for i in range(3):
        assert x_ends[i] < y_starts[i] < y_ends[i] < x_starts[i + 1]


def test_a_rig_built_to_dead_lock_names_both_waiting_macros(tmp_path):
    # each waits for the other's signal before giving its own
    path = rig_of(tmp_path, "macro hello { WN 2, CN 1 }\nautostart { goto hello }\n",
                  "macro answer { WN 1, CN 2 }\nautostart { goto answer }\n",
                  '"x.out1 -> y.in1", "y.out2 -> x.in2"')
    result = run(path, until_ms=5_000)
    for name in ("x", "y"):
        (hazard,) = result.runs[name].record.hazards
        assert hazard.rule == "rig-deadlock"
        assert ("x waits in hello (MC01) at WN2 for in2 ON (from y.out2, which stays OFF: "
                "y waits too)") in hazard.message
        assert ("y waits in answer (MC01) at WN1 for in1 ON (from x.out1, which stays OFF: "
                "x waits too)") in hazard.message
        assert hazard.where is not None and hazard.where.ip == 0  # the wait itself
    assert result.hazards == 2


def test_the_dead_lock_rule_is_explained():
    assert explain.find("MH008") is explain.find("rig-deadlock")
    assert "dead-lock" in explain.find("MH008").explanation


def test_a_controller_waiting_for_a_person_is_no_dead_lock(tmp_path):
    # y waits on x's line, but x waits for box button 2, which someone may still press
    path = rig_of(tmp_path, "autostart { WN 2, CN 1 }\n", "autostart { WN 1, CN 2 }\n",
                  '"x.out1 -> y.in1"', 'box = "x"\n')
    result = run(path, until_ms=1_000)
    assert result.hazards == 0
    pressed = run(path, presses={"x": parse_buttons("2@500ms")}, until_ms=1_000)
    assert [e.pattern for e in pressed.runs["y"].record.outputs] == [2]


def test_a_controller_that_ended_leaves_the_other_waiting_for_good(tmp_path):
    # x ends without raising out1: y waits on it for ever
    path = rig_of(tmp_path, "autostart { WA 5 }\n", "autostart { WN 1, CN 2 }\n",
                  '"x.out1 -> y.in1"')
    (hazard,) = run(path, until_ms=1_000).runs["y"].record.hazards
    assert hazard.rule == "rig-deadlock" and hazard.t == 5_000
    assert ("y waits in autostart (MC00) at WN1 for in1 ON (from x.out1, which stays OFF: "
            "x has ended)") in hazard.message


# x waits on in3, which nothing drives; y waits on x's line
UNDRIVEN = ("autostart { WN 3, CN 1 }\n", "autostart { WN 1, CN 2 }\n",
            '"x.out1 -> y.in1", "y.out2 -> x.in2"')


def test_a_wait_on_an_input_nothing_drives_is_part_of_the_dead_lock(tmp_path):
    result = run(rig_of(tmp_path, *UNDRIVEN), until_ms=5_000)
    for name in ("x", "y"):
        (hazard,) = result.runs[name].record.hazards
        assert hazard.rule == "rig-deadlock" and hazard.t == 0
        assert ("x waits in autostart (MC00) at WN3 for in3 ON (no wire or box button drives "
                "it)") in hazard.message
        assert ("y waits in autostart (MC00) at WN1 for in1 ON (from x.out1, which stays OFF: "
                "x waits too)") in hazard.message


def test_a_dead_lock_waits_for_the_last_scripted_press(tmp_path):
    # a press of x's in3 is scripted at 2 s (no box: a test's script) and released at 3 s;
    # x goes on at 2 s, so y goes on too: both end, no dead-lock at all
    path = rig_of(tmp_path, *UNDRIVEN)
    pressed = run(path, presses={"x": parse_buttons("3@2s-3s")}, until_ms=5_000)
    assert pressed.hazards == 0
    assert [e.pattern for e in pressed.runs["y"].record.outputs] == [2]


def test_a_wait_on_an_unwired_input_after_the_other_ended_is_a_dead_lock(tmp_path):
    # y ends at 5 ms; x waits on in3 from the start: the dead-lock is when y ends
    path = rig_of(tmp_path, "autostart { WF 2, WN 3 }\n", "autostart { WA 5 }\n",
                  '"y.out2 -> x.in2"')
    (hazard,) = run(path, until_ms=1_000).runs["x"].record.hazards
    assert hazard.rule == "rig-deadlock" and hazard.t == 5_000
    assert "x waits in autostart (MC00) at WN3 for in3 ON (no wire" in hazard.message


def test_a_ws_for_a_move_that_never_ends_leaves_the_other_waiting_for_good(tmp_path):
    # SV 0: x's move never ends (MH005), so x never raises out1, which y waits for
    path = rig_of(tmp_path, "autostart { SV 0, MR 100, WS 0, CN 1 }\n",
                  "autostart { WN 1, CN 2 }\n", '"x.out1 -> y.in1"')
    result = run(path, until_ms=1_000)
    assert [h.rule for h in result.runs["x"].record.hazards] == ["ws-never-finishes"]
    (hazard,) = result.runs["y"].record.hazards
    assert hazard.rule == "rig-deadlock" and ("(from x.out1, which stays OFF: x waits for a "
                                              "move that never ends)") in hazard.message


def test_a_wait_on_an_input_a_wire_and_a_box_button_drive_is_no_dead_lock(tmp_path):
    # in1 of y is wired from x.out1 (which x never raises) and has box button 1 (MR008: an
    # error for check; the simulator still gives a person the benefit of the doubt)
    path = rig_of(tmp_path, "autostart { WA 5 }\n", "autostart { WN 1, CN 2 }\n",
                  '"x.out1 -> y.in1"', 'box = "y"\n')
    assert run(path, until_ms=1_000).hazards == 0


def test_a_finished_rig_is_no_dead_lock(tmp_path):
    path = rig_of(tmp_path, "autostart { CN 1 }\n", "autostart { WN 1, CN 2 }\n",
                  '"x.out1 -> y.in1"')
    assert run(path, until_ms=1_000).hazards == 0


def outcome(result) -> dict:
    """All a run shows but how it got there (skips are events of their own)."""
    return {"edges": [(e.t, str(e.wire), e.level) for e in result.edges],
            "dropped": result.edges_dropped,
            **{name: (r.final(), [(e.t, e.pattern) for e in r.record.outputs],
                      [(e.t, e.text) for e in r.record.reports], r.record.dropped["outputs"],
                      [h.message for h in r.record.hazards])
               for name, r in result.runs.items()}}


@pytest.mark.parametrize("until_ms", [30_000, 61_234, 200_000])
def test_joint_fast_forward_equals_stepping(until_ms):
    fast = run(RASTER, presses=START, until_ms=until_ms)
    plain = run(RASTER, presses=START, until_ms=until_ms, fast_forward="off")
    assert outcome(fast) == outcome(plain)
    assert events(fast, "y", ev.FastForwarded) and not events(plain, "y", ev.FastForwarded)


def test_an_idle_rig_polling_with_a_counted_loop_skips_exactly():
    # no button: X polls button 1 every 50 ms (an RP counting down), Y waits on in1
    fast = run(RASTER, until_ms=200_000)
    plain = run(RASTER, until_ms=200_000, fast_forward="off")
    assert outcome(fast) == outcome(plain)
    assert fast.runs["x"].machine.counters == plain.runs["x"].machine.counters
    assert events(fast, "x", ev.FastForwarded)


def test_a_skip_stops_before_a_counted_loop_ends(tmp_path):
    # x blinks out1 in a loop of 300 passes, then raises out2 for good; y counts x's blinks
    # in a loop of its own and answers on out3 each time
    path = rig_of(tmp_path, "macro blink { repeat 300 { CN 1, WA 10, CF 1, WA 20 } }\n"
                            "autostart { call blink\n CN 2 }\n",
                  "macro echo { WN 1, CN 3, WF 1, CF 3, goto echo }\nautostart { goto echo }\n",
                  '"x.out1 -> y.in1", "x.out2 -> y.in2"')
    fast = run(path, until_ms=20_000)
    plain = run(path, until_ms=20_000, fast_forward="off")
    assert outcome(fast) == outcome(plain)
    assert events(fast, "x", ev.FastForwarded)
    (blinks_over,) = [e for e in fast.runs["x"].record.outputs if e.pattern == 2]
    assert blinks_over.t == plain.runs["x"].record.outputs[-1].t


def test_a_button_during_the_scan_bounds_the_skip():
    # button 3 stops the scan after the current pair of lines: stepping and skipping agree
    presses = {"x": parse_buttons("1@0-100ms,3@40s-45s")}
    fast = run(RASTER, presses=presses, until_ms=90_000)
    plain = run(RASTER, presses=presses, until_ms=90_000, fast_forward="off")
    assert outcome(fast) == outcome(plain)
    assert fast.runs["x"].machine.macro is not None and fast.runs["y"].final()["target"] < 45_000


SPIN = "macro spin { CN 1, CF 1, goto spin }\nautostart { goto spin }\n"
CALLS = 400_000  # Python and C calls one run of SPIN may make, whatever its --until


class OverBudget(Exception):
    """More calls than the run may make: the skip costs something per pass."""


def calls_of(path: Path, until_ms: int):
    """The run to until_ms and the calls it made (sys.setprofile: a count, not a time); a
    run that makes more than CALLS fails at once (OverBudget) rather than running for days."""
    made = 0

    def count(frame, event, arg) -> None:
        nonlocal made
        made += 1
        if made > CALLS:
            raise OverBudget(f"over {CALLS} calls")

    sys.setprofile(count)
    try:
        result = run(path, until_ms=until_ms)
    finally:
        sys.setprofile(None)
    return result, made


def test_skipping_passes_that_change_no_wire_costs_nothing_per_pass(tmp_path):
    # a rig of one controller that blinks out1 in a busy loop: 28.8 million passes a day,
    # none of which changes a wire; the skip's work does not grow with the passes it skips
    path = rig_of_one(tmp_path, SPIN)
    short, short_calls = calls_of(path, 60_000)
    long, long_calls = calls_of(path, 1500 * 86_400_000)
    assert long_calls <= short_calls + 1_000
    program = compile_file(str(tmp_path / "s.mcm")).program
    alone = simulate_program(program, until_ms=1500 * 86_400_000)
    ours = long.runs["s"]  # what `sim FILE` says of the program, the rig says of it
    assert ours.final() == alone.final()
    assert (ours.record.outputs, ours.record.dropped) == (alone.record.outputs,
                                                          alone.record.dropped)


def test_the_joystick_drives_its_controller_with_the_cubic_response(tmp_path):
    # JN 8000: full deflection is 8000 counts/s; half of it through the cubic table
    # (§6.4 JT, the factory default) is 8000 * 0.5**3 = 1000 counts/s
    path = rig_of(tmp_path, "autostart { JN 8000 }\n", "autostart { WA 1 }\n", "",
                  '[joystick]\nX = "x"\n')
    result = run(path, holds=[Hold("x", 0.5, 1000, 3000)], until_ms=6000)
    starts = events(result, "x", ev.MoveStarted)
    assert starts[0].kind is ev.Motion.JOYSTICK and starts[0].t == 1_000_000
    assert starts[1].kind is ev.Motion.STOP and starts[1].t == 3_000_000
    assert 1900 <= result.runs["x"].final()["position"] <= 2100  # about 1000 counts/s for 2 s
    back = run(path, holds=[Hold("x", -1.0, 1000, 2000)], until_ms=6000)
    assert back.runs["x"].final()["position"] < -7000  # full deflection the other way
