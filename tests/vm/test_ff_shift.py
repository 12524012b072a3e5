"""Shifted fast-forward: passes that differ only by a constant shift of position and target
are skipped up to the next boundary, exactly as plain stepping runs them."""
from __future__ import annotations

import io
import math
from unittest import mock

from click.testing import CliRunner

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from helpers.budgets import budget
from helpers.compiling import program_of
from helpers.simulation import skips, states
from mercmac.compiler.program import Macro, Op, Program
from mercmac.timespec import Press
from mercmac.vm.events import Motion
from mercmac.vm.shapes import Move, Tag
from mercmac.vm.skips import _same_arrival
from mercmac.vm.models import Options
from mercmac.sim import record as record_module
from mercmac.cli import main
from mercmac.render import progress as progress_module
from mercmac.cli import run as sim_run
from mercmac.sim.simulate import machine_for, simulate_program

DAY_MS = 86_400_000
JOG = "autostart {\n  every 10ms { MR 1, WS 0 }\n}\n"  # MR1,WS0,WA10,RP,RP


def test_a_jog_loop_is_skipped_and_lands_where_stepping_does():
    program = program_of(JOG)
    fast, record = states(program, "all", [5_000, 60_000, 200_000])
    plain, _ = states(program, "off", [5_000, 60_000, 200_000])
    assert fast == plain
    assert any(s.shift == 1 for s in skips(record))


def test_a_jog_loop_runs_1500_days_into_the_soft_limit():
    machine, record = machine_for(program_of(JOG))
    machine.power_on()
    machine.run_until(1500 * DAY_MS)
    assert machine.target == machine.position() == 100_000_000  # JH of the C-863 (§3.4.1)
    assert [h.rule for h in record.hazards] == ["soft-limit-clamp"]
    assert len(record.timeline) < 1000


def test_the_clamp_comes_at_the_pass_stepping_reaches_it():
    program = program_of("autostart {\n  JH 700\n  every 10ms { MR 3, WS 0, TP }\n}\n")
    fast, record = states(program, "all", [20_000])
    plain, _ = states(program, "off", [20_000])
    assert fast == plain and skips(record)
    assert fast["hazards"][0][1] == "soft-limit-clamp"


def test_position_reports_of_skipped_passes_are_the_shifted_texts():
    program = program_of("autostart {\n  every 5ms { MR -7, WS 2, TP, TT, TE }\n}\n")
    with mock.patch.object(record_module, "CAP", 400):
        fast, record = states(program, "all", [30_000])
        plain, _ = states(program, "off", [30_000])
    assert fast == plain and any(s.shift == -7 for s in skips(record))
    texts = [text for _, text in fast["reports"]]
    assert texts[:3] == ["P:-0000000007", "T:-0000000007", "E:+0000000000"]


def test_a_hard_limit_is_a_boundary():
    program = program_of(JOG)
    options = Options(hard_limits=(-1000, 250))
    fast, record = states(program, "all", [10_000], options=options)
    plain, _ = states(program, "off", [10_000], options=options)
    assert fast == plain and skips(record)
    assert [h[1] for h in fast["hazards"]] == ["hard-limit"]


def test_a_button_release_is_a_boundary():
    program = program_of("[MC00] EM1,WA10,RP,RP\n[MC01] XN1,MR20,WS0\n")
    presses = [Press((1,), 100, 4321)]
    fast, record = states(program, "all", [3000, 9000], presses)
    plain, _ = states(program, "off", [3000, 9000], presses)
    assert fast == plain and skips(record)


def move_of(arrival: float, dts: tuple[float, ...]) -> Move:
    """A move one count on from the pass's start, arriving `arrival` us after its start in
    segments of `dts` us."""
    return Move(Tag.MOVE, 0, Motion.MOVE, 1, 0, None, arrival, dts, 0, 1)


