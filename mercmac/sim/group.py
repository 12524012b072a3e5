"""A group: controllers that wires join, directly or through others, on a clock of their own
(docs/rigs.md, "One instant"; docs/simulator.md, "Fast-forward").

Wires are all that controllers share (MS176E §3.8, §4.5.1), so two groups no wire joins never
see each other: each one runs to the end of a slice on its own, and a rig of sixteen
controllers in eight pairs is eight rigs of two, each skipping the passes it repeats. A group
of one controller without a wire runs on that machine's own fast-forward (vm/optimiser.py);
a group of several advances instant by instant by the rule of vm/wiring.py and skips the
passes its controllers repeat together (sim/rig_skip.py).
"""
from __future__ import annotations

import heapq
from dataclasses import dataclass
from typing import Hashable, Mapping, Sequence

from mercmac.rig.model import Wire
from mercmac.sim.record import CAP
from mercmac.vm.machine import Machine
from mercmac.vm.wiring import Wired

# a joystick change: (t in us, order of scripting, controller, deflection)
Held = tuple[int, int, str, float]


@dataclass(frozen=True, slots=True)
class Edge:
    """A wire changed level at t (us): the driving output's new level."""

    t: int
    wire: Wire
    level: bool


class Group:
    """Machines by name that wires join, the wires between them, their edges and the joystick
    changes scripted for them."""

    def __init__(self, machines: Mapping[str, Machine], wires: Sequence[Wire], *,
                 joint: bool):
        self.machines = dict(machines)
        self.wired = Wired(self.machines, wires, on_edge=self._edge)
        self.edges: list[Edge] = []  # in time order, up to CAP
        self.edges_dropped = 0
        self.edges_copied = 0  # edges of the passes a joint skip skipped, listed or not
        self.holds: list[Held] = []  # a heap
        self.held_at = 0  # the last joystick change (us): activity, for a dead-lock's time
        self.joint = None
        if joint and self.wired.wires:
            from mercmac.sim.rig_skip import JointForward

            self.joint = JointForward(self)

    @property
    def levels(self) -> dict[Wire, bool]:
        """Each wire's level now (its driving output's)."""
        return self.wired.levels

    def hold(self, t_us: int, controller: str, deflection: float) -> None:
        heapq.heappush(self.holds, (t_us, len(self.holds), controller, deflection))

    def power_on(self, t_us: int) -> None:
        """The machines powered on (the Simulation did): the wires follow their outputs."""
        if self.joint is not None:
            self.joint.forget()  # passes before the reset are no pattern for after it
        self.wired.carry(t_us)

    # ------------------------------------------------------------ the clock
    def run_until(self, until: int) -> None:
        """Advance the group to `until` (us): alone on its own fast-forward when no wire
        joins it, else instant by instant, skipping the passes it repeats."""
        if not self.wired.wires:
            (name, m), = self.machines.items()
            self._alone(name, m, until)
            return
        while (t := self.next_us()) < until:
            self._joystick(t)
            self.wired.instant(t)
            if self.joint is not None:
                self.joint.arrive(t, until)
        for m in self.machines.values():
            m.run(until)

    def _alone(self, name: Hashable, m: Machine, until: int) -> None:
        """A controller no wire joins, to `until`; its joystick changes on the way, each
        before any command at its time."""
        while self.holds and self.holds[0][0] < until:
            t, _, _, deflection = heapq.heappop(self.holds)
            m.run(t)
            m.set_joystick(deflection)
            self.held_at = max(self.held_at, t)
        m.run(until)

    def next_us(self) -> float:
        """The earliest event of the machines or of their joystick; inf when none."""
        t = self.wired.next_us()
        return min(t, self.holds[0][0]) if self.holds else t

    def _joystick(self, t: int) -> None:
        while self.holds and self.holds[0][0] <= t:
            _, _, name, deflection = heapq.heappop(self.holds)
            self.wired.at(name, t).set_joystick(deflection)
            self.held_at = max(self.held_at, t)

    # ------------------------------------------------------------ its wires' edges
    def _edge(self, t: int, wire: Wire, level: bool) -> None:
        self.add_edge(Edge(t, wire, level))

    def add_edge(self, edge: Edge) -> None:
        """Keep an edge, up to CAP; past it, count it (the rig lists the first CAP of all
        its groups' edges, merged by time: none of them is past its own group's CAP)."""
        if len(self.edges) < CAP:
            self.edges.append(edge)
        else:
            self.edges_dropped += 1

    @property
    def edges_seen(self) -> int:
        """Edges so far, listed or not."""
        return len(self.edges) + self.edges_dropped


def groups_of(names: Sequence[str], wires: Sequence[Wire]) -> list[list[str]]:
    """The controllers in groups that wires join (connected parts of the wire graph), each
    in the rig's order, the groups in the order of their first controller."""
    parent = {name: name for name in names}

    def root(name: str) -> str:
        while parent[name] != name:
            parent[name] = parent[parent[name]]
            name = parent[name]
        return name

    for wire in wires:
        a, b = root(wire.source.controller), root(wire.target.controller)
        if a != b:
            parent[b] = a
    groups: dict[str, list[str]] = {}
    for name in names:
        groups.setdefault(root(name), []).append(name)
    return list(groups.values())
