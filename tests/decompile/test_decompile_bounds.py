"""`decompile` of any 32-slot program does bounded work and still round-trips.

Before, a chain of conditional slots (`[MCi] XN1,EM(i+1),MR5`) was folded into one
`when` nested 32 deep, and the compiler lowers a nested block that calls on twice per
level: 2^depth lowerings per candidate (16 slots 1 s, 24 past 300 s). The work is
counted here as the statement sequences the compiler lowers, not timed (the times are
in benchmarks/decompile_speed.py).
"""
from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from benchmarks.decompile_speed import chain
from mercmac.commands import Mnemonic
from helpers.budgets import budget
from helpers.decompiling import round_trip
from helpers.programs import RAW_COMMANDS

# Statement sequences one decompile may lower: the worst of the benchmark's programs
# needs about 3,300; the chain of 20 needed over a million per candidate before.
MAX_LOWERED = 100_000


class TooMuchWork(Exception):
    pass


@pytest.fixture
def counted(monkeypatch):
    """Counts the compiler's statement lowerings; stops the decompile past MAX_LOWERED."""
    from mercmac.compiler import lower

    original, count = lower._Lowerer.seq, [0]

    def seq(self, *args, **kw):
        count[0] += 1
        if count[0] > MAX_LOWERED:
            raise TooMuchWork(f"more than {MAX_LOWERED:,} statement sequences lowered")
        return original(self, *args, **kw)

    monkeypatch.setattr(lower._Lowerer, "seq", seq)
    return count


# The shapes that took exponential work (16 slots was still cheap); the fan-out tree, the
# every-slot-calls-15 mesh and the loop chain of the benchmark never did.
PROGRAMS = {f"chain of {n}": chain(n) for n in (20, 24, 32)}


@pytest.mark.parametrize("name", PROGRAMS)
def test_worst_shapes_round_trip_with_bounded_work(counted, name):
    source = round_trip(PROGRAMS[name])
    assert "Decompiled by mercmac" in source


def test_a_chain_of_32_is_nested_at_most_a_few_deep(counted):
    from mercmac.decompile.source import MAX_NEST

    source = round_trip(chain(32))
    depth = max(len(line) - len(line.lstrip(" ")) for line in source.split("\n")) // 4
    assert depth <= MAX_NEST + 1  # the macro's body, and its folded blocks


CONDITIONS = st.sampled_from(["XN1", "XF2", "XN3"])


@st.composite
def free_programs(draw):
    """Raw programs of all 32 slots, each 1-16 commands, with EMs to any slot."""
    em = st.integers(1, 31).map(lambda s: f"{Mnemonic.EM}{s}")
    line = st.lists(st.one_of(RAW_COMMANDS, em, em), min_size=1, max_size=16).map(",".join)
    return {slot: draw(line) for slot in range(32)}


@st.composite
def chained_programs(draw):
    """All 32 slots, each a condition, some commands, a call of the next slot and more
    commands: every slot could fold into its caller (the shape that nested 32 deep)."""
    macros = {}
    for slot in range(32):
        ops = draw(st.lists(CONDITIONS, min_size=1, max_size=2))
        ops += draw(st.lists(RAW_COMMANDS, max_size=3))
        ops += [f"{Mnemonic.EM}{slot + 1}"] if slot < 31 else []
        macros[slot] = ",".join(ops + draw(st.lists(RAW_COMMANDS, min_size=1, max_size=3)))
    return macros


@pytest.mark.slow
@settings(max_examples=budget(20), deadline=None, suppress_health_check=list(HealthCheck))
@given(st.one_of(free_programs(), chained_programs()))
def test_random_32_slot_programs_round_trip_with_bounded_work(counted, macros):
    counted[0] = 0
    round_trip(macros)
