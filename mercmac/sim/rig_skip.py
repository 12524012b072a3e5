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

from mercmac.sim.group import Edge
from mercmac.sim.record import CAP
from mercmac.vm import events as ev
from mercmac.vm.shapes import moved_shape, plain
from mercmac.vm.skips import Pass

if TYPE_CHECKING:
    from mercmac.sim.group import Group

SEEN_LIMIT = 4096  # joint keys remembered; a rig whose state never repeats forgets them
SHAPES_LIMIT = 200_000  # items of the shapes kept; past it, the joint keys are forgotten
PAUSE_LIMIT = 256  # anchors at most that a repeat which cannot skip leaves uncompared


@dataclass(slots=True)
class JointVisit:
    """The rig at one joint anchor."""

    t: int
    positions: tuple[int, ...]
    logged: tuple[int, ...]  # each machine's effect log length (its optimiser's)
    edges: int  # edges so far, listed or not
    external: float  # the next button or joystick change
    counters: tuple = ()  # every machine's RP counters, {(slot, ip): value}
    shapes: tuple | None = None  # per machine, the pass that ended here; None: not yet known
    deltas: tuple[int, ...] | None = None
    spent: tuple | None = None  # per machine, how much the pass counted each RP down
    since: JointVisit | None = None  # where the pass that ended here began, while its
    # shapes are not known (they are worked out only when its shifts repeat: a long pass
    # that does not repeat costs nothing to keep)
    size: int = 0  # items of its shapes, once known


class JointForward:
    """Compares the rig at its joint anchors and skips repeating passes."""

    def __init__(self, group: Group):
        self.group = group
        self.machines = list(group.machines.values())
        self.seen: dict[tuple, JointVisit] = {}
        self.arrivals: tuple[int, ...] = ()  # each machine's loop arrivals at the last instant
        self.kept = 0  # items of the shapes in seen's visits (SHAPES_LIMIT)
        # A repeat that a boundary keeps from skipping (a float pass at a power of two of
        # time) is met again at every anchor of the pass until the boundary is passed:
        # the next `pause` anchors compare only shifts, each such repeat doubling it.
        self.pause, self.backoff = 0, 1

    def arrive(self, t: int, until: int) -> None:
        """After the instant t: compare the rig with its last visit of the same key, if a
        loop of one of its machines came round at t (a rig whose state repeats comes round
        the same loops every pass: comparing there finds every repeat, at a fraction of the
        cost of comparing at every instant)."""
        arrivals = tuple(m.optimiser.arrivals for m in self.machines)
        if arrivals == self.arrivals:
            return
        self.arrivals = arrivals
        key = self._key(t)
        if key is None:
            return
        visit = JointVisit(t, tuple(m.axis.target for m in self.machines), self._logged(),
                           self.group.edges_seen, self._external(),
                           tuple(m.rp_counters() for m in self.machines))
        previous = self.seen.get(key)
        forgotten = len(self.seen) >= SEEN_LIMIT or self.kept > SHAPES_LIMIT
        if forgotten:
            self.forget()
        self.seen[key] = visit
        if previous is None:
            return
        let_go = 0 if forgotten else previous.size  # the visit `visit` replaces in seen
        repeats = self._repeats(previous, visit, shapes=not self.pause)
        self.pause = max(self.pause - 1, 0)
        self.kept += visit.size - let_go
        if not repeats:
            return
        period = t - previous.t
        passes = min(self._passes(visit, period, min(until, visit.external)), _left(visit))
        if passes > 0:
            self._jump(key, previous, visit, period, passes)
            self.backoff = 1
        else:
            self.pause, self.backoff = self.backoff, min(2 * self.backoff, PAUSE_LIMIT)

    def _repeats(self, previous: JointVisit, visit: JointVisit, shapes: bool = True) -> bool:
        """Whether the pass that ended at `visit` is the one that ended at `previous` again
        (its shapes, shifts and RP counts; nothing from outside in it), noting them; False
        without `shapes` (its shifts only are noted)."""
        if previous.external != visit.external or visit.external <= visit.t:
            return False  # a button or the joystick changed something in the pass
        visit.deltas = tuple(p - q for p, q in zip(visit.positions, previous.positions))
        visit.spent = tuple(_spent(p, v) for p, v in zip(previous.counters, visit.counters))
        visit.since = previous
        same = (shapes and visit.deltas == previous.deltas and visit.spent == previous.spent
                and None not in visit.spent and self._shapes_at(visit) is not None
                and visit.shapes == self._shapes_at(previous))
        previous.since = None  # (so no chain of visits is kept)
        return same

    def forget(self) -> None:
        """Forget every joint visit (a reset, or too many kept)."""
        self.seen.clear()
        self.kept = 0

    def _shapes_at(self, visit: JointVisit) -> tuple | None:
        """The shapes of the pass that ended at `visit`, worked out once."""
        if visit.shapes is None and visit.since is not None:
            visit.shapes = self._shapes(visit.since, visit)
            visit.since = None
            if visit.shapes is not None:
                visit.size = sum(len(shape) for shape in visit.shapes)
        return visit.shapes

    # ------------------------------------------------------------ the joint state
    def _key(self, t: int) -> tuple | None:
        parts = []
        for m in self.machines:
            part = m.optimiser.joint_key(t)
            if part is None:
                return None
            parts.append(part)
        parts.append(tuple(self.group.levels.values()))
        return tuple(parts)

    def _logged(self) -> tuple[int, ...]:
        return tuple(m.optimiser.logged() for m in self.machines)

    def _external(self) -> float:
        """The next change from outside: a scheduled button or the joystick."""
        t = min(m.inputs.next_change() for m in self.machines)
        holds = self.group.holds
        return min(t, holds[0][0]) if holds else t

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
                           self._logged(), self.group.edges_seen,
                           visit.external, tuple(m.rp_counters() for m in self.machines),
                           visit.shapes, visit.deltas, visit.spent, size=visit.size)
        # every other visit is from before the skip: a pass from there would span it, and
        # a machine's effect log holds none of what the skipped passes emitted (tell)
        self.seen = {key: after}
        self.kept = after.size

    def _repeat_edges(self, previous: JointVisit, visit: JointVisit, period: int,
                      passes: int) -> None:
        """The wires' edges of the skipped passes: listed up to CAP, the rest counted."""
        group = self.group
        count = visit.edges - previous.edges
        if count == 0:
            return  # a pass that changes no wire: nothing to copy, whatever `passes` is
        group.edges_copied += count * passes
        if group.edges_dropped:  # the list is full: the pass's edges were past the cap too
            group.edges_dropped += count * passes
            return
        listed = group.edges[-count:]  # the pass's edges: the last ones, all listed
        for p in range(1, passes + 1):
            for edge in listed:
                group.add_edge(Edge(edge.t + p * period, edge.wire, edge.level))
            if len(group.edges) >= CAP:
                group.edges_dropped += count * (passes - p)
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
