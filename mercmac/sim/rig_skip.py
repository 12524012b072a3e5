"""Fast-forward for a whole rig: skip the passes that the rig as a whole repeats.

One machine's fast-forward (vm/optimiser.py) sees only its own state, and a machine that
waits on a wired input cannot know when the other side will answer; so in a rig the wired
machines run instant by instant (sim/simulate.py) and this module compares their joint state
(a controller no wire joins skips on its own).

A joint anchor is an instant after which every axis rests on a whole-count target or moves
on a profile it keys relative to the time and target, with no trigger pulse on
and no JT table being made. The joint key there is every machine's own (Optimiser.joint_key:
its state key without position, target and profile, the profile and the trigger relative to
the target, its input lines, its next command relative to now) and every wire's level. The
machines are read and moved only through their public surface (Machine.skip_passes,
Optimiser.effects, ...); this module keeps what is about several controllers
(docs/simulator.md, "Fast-forward"). When the key comes back,
the rig passed through a pass; when two passes in a row have the same shape (per machine:
moves, arrivals, reports, output changes relative to the pass's start time and position,
shapes.moved_shape) and the same shifts, the next passes are copies, each `period`
later and `delta` further on per axis, until a button or joystick change, the end of the
run, or a boundary of a shifted move (a soft limit, a switch, an arrival that could round
to another microsecond, a power of two of positions or time for a pass that computes with
fractions: skips.shifted_passes) — the rules of the single machine, applied to all at
once. What a pass does that cannot shift exactly (a hazard, a search, a limit hit) makes
its shape None, and the rig steps it.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from mercmac.sim.record import CAP
from mercmac.vm import events as ev
from mercmac.vm.shapes import moved_shape, plain
from mercmac.vm.skips import Pass

if TYPE_CHECKING:
    from mercmac.sim.simulate import Simulation

SEEN_LIMIT = 4096  # joint keys remembered; a rig whose state never repeats forgets them


@dataclass(slots=True)
class JointVisit:
    """The rig at one joint anchor."""

    t: int
    positions: tuple[int, ...]
    logged: tuple[int, ...]  # each machine's effect log length (its optimiser's)
    edges: int  # edges so far, listed or not
    external: float  # the next button or joystick change
    counters: tuple = ()  # every machine's RP counters, {(slot, ip): value}
    shapes: tuple | None = None  # per machine, the pass that ended here; None: unknown
    deltas: tuple[int, ...] | None = None
    spent: tuple | None = None  # per machine, how much the pass counted each RP down


class JointForward:
    """Compares the rig at its joint anchors and skips repeating passes."""

    def __init__(self, sim: Simulation):
        self.sim = sim
        self.machines = list(sim.wired.machines.values())  # the ones no wire joins skip alone
        self.seen: dict[tuple, JointVisit] = {}

    def arrive(self, t: int, until: int) -> None:
        """After the instant t: compare the rig with its last visit of the same key."""
        key = self._key(t)
        if key is None:
            return
        visit = JointVisit(t, tuple(m.axis.target for m in self.machines), self._logged(),
                           len(self.sim.edges) + self.sim.edges_dropped, self._external(),
                           tuple(m.rp_counters() for m in self.machines))
        previous = self.seen.get(key)
        if len(self.seen) >= SEEN_LIMIT:
            self.seen.clear()
        self.seen[key] = visit
        if previous is None or not self._repeats(previous, visit):
            return
        period = t - previous.t
        passes = min(self._passes(visit, period, min(until, visit.external)), _left(visit))
        if passes > 0:
            self._jump(key, previous, visit, period, passes)

    def _repeats(self, previous: JointVisit, visit: JointVisit) -> bool:
        """Whether the pass that ended at `visit` is the one that ended at `previous` again
        (its shapes, shifts and RP counts; nothing from outside in it), noting them."""
        if previous.external != visit.external or visit.external <= visit.t:
            return False  # a button or the joystick changed something in the pass
        visit.deltas = tuple(p - q for p, q in zip(visit.positions, previous.positions))
        visit.spent = tuple(_spent(p, v) for p, v in zip(previous.counters, visit.counters))
        visit.shapes = self._shapes(previous, visit)
        return (visit.shapes is not None and visit.shapes == previous.shapes
                and visit.deltas == previous.deltas and visit.spent == previous.spent
                and None not in visit.spent)

    # ------------------------------------------------------------ the joint state
    def _key(self, t: int) -> tuple | None:
        parts = []
        for m in self.machines:
            part = m.optimiser.joint_key(t)
            if part is None:
                return None
            parts.append(part)
        parts.append(tuple(self.sim.levels.values()))
        return tuple(parts)

    def _logged(self) -> tuple[int, ...]:
        return tuple(m.optimiser.logged() for m in self.machines)

    def _external(self) -> float:
        """The next change from outside: a scheduled button or the joystick."""
        t = min(m.inputs.next_change() for m in self.machines)
        return min(t, self.sim.holds[0][0]) if self.sim.holds else t

    def _shapes(self, previous: JointVisit, visit: JointVisit) -> tuple | None:
        """Each machine's pass from `previous` to `visit`, as shapes.moved_shape sees it
        (the wires' input changes are left out: the joint key holds the lines)."""
        shapes = []
        for i, m in enumerate(self.machines):
            effects = m.optimiser.effects(previous.logged[i], visit.logged[i])
            if effects is None:
                return None  # the log was cut since: the pass is not known whole
            events = [e for e in effects if type(e) is not ev.InputChanged]
            shape = moved_shape(events, previous.t, previous.positions[i])
            if shape is None:
                return None
            shapes.append(shape)
        return tuple(shapes)

    def _passes(self, visit: JointVisit, period: int, horizon: float) -> int:
        """Whole passes that end before `horizon` and clear every machine's boundaries."""
        fit = max(int(horizon - 1 - visit.t) // period, 0)
        for i, m in enumerate(self.machines):
            if fit <= 0:
                break
            shape = visit.shapes[i]
            if not plain(shape):
                now = Pass(visit.t, visit.positions[i], visit.deltas[i], shape)
                fit = m.optimiser.shifted_passes(now, period, fit)
        return fit

    # ------------------------------------------------------------ the skip
    def _jump(self, key: tuple, previous: JointVisit, visit: JointVisit, period: int,
              passes: int) -> None:
        span = passes * period
        for i, m in enumerate(self.machines):
            m.skip_passes(visit.t, passes, period, visit.shapes[i], visit.positions[i],
                          visit.deltas[i], visit.spent[i])
        self._repeat_edges(previous, visit, period, passes)
        after = JointVisit(visit.t + span,
                           tuple(p + d * passes for p, d in zip(visit.positions, visit.deltas)),
                           self._logged(), len(self.sim.edges) + self.sim.edges_dropped,
                           visit.external, tuple(m.rp_counters() for m in self.machines),
                           visit.shapes, visit.deltas, visit.spent)
        self.seen[key] = after

    def _repeat_edges(self, previous: JointVisit, visit: JointVisit, period: int,
                      passes: int) -> None:
        """The wires' edges of the skipped passes: listed up to CAP, the rest counted."""
        sim = self.sim
        count = visit.edges - previous.edges
        if count == 0:
            return  # a pass that changes no wire: nothing to copy, whatever `passes` is
        listed = [e for e in sim.edges if previous.t < e.t <= visit.t]
        if len(listed) < count:  # some of the pass's edges were past the cap already
            sim.edges_dropped += count * passes
            return
        for p in range(1, passes + 1):
            for edge in listed:
                sim.add_edge(type(edge)(edge.t + p * period, edge.wire, edge.level))
            if len(sim.edges) >= CAP:
                sim.edges_dropped += count * (passes - p)
                return


def _spent(before: dict, after: dict) -> dict | None:
    """How much a pass counted each RP down; None if one counted up (a loop restarted)."""
    spent = {place: before[place] - c for place, c in after.items()}
    return None if any(d < 0 for d in spent.values()) else spent


def _left(visit: JointVisit) -> int | float:
    """Passes before an RP that the pass counts down would end its loop: a pass that counts
    an RP down by d from c repeats only while every jump in it still jumps (c > d; the
    machine's rule, docs/simulator.md, "Repeat counters")."""
    left = math.inf
    for counters, spent in zip(visit.counters, visit.spent):
        for place, d in spent.items():
            if d:
                left = min(left, (counters[place] - 1) // d)
    return left
