"""The position signal of a VCD inside a shifted skip: where the skipped passes
start, and the last pass's moves sampled as plain stepping samples them."""
from __future__ import annotations

import io
import re

from helpers.compiling import program_of
from mercmac.sim.simulate import machine_for
from mercmac.sim.vcd import VcdObserver
from mercmac.vm import events as ev

SAW = "macro m { MR 3000, WS 0, MR -2900, WS 0, goto m }\nautostart { goto m }\n"
UNTIL_MS = 600_000


def dump(mode: str) -> tuple[list, list]:
    """The position changes of a run's VCD, and its skips."""
    out = io.StringIO()
    vcd = VcdObserver(out)
    machine, record = machine_for(program_of(SAW), fast_forward=mode, listeners=[vcd.on_event])
    machine.power_on()
    machine.run_until(UNTIL_MS)
    vcd.close(UNTIL_MS * 1000)
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
