"""Fast-forward of passes that move on the way: a profile still running when the
loop comes round, moves started while the axis moves, and reports (TP, TD, TE, TV, TS) taken
during a move. Such passes repeat shifted, bit for bit, while their positions and times stay
within one power of two (skips._same_binade); the skips must give exactly what plain
stepping gives: reports, outputs, hazards, every event but the skip markers, and the state.
Trigger pulses (ZM) in such passes repeat too, where the trigger stands alike relative to the
target (Trigger.relative)."""
from __future__ import annotations

from unittest import mock

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from helpers.budgets import budget
from helpers.compiling import program_of
from helpers.simulation import run_checkpoints, same_as_stepping
from mercmac.compiler.program import Macro, Op, Program
from mercmac.sim import record as record_module
from mercmac.sim.simulate import machine_for
from mercmac.vm import shapes
from mercmac.vm.models import Options
from mercmac.vm.skips import _within_binade

# the loops (i) and (j) of benchmarks/sim_speed.py: reports between short moves, and a long
# body moving on the way
BETWEEN_MOVES = ("macro m {\n  TT, MR 1, when 4 { goto fin }, goto m\n}\n"
                 "macro fin {\n  TP\n}\nautostart { goto m }\n")
LONG_BODY = ("autostart {\n  every 30ms { "
             + ", ".join(f"TT, MR {n}" for n in range(1, 10)) + " }\n}\n")
# reports of the position and the velocity taken while the axis moves
WHILE_MOVING = "autostart {\n  every 7ms { MR 40, WA 3, TP, TV, TE, TD, WS 0 }\n}\n"
MODELS = ("c-863", "c-663")


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("source", [BETWEEN_MOVES, LONG_BODY, WHILE_MOVING],
                         ids=["between-moves", "long-body", "while-moving"])
def test_passes_that_move_on_the_way_are_skipped_exactly(source, model):
    skips = same_as_stepping(program_of(source), [3, 700, 9_000, 40_000], model)
    shifted = [s for s in skips if s.shift]
    assert shifted and sum(s.passes for s in shifted) > 500


def test_a_profile_running_across_the_loop_anchor_is_moved_on_as_stepping_plans_it():
    # C-863: MR 1 lasts 3.16 ms and the pass 5 ms, so the profile of each pass is still running
    # when `m` is entered again; the skip moves it on 1 count and 5 ms a pass
    program = program_of(BETWEEN_MOVES)
    machine, _ = machine_for(program, model="c-863", fast_forward="all")
    machine.power_on()
    machine.run_until(100_000)
    assert machine.optimiser.anchors.visits  # and it did skip: 20,000 passes in 100 s
    assert machine.target == 20_000


def test_reports_while_moving_show_the_shifted_positions():
    program = program_of(WHILE_MOVING)
    with mock.patch.object(record_module, "CAP", 10**7):
        fast, skips = run_checkpoints(program, "all", [60_000], "c-863")
    assert any(s.shift == 40 for s in skips)
    positions = [int(text[2:]) for _, text in fast["reports"] if text.startswith("P:")]
    assert len(positions) > 2000 and len(set(positions)) == len(positions)  # each pass on
    assert len({text for _, text in fast["reports"] if text.startswith("V:")}) == 1


# trigger pulses on output 4 in every pass of a scan (§4.5.2): every ZI counts from ZP
# (multiple mode), and at multiples of ZI (grid mode), 20 counts a pass
MULTIPLE = "[MC00] ZM2,ZP5,ZI10,MA3,WS0,EM1\n[MC01] MR20,WS0,WA2,RP,RP\n"
GRID = "[MC00] ZM3,ZI7,MA-500,WS0,EM1\n[MC01] MR28,WS0,WA2,TP,RP,RP\n"


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("source", [MULTIPLE, GRID], ids=["multiple", "grid"])
def test_trigger_pulses_of_a_scan_are_skipped_exactly(source, model):
    skips = same_as_stepping(program_of(source), [5, 900, 20_000], model)
    assert sum(s.passes for s in skips if s.shift) > 300
    # two pulses, on and off
    assert any(shapes.count(s.shape, shapes.OUTPUTS) >= 4 for s in skips if s.shift)


def test_a_scan_whose_shift_is_off_the_grid_is_stepped_as_it_must_be():
    # 20 counts a pass on a grid of 7: the pulses fall elsewhere in each pass
    source = "[MC00] ZM3,ZI7,EM1\n[MC01] MR20,WS0,WA2,RP,RP\n"
    skips = same_as_stepping(program_of(source), [2_000], "c-863")
    assert sum(s.passes for s in skips if s.shift) < 20


def test_a_skip_stops_where_a_power_of_two_is_crossed():
    # passes on the way compute with fractional positions, whose floats round otherwise in
    # another power of two: a pass spanning 60..62 moves on one count, to 61..63, and stops
    # before 62..64 reaches [64, 128)
    assert _within_binade(60, 62, 1, 100) == 1
    assert _within_binade(64, 70, 1, 100) == 57  # up to 121..127
    assert _within_binade(-70, -64, -1, 100) == 57  # the same below zero
    assert _within_binade(-3, 5, 1, 100) == 0  # across zero
    assert _within_binade(2**36, 2**36 + 10, 10**6, 10**9) == (2**36 - 11) // 10**6


# -- the property: skipping passes that move on the way changes nothing but the speed -----
body = st.lists(st.sampled_from([
    ("MR", 1), ("MR", -3), ("MR", 17), ("MR", 250), ("MA", 900), ("WS", 0), ("WA", 1),
    ("WA", 3), ("TP", None), ("TD", None), ("TE", None), ("TV", None), ("TT", None),
    ("TS", None), ("CN", 1), ("CF", 1), ("SV", 3000), ("AB", None), ("ST", None)]),
    min_size=1, max_size=7)
start = st.sampled_from([0, 61, -5, 1020, 4094, -70_000, 2**20 - 40])
tail = st.sampled_from([[("RP", 65535)], [("WA", 2), ("RP", 30), ("RP", 65535)],
                        [("EM", 4)], [("EM", 3)]])
limits = st.sampled_from([None, (-90_000, 5000)])


trigger = st.sampled_from([[], [("ZM", 2), ("ZP", 5), ("ZI", 10)], [("ZM", 2), ("ZI", -3)],
                           [("ZM", 3), ("ZI", 7)], [("ZM", 3), ("ZI", 17)], [("ZM", 1)]])


@pytest.mark.slow
@settings(max_examples=budget(150), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(start, body, tail, limits, trigger, st.sampled_from(MODELS),
       st.lists(st.integers(10, 9_000), min_size=1, max_size=3))
def test_passes_moving_on_the_way_skipped_give_what_stepping_gives(at, ops, loop, hard, pulses,
                                                                   model, times):
    slots = {0: [("EM", 3)], 3: [("MA", at), ("WS", 0), *pulses, ("EM", 4)], 4: ops + loop}
    program = Program({s: Macro(s, f"MC{s:02d}", [Op(m, a) for m, a in code])
                       for s, code in slots.items()})
    same_as_stepping(program, sorted(set(times)), model, Options(hard_limits=hard))
