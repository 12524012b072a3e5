"""A simulation run as plain data, and a run stepped or fast-forwarded to checkpoints, so that
two runs can be compared (docs/simulator.md, "Fast-forward": a skip lands where stepping does)."""
from __future__ import annotations

from mercmac.compiler.program import Program
from mercmac.sim.simulate import machine_for, schedule
from mercmac.vm import events as ev


def observed(record) -> dict:
    """What a simulation run recorded, as plain data to compare two runs (fast-forward on/off)."""
    return {
        "reports": [(r.t, r.text) for r in record.reports],
        "outputs": [(o.t, o.pattern) for o in record.outputs],
        "dropped": (record.dropped["reports"], record.dropped["outputs"]),
        "hazards": [(h.t, h.rule, h.where) for h in record.hazards],
        "ended": record.ended_at,
    }


def states(program: Program, mode: str, checkpoints: list[int], presses=(), options=None):
    """Reports, outputs, hazards and the machine at each checkpoint (ms), stepping or skipping."""
    machine, record = machine_for(program, fast_forward=mode, options=options)
    schedule(machine, presses)
    machine.power_on()
    seen = []
    for t in checkpoints:
        machine.run_until(t)
        m = machine
        seen.append((m.clock.now, m.position(), m.target, m.velocity(), m.moving(), m.macro,
                     m.ip, m.counters, m.block, m.wake, m.error, m.outputs_pattern()))
    return {**observed(record), "states": seen}, record


def skips(record) -> list[ev.FastForwarded]:
    """The skips of a run, in time order."""
    return [e for e in record.timeline if isinstance(e, ev.FastForwarded)]
