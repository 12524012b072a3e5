"""Joint fast-forward of a rig against stepping it: two controllers wired to each
other, running random programs that move, move on the way, report while moving, set the
trigger, and wait on each other's lines, give the same wire edges, reports, outputs,
hazards and final state whether the rig's repeating passes are skipped or stepped; also
when the wires join lines the programs never set, so that no pass changes a wire."""
from __future__ import annotations

import io
import shutil
import tempfile
from pathlib import Path
from unittest import mock

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from helpers.budgets import budget
from helpers.rigs import rig_of, rig_of_many
from helpers.simulation import same_samples, vcd_values
from mercmac.compiler import compile_file
from mercmac.rig.load import read_rig
from mercmac.sim import record as record_module
from mercmac.sim.simulate import Simulation, simulate
from mercmac.sim.vcd import Dump
from mercmac.vm import events as ev

WIRES = '"x.out1 -> y.in1", "y.out2 -> x.in2"'
QUIET = '"x.out3 -> y.in3", "y.out4 -> x.in4"'  # lines the programs never set: no edge


def run(path: Path, until_ms: int, fast_forward: bool, dumped: dict | None = None):
    """The rig run to until_ms, skipping or stepping; its VCD's positions into `dumped`."""
    rig = read_rig(str(path)).rig
    programs = {c.name: compile_file(c.program, target=c.model).program for c in rig.controllers}
    out = io.StringIO()
    dump = Dump(out, [c.name for c in rig.controllers])
    with mock.patch.object(record_module, "CAP", 10**7):  # every event listed: comparable
        result = simulate(rig, programs, until_ms=until_ms, listeners=dump.listeners(),
                          fast_forward="all" if fast_forward else "off")
    dump.close(until_ms * 1000)
    if dumped is not None:
        dumped.update(vcd_values(out.getvalue()))
    return result


def outcome(result) -> dict:
    """What a rig run shows: edges, and per controller its record and final machine."""
    seen = {"edges": [(e.t, str(e.wire), e.level) for e in result.edges],
            "dropped": result.edges_dropped}
    for name, r in result.runs.items():
        m = r.machine
        seen[name] = (r.final(), [(e.t, e.pattern) for e in r.record.outputs],
                      [(e.t, e.text) for e in r.record.reports], dict(r.record.dropped),
                      [(h.t, h.message) for h in r.record.hazards],
                      [e for e in r.record.events if not isinstance(e, ev.FastForwarded)
                       and not isinstance(e, ev.MoveStarted)],
                      # a blocked machine's next command time is unused (it is set when the
                      # wait ends), and a skip moves it on with the clock
                      m.counters, m.ip, m.wake if m.block is None else None, m.axis.segs,
                      m.axis.final, m.axis.plan)
    return seen


def skipped(result) -> int:
    return sum(e.passes for r in result.runs.values() for e in r.record.events
               if isinstance(e, ev.FastForwarded))


x_ops = st.lists(st.sampled_from(["MR3", "MR-1", "MR40", "WS0", "WA2", "WA5", "TP", "TT", "TV",
                                  "CN1", "CF1", "WN2", "WF2", "TS"]), min_size=1, max_size=6)
y_ops = st.lists(st.sampled_from(["WN1", "WF1", "MR2", "MR17", "WS0", "WA1", "TP", "TE",
                                  "CN2", "CF2"]), min_size=1, max_size=6)
tails = st.sampled_from(["RP,RP", "WA3,RP,RP", "EM1"])
prologues = st.sampled_from(["", "ZM2,ZP0,ZI5,", "MA-70000,WS0,", "MA1020,WS0,"])


