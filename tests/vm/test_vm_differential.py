"""The VM against the tests' reference interpreter (`semantics.Firmware`, written
straight from docs/simulator.md, time-free), the one the lowering tests use too.

Random programs of calls, repeats, conditions, outputs and reports run on both;
the order of reports and of output patterns, and whether the program ends,
must agree. Programs the reference does not finish within its step budget are
not terminating and are left out.
"""
from __future__ import annotations

from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from mercmac.compiler.program import Macro, Op, Program
from mercmac.sim.simulate import simulate_program
from mercmac.timespec import Press
from helpers.budgets import budget
from helpers.semantics import Firmware

BUDGET = 3000  # executed commands
SLOTS = range(0, 6)
command = st.one_of(
    st.tuples(st.sampled_from(["CN", "CF"]), st.integers(1, 4)),
    st.tuples(st.just("CP"), st.integers(0, 15)),
    st.tuples(st.sampled_from(["TI", "TB"]), st.none()),
    st.tuples(st.sampled_from(["XN", "XF"]), st.integers(1, 4)),
    st.tuples(st.just("EM"), st.integers(1, 7)),  # 6 and 7 are never defined
    st.tuples(st.just("RP"), st.integers(0, 3)),
)
programs = st.dictionaries(st.sampled_from(SLOTS), st.lists(command, min_size=1, max_size=7),
                           min_size=1, max_size=6)


@settings(max_examples=budget(400), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(programs, st.sets(st.integers(1, 4)))
def test_vm_agrees_with_the_reference_interpreter(macros, inputs):
    reference = Firmware(macros, inputs)
    assume(reference.run(BUDGET))
    program = Program({s: Macro(s, f"MC{s:02d}", [Op(m, a) for m, a in ops])
                       for s, ops in macros.items()})
    presses = [Press(tuple(sorted(inputs)), 0, None)] if inputs else []
    run = simulate_program(program, presses=presses, until_ms=BUDGET + 10)
    assert [r.text for r in run.record.reports] == reference.reports
    assert [o.pattern for o in run.record.outputs] == reference.patterns
    assert run.halted


def test_the_reference_itself_follows_the_manual_examples():
    # RP9 runs the line 10 times; the one return point of §3.8.4
    ten = Firmware({0: [("TB", None), ("RP", 9)]}, set())
    assert ten.run(BUDGET) and ten.reports == ["B:0"] * 10
    nested = Firmware({0: [("EM", 1), ("CN", 4)], 1: [("EM", 2), ("CN", 1)], 2: [("CN", 2)]}, set())
    assert nested.run(BUDGET) and nested.outputs == 0b0011
    forever = Firmware({0: [("TB", None), ("RP", 3), ("EM", 1)],
                        1: [("EM", 1)]}, set())
    assert not forever.run(BUDGET)
    # the manual's TI example: 0 before the first RP, then the remaining count
    counted = Firmware({0: [("TI", None), ("RP", 2)]}, set())
    assert counted.run(BUDGET) and counted.reports == ["X:+0000000000", "X:+0000000002",
                                                       "X:+0000000001"]
    # a bare RP is 65535 (docs/simulator.md, "Repeat counters"); XN ends the macro when its
    # input is off
    bare = Firmware({0: [("TB", None), ("XN", 1), ("RP", None)]}, set())
    assert bare.run(BUDGET) and bare.effects == ["TB"]
