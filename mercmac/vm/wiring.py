"""Machines joined by wires on one clock: the instant rule that `sim RIG` and the virtual
chain of `emulate --rig` both follow (docs/rigs.md, "One instant").

MS176E §3.8 and §4.5.1 let axes interact only through wired I/O lines, so the wires are all
that wired machines share. Times are whole microseconds, the VM's unit. Within one instant t
(deterministic, and independent of the order of the controllers in the rig file):
  1. every machine due at t processes its hardware events at t, then its command at t;
     all of them read their inputs as they were before any command at t ran;
  2. then every wire takes its driving output's level at t, and an input whose level so
     changes changes at t (an InputChanged at t on the driven machine); an input that two
     outputs drive is ON while either is (`check` refuses such a rig; the emulator serves it);
  3. a machine this lets go on (a WN/WF wait that ends) runs its next command at t itself,
     so 1-3 repeat at t until no machine is due at t any more.
So an output set at t reaches the wired input at t, before the driven machine runs any
command after its wait; two commands at the same instant never see each other's outputs
(as two controllers' clocks are not in step on the bench either).
"""
from __future__ import annotations

import math
from typing import Callable, Hashable, Iterable, Mapping, Protocol

from mercmac.vm.machine import Machine

INF = math.inf


class End(Protocol):
    """One end of a wire: a controller's key and a line number (rig.model.Line is one)."""

    controller: Hashable
    number: int


class Link(Protocol):
    """An output of one machine driving an input of another (rig.model.Wire is one)."""

    source: End
    target: End


# Runs one machine's work (key, work): the emulator answers a failure of its firmware there
# with error 06 and goes on (emulator/virtual.py); the simulator lets it propagate.
Guard = Callable[[Hashable, Callable[[], None]], None]
OnEdge = Callable[[int, Link, bool], None]  # (t in us, the wire, its new level)


def _unguarded(key: Hashable, work: Callable[[], None]) -> None:
    work()


def next_us(m: Machine) -> float:
    """The machine's next event in whole us (inf: none)."""
    t = m.next_event_ms()
    return t if t == INF else round(t * 1000)


class Wired:
    """Machines by key and the wires between them, advanced instant by instant."""

    def __init__(self, machines: Mapping[Hashable, Machine], wires: Iterable[Link], *,
                 on_edge: OnEdge | None = None, guard: Guard = _unguarded):
        self.machines = dict(machines)
        by_source: dict[Hashable, list[Link]] = {}
        for wire in wires:
            by_source.setdefault(wire.source.controller, []).append(wire)
        # by driving controller, then as given: the order edges are told in
        self.wires = tuple(w for group in by_source.values() for w in group)
        self.levels = {w: False for w in self.wires}  # outputs are off at power-on (§3.4)
        self._drivers: dict[tuple[Hashable, int], list[Link]] = {}
        for wire in self.wires:
            self._drivers.setdefault((wire.target.controller, wire.target.number), []).append(wire)
        self._on_edge = on_edge
        self._guard = guard

    def next_us(self) -> float:
        """The earliest event of any machine; inf when none is left."""
        return min((next_us(m) for m in self.machines.values()), default=INF)

    def run_until(self, until: int, after: Callable[[int], None] | None = None) -> None:
        """Every instant before `until` (us) in turn; `after(t)` hears each one done."""
        while (t := self.next_us()) < until:
            self.instant(t)
            if after is not None:
                after(t)

    def instant(self, t: int) -> None:
        """Steps 1-3 of the rule at t."""
        due = self._due(t)
        while due:
            for key in due:
                m = self.machines[key]
                self._guard(key, lambda m=m: m.run(t, through=True))
            if not self.carry(t):
                return  # no input changed: nothing more is due at t
            due = self._due(t)

    def _due(self, t: int) -> list[Hashable]:
        return [key for key, m in self.machines.items() if next_us(m) <= t]

    def carry(self, t: int) -> bool:
        """Step 2 at t: every wire takes its driving output's level, and each input whose
        level so changes (ON while any wire into it is) changes at t; whether any did."""
        changed: dict[tuple[Hashable, int], None] = {}
        for wire in self.wires:
            pattern = self.machines[wire.source.controller].outputs.pattern(t)
            level = bool(pattern >> (wire.source.number - 1) & 1)
            if level != self.levels[wire]:
                self.levels[wire] = level
                if self._on_edge is not None:
                    self._on_edge(t, wire, level)
                changed[(wire.target.controller, wire.target.number)] = None
        moved = False
        for key, n in changed:
            on = any(self.levels[w] for w in self._drivers[(key, n)])
            m = self.at(key, t)
            moved |= m.input(n) != on
            m.set_input(n, on)
        return moved

    def at(self, key: Hashable, t: int) -> Machine:
        """The machine `key`, its clock brought to t (nothing of it is due before t)."""
        m = self.machines[key]
        if m.now_us < t:
            self._guard(key, lambda: m.run(t))
        return m