@pytest.mark.slow
@settings(max_examples=budget(60), deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(x_ops, y_ops, tails, tails, prologues, st.integers(300, 6_000),
       st.sampled_from([WIRES, QUIET]))
def test_a_wired_rig_skipped_gives_what_stepping_gives(xs, ys, x_tail, y_tail, prologue,
                                                        until_ms, wires):
    folder = Path(tempfile.mkdtemp())
    try:
        path = rig_of(folder, f"[MC00] {prologue}EM1\n[MC01] {','.join(xs)},{x_tail}\n",
                      f"[MC00] EM1\n[MC01] {','.join(ys)},{y_tail}\n", wires)
        fast_vcd, plain_vcd = {}, {}
        fast = run(path, until_ms, True, fast_vcd)
        plain = run(path, until_ms, False, plain_vcd)
        assert outcome(fast) == outcome(plain)
        same_samples(fast_vcd, plain_vcd)  # a move across a skip is sampled as stepping has it
    finally:
        shutil.rmtree(folder)


def test_a_rig_that_moves_on_the_way_skips_together(tmp_path):
    # x reports and steps on the way, 1 count a pass, and pulses y, which steps along
    path = rig_of(tmp_path, "[MC00] EM1\n[MC01] TT,MR1,CN1,WA1,CF1,RP,RP\n",
                  "[MC00] EM1\n[MC01] WN1,MR1,TP,WF1,RP,RP\n", WIRES)
    fast_vcd, plain_vcd = {}, {}
    fast, plain = run(path, 20_000, True, fast_vcd), run(path, 20_000, False, plain_vcd)
    assert outcome(fast) == outcome(plain)
    assert skipped(fast) > 1000
    assert same_samples(fast_vcd, plain_vcd) > 10


def test_passes_that_change_no_wire_skip_together(tmp_path):
    # x blinks an output no wire takes and y steps on its own: the wires never change
    path = rig_of(tmp_path, "[MC00] EM1\n[MC01] CN1,WA2,CF1,RP,RP\n",
                  "[MC00] EM1\n[MC01] MR1,TP,WA5,RP,RP\n", QUIET)
    fast, plain = run(path, 20_000, True), run(path, 20_000, False)
    assert outcome(fast) == outcome(plain)
    assert not fast.edges and skipped(fast) > 500  # of about 1,000 joint passes


# -- rigs of 2-16 controllers: groups that wires join run on their own, each skipping alone --
ops = st.lists(st.sampled_from(["MR3", "MR-1", "MR40", "MA900", "WS0", "WA2", "WA5", "WA7",
                                "TP", "TT", "CN1", "CF1", "CN2", "CF2", "WN1", "WF1", "WN2",
                                "WF2", "WN3"]), min_size=1, max_size=5)


@st.composite
def many(draw) -> tuple[list[str], list[str]]:
    """Programs of 2-16 controllers looping at different lengths, and wires among them
    (none, pairs, chains or rings: each input driven by one output at most)."""
    n = draw(st.integers(2, 16))
    programs = []
    for i in range(n):
        body = ",".join(draw(ops)) + ",TP" * draw(st.integers(0, 3))  # loops of other lengths
        tail = draw(st.sampled_from(["RP,RP", "WA3,RP,RP", "EM1", "RP30,WA9,RP,RP"]))
        programs.append(f"[MC00] EM1\n[MC01] {body},{tail}\n")
    wires, driven = [], set()
    for _ in range(draw(st.integers(0, 2 * n))):
        source, target = draw(st.integers(0, n - 1)), draw(st.integers(0, n - 1))
        out, into = draw(st.integers(1, 2)), draw(st.integers(1, 3))
        if source != target and (target, into) not in driven:
            driven.add((target, into))
            wires.append(f"c{source}.out{out} -> c{target}.in{into}")
    return programs, wires


@pytest.mark.slow
@settings(max_examples=budget(40), deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(many(), st.integers(200, 3_000))
def test_a_rig_of_many_skipped_gives_what_stepping_gives(rig, until_ms):
    programs, wires = rig
    folder = Path(tempfile.mkdtemp())
    try:
        path = rig_of_many(folder, programs, wires)
        assert outcome(run(path, until_ms, True)) == outcome(run(path, until_ms, False))
    finally:
        shutil.rmtree(folder)


def test_pairs_that_no_wire_joins_skip_each_on_their_own(tmp_path):
    # four handshake pairs of loops of different lengths: jointly they would almost never
    # repeat; pair by pair they repeat at once
    leader = "[MC00] EM1\n[MC01] MR100,WS0,CN1,WN2,CF1,WF2{},RP,RP\n"
    follower = "[MC00] EM1\n[MC01] WN1,MR10,WS0,CN2,WF1,CF2,RP,RP\n"
    programs, wires = [], []
    for pair in range(4):
        programs += [leader.format(",TP" * (2 * pair + 1)), follower]
        wires += [f"c{2 * pair}.out1 -> c{2 * pair + 1}.in1",
                  f"c{2 * pair + 1}.out2 -> c{2 * pair}.in2"]
    path = rig_of_many(tmp_path, programs, wires)
    fast, plain = run(path, 30_000, True), run(path, 30_000, False)
    assert outcome(fast) == outcome(plain)
    for name, r in fast.runs.items():
        assert sum(e.passes for e in r.record.events if isinstance(e, ev.FastForwarded)) > 50


W3 = {  # a token ring whose joint state comes back every 2.58 s with other shifts each time
    "left": "[MC00] EM10\n[MC10] CN1,WN3,EM29,CF4,CF1,WF3,RP250\n[MC29] TT,TT,XF3\n",
    "z": "[MC00] EM12\n[MC12] WN2,CF4,TC1,CN1,WF2,EM20,TT,CF1,MA3917,RP250\n[MC20] XN2\n",
    "b2": "[MC00] EM7\n[MC07] WN1,MA-4531,CN2,WF1,MR2530,EM31,CF2,RP250\n[MC31] XF1,XF2,TT,MA4425\n",
}


def test_a_ring_whose_passes_never_repeat_keeps_no_pass_shapes(tmp_path):
    # its keys come back with long passes that never repeat: their shapes were kept, one per
    # key, 400 MB a simulated second; now a pass's shape is made only when its shifts repeat
    path = rig_of_many(tmp_path, list(W3.values()),
                       ["c1.out1 -> c0.in3", "c0.out1 -> c2.in1", "c2.out2 -> c1.in2"])
    rig = read_rig(str(path)).rig
    programs = {c.name: compile_file(c.program, target=c.model).program for c in rig.controllers}
    sim = Simulation(rig, programs)
    sim.power_on()
    sim.run_until(4_000)
    (group,) = sim.groups
    seen = group.joint.seen.values()
    kept = sum(len(shape) for visit in seen if visit.shapes for shape in visit.shapes)
    assert kept == group.joint.kept <= 10_000
    assert all(visit.since is None or visit.since.since is None for visit in seen)
