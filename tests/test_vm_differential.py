"""The VM against a small, independent, time-free interpreter written straight from SPEC §3.

Random programs of calls, repeats, conditions, outputs and reports run on both;
the order of reports and of output patterns, and whether the program ends,
must agree. Programs the reference does not finish within its step budget are
not terminating and are left out.
"""
from __future__ import annotations

from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from mercmac.compiler.program import Macro, Op, Program
from mercmac.timespec import Press
from mercmac.sim.simulate import simulate

BUDGET = 3000  # executed commands


class Reference:
    """SPEC §3, line by line, without time: no waits and no motion in these programs."""

    def __init__(self, macros: dict[int, list[tuple[str, int | None]]], inputs: set[int]):
        self.macros, self.inputs = macros, inputs
        self.reports: list[str] = []
        self.patterns: list[int] = []
        self.outputs = 0

    def run(self) -> bool:
        """True if the program ended within the budget."""
        if 0 not in self.macros:
            return True
        slot, pc, return_point = 0, 0, None
        counters: dict[tuple[int, int], int] = {}  # (slot, index of the RP) -> count
        jumped: dict[int, int] = {}  # slot -> index of the RP that last jumped
        counters_of = lambda s: [k for k in counters if k[0] == s]  # noqa: E731
        for _ in range(BUDGET):
            line = self.macros[slot]
            exit_macro = pc >= len(line)
            if not exit_macro:
                name, n = line[pc]
                pc += 1
                if name == "EM" and n in self.macros:
                    # "stores 'continue after this EM in the current macro' ... and starts n"
                    return_point = (slot, pc)
                    slot, pc = n, 0
                    for k in counters_of(n):  # "Counters of a macro reset when it is entered"
                        del counters[k]
                    jumped.pop(n, None)
                elif name == "RP":
                    key = (slot, pc - 1)
                    counters[key] = n if key not in counters else counters[key] - 1
                    if counters[key] > 0:
                        jumped[slot] = pc - 1
                        pc = 0
                    else:
                        del counters[key]
                elif name in ("XN", "XF"):
                    exit_macro = (n in self.inputs) != (name == "XN")
                else:
                    self._effect(name, n, counters.get((slot, jumped.get(slot)), 0))
            if exit_macro:
                if return_point is None:
                    return True
                (slot, pc), return_point = return_point, None
        return False

    def _effect(self, name: str, n: int | None, remaining: int) -> None:
        before = self.outputs
        if name == "CN":
            self.outputs |= 1 << (n - 1)
        elif name == "CF":
            self.outputs &= ~(1 << (n - 1))
        elif name == "CP":
            self.outputs = n
        elif name == "TI":
            self.reports.append(f"X:{remaining:+011d}")
        elif name == "TB":
            self.reports.append("B:0")
        if self.outputs != before:
            self.patterns.append(self.outputs)


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


@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(programs, st.sets(st.integers(1, 4)))
def test_vm_agrees_with_the_reference_interpreter(macros, inputs):
    reference = Reference(macros, inputs)
    assume(reference.run())
    program = Program({s: Macro(s, f"MC{s:02d}", [Op(m, a) for m, a in ops])
                       for s, ops in macros.items()})
    presses = [Press(tuple(sorted(inputs)), 0, None)] if inputs else []
    run = simulate(program, presses=presses, until_ms=BUDGET + 10)
    assert [r.text for r in run.record.reports] == reference.reports
    assert [o.pattern for o in run.record.outputs] == reference.patterns
    assert run.halted


def test_the_reference_itself_follows_the_manual_examples():
    # RP9 runs the line 10 times; the one return point of §3.8.4
    ten = Reference({0: [("TB", None), ("RP", 9)]}, set())
    assert ten.run() and ten.reports == ["B:0"] * 10
    nested = Reference({0: [("EM", 1), ("CN", 4)], 1: [("EM", 2), ("CN", 1)], 2: [("CN", 2)]}, set())
    assert nested.run() and nested.outputs == 0b0011
    forever = Reference({0: [("TB", None), ("RP", 3), ("EM", 1)],
                         1: [("EM", 1)]}, set())
    assert not forever.run()
