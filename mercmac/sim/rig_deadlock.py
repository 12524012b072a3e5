"""A rig dead-locked (MH008, mercmac/hazards.py; docs/rigs.md, "Dead-lock"): nothing is due any
more (no timer, move, scripted button or joystick change), so no output and no wire will
change, and every controller has ended or waits for good, one of them on a line.

A controller waits for good when it waits (WN/WF) on an input no person drives (no button of
the box, no joystick), whether a wire or nothing drives it, or in WS for a move that never
ends (MH005). A wait a person can end is a wait for a person, who may still come: never a
dead-lock. The hazard is told to each controller that waits on a line, at the instant the
rig went still, with every wait and why it never ends.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from mercmac.vm import events as ev
from mercmac.vm.machine import Machine, Wait

if TYPE_CHECKING:
    from mercmac.sim.simulate import Simulation

RULE = "rig-deadlock"  # mercmac/hazards.py MH008


def check(sim: Simulation) -> bool:
    """Whether the still rig is dead-locked; if so each controller waiting on a line hears
    the hazard (once)."""
    running = {name: m for name, m in sim.machines.items() if m.running}
    stuck = {name: m for name, m in running.items() if _stuck(sim, name, m)}
    waiting = {name: m for name, m in stuck.items() if m.block.wait is not Wait.WS}
    if not waiting or len(stuck) < len(running):
        return False
    t = max([m.active for m in sim.machines.values()] + [sim.held_at])
    waits = "; ".join(_waiting_text(sim, name, m) for name, m in waiting.items())
    for name, m in waiting.items():
        message = m.hazards.add(RULE, (name,), waits=waits)
        if message is not None:
            where = m.last_command()
            m.tell(ev.HazardFound(t, RULE, message, where, m.accepts(RULE, where)))
    return True


def _stuck(sim: Simulation, name: str, m: Machine) -> bool:
    """Whether `m`, with nothing due, waits for good: on an input line no person drives, or
    in WS for a move that never ends (MH005)."""
    block = m.block
    return block is not None and (block.wait is Wait.WS
                                  or block.arg not in sim.rig.by_hand(name))


def _waiting_text(sim: Simulation, name: str, m: Machine) -> str:
    block = m.block
    wanted = block.wait is Wait.WN
    return (f"{name} waits in {m.label} at {block.wait.name}{block.arg} for in{block.arg} "
            f"{_word(wanted)} ({_why_never(sim, name, block.arg, not wanted)})")


def _why_never(sim: Simulation, name: str, number: int, level: bool) -> str:
    """Why input `number` of `name` stays at `level`: nothing drives it, or the output at the
    far end of its wire stays there, its controller ended or waiting too."""
    wires = sim.rig.drivers(name, number)
    if not wires:
        return "no wire or box button drives it"
    source = wires[0].source.controller
    m = sim.machines[source]
    state = ("has ended" if not m.running
             else "waits for a move that never ends" if m.block.wait is Wait.WS
             else "waits too")
    return f"from {wires[0].source}, which stays {_word(level)}: {source} {state}"


def _word(on: bool) -> str:
    return "ON" if on else "OFF"