def test_an_arrival_that_floats_could_round_otherwise_is_not_skipped_that_far():
    # segments of whole microseconds from a command's whole time: every float sum is exact
    # below 2**53 us, and no further
    item = move_of(3, (1.0, 2.0))
    assert _same_arrival(item, 0, 10, 100) == 100
    assert _same_arrival(item, 2**53 - 1000, 10, 10**6) < 100
    # a hair over a whole number of us (the C-663's 2000.0000000000002 twice): the sum rounds
    # either way with the time, so no time is safe by this rule (_same_time_binade's is)
    item = move_of(4000, (2000.0000000000002, 2000.0000000000002))
    assert _same_arrival(item, 0, 10, 100) == 0
    # 0.25 us from the next microsecond: safe while an ulp of the time is far smaller
    item = move_of(4, (1.5, 2.25))
    safe = _same_arrival(item, 0, 2**30, 10**9)
    assert 0 < safe < 10**9
    latest = (safe + 1) * 2**30 + 5
    assert math.ulp(float(latest)) * 2 >= 0.25 or safe == 10**9


# -- the property: shifted skipping changes nothing but the speed ----------------
command = st.one_of(
    st.tuples(st.just("MR"), st.sampled_from([1, -1, 7, -40, 3000, 250_000])),
    st.tuples(st.just("MA"), st.sampled_from([0, 500])),
    st.tuples(st.just("WS"), st.sampled_from([0, 2])),
    st.tuples(st.just("WA"), st.sampled_from([0, 1, 3, 10])),
    st.tuples(st.sampled_from(["TP", "TT", "TE", "TV", "TS", "TI"]), st.none()),
    st.tuples(st.sampled_from(["CN", "CF"]), st.integers(1, 2)),
    st.tuples(st.sampled_from(["JH", "JL"]), st.sampled_from([-300, 900, 5000])),
    st.tuples(st.just("XN"), st.integers(1, 2)),
    st.tuples(st.just("AB"), st.none()),
    st.tuples(st.just("DH"), st.sampled_from([0, 77])),
    st.tuples(st.just("ZM"), st.sampled_from([0, 2])),
    st.tuples(st.just("SV"), st.sampled_from([3000, 45000])),
    st.tuples(st.just("EM"), st.integers(1, 2)),
)
jog = st.lists(st.sampled_from([("MR", 1), ("MR", -3), ("MR", 9), ("WS", 0), ("WA", 4),
                                ("TP", None), ("TT", None)]), min_size=1, max_size=4)
loop_tail = st.sampled_from([[("RP", 65535)], [("RP", 7), ("RP", 65535)],
                             [("WA", 2), ("RP", 40), ("RP", 65535)], [("EM", 0)]])
macros = st.tuples(
    st.lists(command, max_size=2),  # a prologue: limits, home, speed
    jog | st.lists(command, min_size=1, max_size=4),
    loop_tail,
    st.dictionaries(st.integers(1, 2), st.lists(command | jog.map(tuple), min_size=1,
                                                max_size=3), max_size=2),
).map(lambda p: (p[0], p[1] + p[2], {s: [c for c in cs if isinstance(c[0], str)]
                                      for s, cs in p[3].items()}))
limits = st.sampled_from([None, (-2000, 600), (-50, 40_000)])
presses = st.lists(st.tuples(st.integers(1, 2), st.integers(0, 8000), st.integers(0, 3000)),
                   max_size=2)


jogs = st.tuples(
    st.lists(st.tuples(st.sampled_from(["JH", "JL"]), st.sampled_from([-300, 900, 5000]))
             | st.tuples(st.just("SV"), st.sampled_from([3000, 45000])), max_size=2),
    st.lists(st.sampled_from([("MR", 1), ("MR", -3), ("MR", 9), ("WS", 0), ("WS", 1),
                              ("WA", 4), ("TP", None), ("TT", None), ("TS", None),
                              ("CN", 1), ("CF", 1), ("XN", 1), ("EM", 1)]),
             min_size=1, max_size=5),
    loop_tail,
    st.just({1: [("MR", 2), ("WS", 0)]}),
).map(lambda p: (p[0], p[1] + p[2], p[3]))


