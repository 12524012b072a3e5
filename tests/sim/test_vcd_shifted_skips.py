"""The position signal of a VCD inside a shifted skip: where the skipped passes
start, and the last pass's moves sampled as plain stepping samples them."""
from __future__ import annotations

import io
import re

from hypothesis import given, settings
from hypothesis import strategies as st

from helpers.budgets import budget
from helpers.compiling import program_of
from helpers.simulation import same_samples, vcd_values
from mercmac.sim.simulate import machine_for
from mercmac.sim.vcd import VcdObserver
from mercmac.vm import events as ev

SAW = "macro m { MR 3000, WS 0, MR -2900, WS 0, goto m }\nautostart { goto m }\n"
UNTIL_MS = 600_000


def dump(mode: str, source: str = SAW, until_ms: int = UNTIL_MS,
         press_ms: int | None = None) -> tuple[list, list]:
    """The position changes of a run's VCD, and its skips; button 4 pressed at press_ms."""
    out = io.StringIO()
    vcd = VcdObserver(out)
    machine, record = machine_for(program_of(source), fast_forward=mode,
                                  listeners=[vcd.on_event])
    if press_ms is not None:
        machine.schedule_input(press_ms, 4, True)
    machine.power_on()
    machine.run_until(until_ms)
    vcd.close(until_ms * 1000)
    text = out.getvalue()
    code = re.search(r"\$var integer 32 (\S+) position \$end", text).group(1)
    t, changes = 0, []
    for line in text.split("\n"):
        if line.startswith("#"):
            t = int(line[1:])
        elif line.endswith(" " + code) and line.startswith("b"):
            changes.append((t, int(line[1:].split()[0], 2)))
    return changes, [e for e in record.events if isinstance(e, ev.FastForwarded)]


def test_the_last_pass_of_a_shifted_skip_is_sampled_as_stepping_samples_it():
    fast, skips = dump("all")
    plain, _ = dump("off")
    (skip,) = skips
    last = skip.t + (skip.passes - 1) * skip.period
    inside = [c for c in fast if last <= c[0] < skip.t_to]
    assert len(inside) > 10  # the moves of the last pass, not one jump at its end
    stepped = dict(plain)
    assert all(stepped.get(t) == x for t, x in inside[1:-1])  # samples as stepping has them
    assert min(x for _, x in inside) == skip.position + (skip.passes - 1) * skip.shift


# re-commands its move at every pass while the stage still runs: the profile runs across
# each skip's end (the dump once wrote its old samples after the skip: out of time order)
CHASE = ("target C-863\nmacro m { TT, MR 1, when 4 { goto fin }, goto m }\n"
         "macro fin { CN 1 }\nautostart { goto m }\n")


def test_a_move_that_runs_across_a_skip_is_sampled_on_after_it_as_stepping_samples_it():
    fast, skips = dump("all", CHASE, 10_000, press_ms=5_000)  # raised VCDPhaseError
    plain, _ = dump("off", CHASE, 10_000, press_ms=5_000)
    assert skips and [t for t, _ in fast] == sorted(t for t, _ in fast)
    stepped = dict(plain)
    assert all(stepped[t] == x for t, x in fast if t in stepped)
    after = [t for t, _ in fast if skips[0].t_to <= t]
    assert after and all(t in stepped for t in after)  # sampled on as stepping samples


LOOPS = st.lists(st.sampled_from(["MR3", "MR-1", "MR40", "WS0", "WA2", "WA5", "TP", "TT", "TV",
                                  "CN1", "CF1", "TS", "MR1", "MA0"]), min_size=1, max_size=6)


@settings(max_examples=budget(40), deadline=None)
@given(LOOPS, st.sampled_from(["RP,RP", "WA3,RP,RP", "EM1"]),
       st.sampled_from(["", "MA-70000,WS0,", "MA1020,WS0,"]), st.integers(300, 20_000))
def test_a_skip_leaves_passes_out_of_the_dump_never_a_wrong_position(ops, tail, prologue,
                                                                      until_ms):
    """Wherever a dump of a run that skips gives the position, stepping gives the same one
    (`same_samples`), in time order (VCDPhaseError otherwise)."""
    source = f"[MC00] {prologue}EM1\n[MC01] {','.join(ops)},{tail}\n"
    fast = dump_values("all", source, until_ms)
    same_samples(fast, dump_values("off", source, until_ms))


def dump_values(mode: str, source: str, until_ms: int) -> dict:
    out = io.StringIO()
    vcd = VcdObserver(out)
    machine, _ = machine_for(program_of(source), fast_forward=mode, listeners=[vcd.on_event])
    machine.power_on()
    machine.run_until(until_ms)
    vcd.close(until_ms * 1000)
    return vcd_values(out.getvalue())
