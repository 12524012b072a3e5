"""A simulation run as plain data, and a run stepped or fast-forwarded to checkpoints, so that
two runs can be compared (docs/simulator.md, "Fast-forward": a skip lands where stepping does)."""
from __future__ import annotations

import dataclasses
from unittest import mock

from mercmac.compiler.program import Program
from mercmac.sim import record as record_module
from mercmac.sim.simulate import machine_for, schedule
from mercmac.vm import events as ev
from mercmac.vm.models import Options


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


def vcd_values(text: str, var: str = "position") -> dict[tuple[str, int], int]:
    """The values a VCD gives the integer variable `var` of each scope, by (scope, time):
    ('axis', t) for a program's dump, ('x.axis', t) for controller x of a rig's."""
    import re

    codes, scopes = {}, []
    for line in text.split("\n"):
        if (opened := re.match(r"\$scope module (\S+) \$end", line)):
            scopes.append(opened.group(1))
        elif line.startswith("$upscope"):
            scopes.pop()
        elif (declared := re.match(rf"\$var integer 32 (\S+) {var} \$end", line)):
            codes[declared.group(1)] = ".".join(scopes)
    t, values = 0, {}
    for line in text.split("\n"):
        if line.startswith("#"):
            t = int(line[1:])
        elif line.startswith("b") and line.split()[-1] in codes:
            bits, code = line[1:].split()
            value = int(bits, 2)
            values[(codes[code], t)] = value - (1 << 32) if value >> 31 else value
    return values


def same_samples(fast: dict, stepped: dict) -> int:
    """How many values a fast-forwarded dump gives at times the stepped one has too; an
    AssertionError names the first that differs (a skip leaves passes out, never wrong)."""
    common = [key for key in fast if key in stepped]
    wrong = [(key, fast[key], stepped[key]) for key in common if fast[key] != stepped[key]]
    assert not wrong, f"{len(wrong)} values differ from stepping, first {wrong[:3]}"
    return len(common)


def run_checkpoints(program: Program, mode: str, checkpoints: list[int], model: str,
                    options: Options | None = None) -> tuple[dict, list]:
    """What a run gives at each checkpoint (ms): the record, every event but the skip
    markers, and the machine with its profile; and the skips it made."""
    machine, record = machine_for(program, model=model, fast_forward=mode, options=options)
    machine.power_on()
    seen = []
    for t in checkpoints:
        machine.run_until(t)
        m, axis = machine, machine.axis
        seen.append((m.clock.now, m.position(), m.target, m.velocity(), m.moving(), m.macro,
                     m.ip, m.counters, m.block, m.wake, m.error, m.outputs_pattern(),
                     axis.segs, axis.final, axis.plan, axis.limit))
    skips = [e for e in record.events if isinstance(e, ev.FastForwarded)]
    events = [_seen(e) for e in record.events if not isinstance(e, ev.FastForwarded)]
    return {**observed(record), "events": events, "states": seen}, skips


def _seen(event: object) -> object:
    """An event as JSON and the timeline show it: a listed copy of a move's profile has the
    stepped one's segments moved on, which agree with those stepping plans to a few ulps (a
    start time summed in floats), not bit for bit; the machine's own profile does (states)."""
    if isinstance(event, ev.MoveStarted):
        return dataclasses.replace(event, segments=tuple(
            (round(s.t0, 6), round(s.x0, 6), s.v0, s.a, s.dt) for s in event.segments))
    return event


def same_as_stepping(program: Program, checkpoints: list[int], model: str,
                     options: Options | None = None) -> list:
    """Assert that skipping gives what stepping gives; the skips made."""
    with mock.patch.object(record_module, "CAP", 10**7):  # every event listed, none counted
        fast, skips = run_checkpoints(program, "all", checkpoints, model, options)
        plain, _ = run_checkpoints(program, "off", checkpoints, model, options)
    assert fast == plain
    return skips
