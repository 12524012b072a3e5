"""Fast-forward of shifted passes that read the switches: TS shows the reference
and limit lines, which change only where a pass crosses the reference edge or a limit
switch, so those crossings end a skip (like soft limits) and the passes between are
skipped, exactly as plain stepping runs them."""
from __future__ import annotations

from unittest import mock

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from helpers.budgets import budget
from helpers.compiling import program_of
from helpers.simulation import skips, states
from mercmac.compiler.program import Macro, Op, Program
from mercmac.sim import record as record_module
from mercmac.vm.models import Options

# a scan that reads TS every pass, from well below the reference edge (at 0) across it
TS_SCAN = "autostart {\n  MA -3000, WS 0\n  every 10ms { MR 7, WS 0, TS }\n}\n"


def test_a_scan_that_reads_ts_is_skipped_up_to_the_reference_and_past_it():
    program = program_of(TS_SCAN)
    checkpoints = [2_000, 60_000, 600_000]
    fast, record = states(program, "all", checkpoints)
    plain, _ = states(program, "off", checkpoints)
    assert fast == plain
    shifted = [s for s in skips(record) if s.shift == 7]
    assert len(shifted) >= 2  # one before the edge, one after it
    assert len({text for _, text in plain["reports"]}) >= 2  # the reference bit changed


def test_a_scan_that_reads_ts_stops_before_a_limit_switch_as_stepping_does():
    program = program_of(TS_SCAN)
    options = Options(hard_limits=(-5000, 4000))
    fast, record = states(program, "all", [3_000, 30_000, 90_000], options=options)
    plain, _ = states(program, "off", [3_000, 30_000, 90_000], options=options)
    assert fast == plain and any(s.shift == 7 for s in skips(record))


# -- the property: skipping passes that read TS changes nothing but the speed ----------
jog = st.lists(st.sampled_from([("MR", 1), ("MR", -3), ("MR", 9), ("MR", 40), ("WS", 0),
                                ("WA", 4), ("TS", None), ("TP", None), ("TT", None),
                                ("CN", 1), ("CF", 1)]), min_size=1, max_size=5)
start = st.sampled_from([-3000, -120, -5, 0, 3, 200])
tail = st.sampled_from([[("RP", 65535)], [("WA", 2), ("RP", 40), ("RP", 65535)],
                        [("EM", 3)]])
limits = st.sampled_from([None, (-2000, 600), (-50, 40_000)])
reference = st.sampled_from([0, 17, -400])


@pytest.mark.slow
@settings(max_examples=budget(200), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(start, jog, tail, limits, reference, st.lists(st.integers(20, 12_000), min_size=1,
                                                     max_size=3))
def test_ts_passes_skipped_give_what_plain_stepping_gives(at, body, loop, hard, ref, times):
    prologue = [("MA", at), ("WS", 0)]
    slots = {0: [("EM", 3)], 3: prologue + [("EM", 4)], 4: body + loop}
    if loop == [("EM", 3)]:
        slots[4] = body + [("EM", 4)]
    program = Program({s: Macro(s, f"MC{s:02d}", [Op(m, a) for m, a in ops])
                       for s, ops in slots.items()})
    options = Options(hard_limits=hard, reference_at=ref)
    checkpoints = sorted(set(times))
    with mock.patch.object(record_module, "CAP", 40):  # lists fill up and counts start
        fast, _ = states(program, "all", checkpoints, options=options)
        plain, _ = states(program, "off", checkpoints, options=options)
    assert fast == plain