@pytest.mark.slow
@settings(max_examples=budget(300), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(macros | jogs, limits, presses, st.lists(st.integers(20, 12_000), min_size=1, max_size=3))
def test_shifted_fast_forward_gives_what_plain_stepping_gives(parts, hard, buttons, times):
    prologue, body, others = parts
    slots = {0: [], 3: prologue + body}
    slots[0] = [("EM", 3)]  # autostart calls the loop's macro: its counters reset once
    slots.update({s: ops or [("WA", 1)] for s, ops in others.items()})
    program = Program({s: Macro(s, f"MC{s:02d}", [Op(m, a) for m, a in ops])
                       for s, ops in slots.items()})
    pressed = [Press((n,), t, t + held) for n, t, held in buttons]
    options = Options(hard_limits=hard)
    checkpoints = sorted(set(times))
    with mock.patch.object(record_module, "CAP", 40):  # lists fill up and counts start
        fast, _ = states(program, "all", checkpoints, pressed, options)
        plain, _ = states(program, "off", checkpoints, pressed, options)
    assert fast == plain


# -- progress and Ctrl-C ---------------------------------------------------------
class Interrupting:
    """A progress hook that presses Ctrl-C at its `after`-th update."""

    def __init__(self, after: int):
        self.after, self.seen, self.closed = after, [], False

    def update(self, now_ms: float) -> None:
        self.seen.append(now_ms)
        if len(self.seen) == self.after:
            raise KeyboardInterrupt

    def close(self) -> None:
        self.closed = True


BLINK_TP = "autostart {\n  every 20ms { CN 1, TP, WA 5, CF 1 }\n}\n"


def test_ctrl_c_ends_the_run_where_it_is_and_keeps_what_came():
    hook = Interrupting(after=6)
    run = simulate_program(program_of(BLINK_TP), until_ms=DAY_MS, progress=hook)
    assert run.interrupted and hook.closed
    assert run.until_ms == hook.seen[-1] < DAY_MS
    assert run.record.reports and run.record.outputs


def test_progress_slices_change_nothing_but_the_skips():
    program = program_of("autostart {\n  every 7ms { MR 3, WS 1, TP, CN 1, WA 2, CF 1 }\n}\n")
    quiet = simulate_program(program, until_ms=40_000)
    hook = Interrupting(after=-1)
    told = simulate_program(program, until_ms=40_000, progress=hook)
    assert not told.interrupted and hook.seen[-1] == 40_000
    assert len(hook.seen) > 3  # it was sliced
    for run in (quiet, told):
        assert run.final() == quiet.final()
    assert ([(r.t, r.text) for r in told.record.reports]
            == [(r.t, r.text) for r in quiet.record.reports])
    assert ([(o.t, o.pattern) for o in told.record.outputs]
            == [(o.t, o.pattern) for o in quiet.record.outputs])
    for what in ("reports", "outputs"):
        assert told.record.dropped[what] == quiet.record.dropped[what]


def test_ctrl_c_in_the_cli_prints_the_timeline_and_summary_and_exits_130(tmp_path):
    source = tmp_path / "blink.mcm"
    source.write_text(BLINK_TP)
    with mock.patch.object(sim_run, "_progress", lambda until: Interrupting(after=4)):
        result = CliRunner().invoke(main, ["sim", str(source), "--until", "1d"])
    assert result.exit_code == 130, result.output
    assert "Summary" in result.output and "interrupted" in result.output


def test_the_progress_line_shows_time_and_rate(monkeypatch):
    monkeypatch.setattr(progress_module, "DELAY_S", 0)
    monkeypatch.setattr(progress_module, "EVERY_S", 0)
    out = io.StringIO()
    line = progress_module.ProgressLine(out, 1500 * DAY_MS)
    line.update(3 * DAY_MS)
    line.close()
    text = out.getvalue()
    assert "3d 00:00:00 of 1500d 00:00:00" in text and "simulated s per s" in text
    assert text.endswith("\r\x1b[K")
