"""Fast-forward: skip the identical passes of a polling loop in one step (issue 3, item 5).

A loop anchor is an RP jump or the entry of a macro by EM. When a loop comes
back to its anchor with the whole machine state equal to the last visit (apart
from the clock and the jumping RP's own counter), with nothing observable in
between and no input change, the next passes are copies of that one: each
lasts `period` and does the same, until an input changes, the run ends or the
RP counter runs out. So they can be skipped with the clock and counter advanced
exactly.

A pass may also emit reports and output changes (issue 7, item 7: a blinking
LED, `every 20ms { TT }`): when two passes in a row start from the same state
and emit the same things at the same offsets (the same `shape`), the later
passes emit them too, and a skip carries that shape so that its observer can
count (and list, up to its cap) exactly what plain stepping would have emitted.
Passes that move, report a hazard or see an input change never repeat this way.

Shifted passes (issue 11, item 3: a jog loop with a button held, a scan stepping
forever): a pass that starts at rest on an integer target and makes moves from
rest is the same pass, `delta` counts further on, when the machine state apart
from the position and target is the same. Two such passes in a row with the
same `moved_shape` (moves, arrivals and position reports relative to the pass's
start position) and the same delta are copies; the skip (`shifted_passes`)
stops before the next boundary: a soft limit or +-MAX_POSITION clamp, a hard
limit switch, the end of the run, an input change, the RP counter's end, and the
time from which the float sum of a profile's segment lengths could round to
another arrival microsecond. What a pass does that cannot shift exactly (a
report or a command while the axis moves, a trigger, a reference search, DH, a
limit hit) leaves a `Mark` in the effect log and makes the pass unskippable.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum
from operator import attrgetter
from fractions import Fraction
from typing import Iterator, NamedTuple

from mercmac.vm import events as ev
from mercmac.vm.reports import number

REPORT, OUTPUTS, SKIP = "report", "outputs", "skip"  # what a shape's items are
PLACED, MOVE, ARRIVE, ABSOLUTE = "placed", "move", "arrive", "absolute"  # moved_shape's too
SHIFTED = "shifted"  # an inner skip that moves or shifts
REQUESTED, UNSHIFTABLE = "requested", "unshiftable"  # what a Mark notes
FLOW = (ev.MacroEntered, ev.MacroLeft, ev.Executed)  # control flow: repeats with the pass


class Loop(Enum):
    """What brings a loop round to its anchor."""

    EM = "em"  # a macro entered by EM (a macro that calls itself, or a ring of gotos)
    RP = "rp"  # an RP that jumps back to the start of its macro


class Anchor(NamedTuple):
    """Where a loop comes round: a macro's entry, or one RP in it."""

    loop: Loop
    slot: int
    ip: int = 0  # the RP's place; 0 for a macro's entry


@dataclass(frozen=True, slots=True)
class Visit:
    """The machine at one arrival at an anchor."""

    key: tuple | None  # state without clock and own counter; None when moving
    wake: int  # when the pass starts, us
    inputs: int  # input change count so far
    waits: int  # wait instructions executed so far
    logged: int  # effects logged so far (the machine's effect log)
    shape: tuple | None  # what the pass that ended here emitted; None: unknown or unrepeatable
    skey: tuple | None = None  # key without position and target; None unless at rest on target
    position: int = 0  # the target (= position) here, when skey is not None
    delta: int | None = None  # position - the last visit's; None unless skeys were equal
    moved: tuple | None = None  # moved_shape of the pass that ended here


class Mark(NamedTuple):
    """A note in the machine's effect log, never emitted: what a shifted pass must know."""

    what: str  # PLACED (the report before it), REQUESTED, ABSOLUTE, UNSHIFTABLE
    value: tuple = ()


class Anchors:
    """The last visit of every loop anchor."""

    def __init__(self):
        self.visits: dict[Anchor, Visit] = {}

    def arrive(self, anchor: Anchor, visit: Visit) -> Visit | None:
        """Record a visit; return the previous one if it bounds a pass."""
        previous = self.visits.get(anchor)
        self.visits[anchor] = visit
        return previous

    def forget_slot(self, slot: int) -> None:
        """A macro was entered: its RP counters restart, so its loop visits are void."""
        for anchor in [a for a in self.visits if a.loop is Loop.RP and a.slot == slot]:
            del self.visits[anchor]

    def forget(self, anchor: Anchor) -> None:
        self.visits.pop(anchor, None)

    def clear(self) -> None:
        self.visits.clear()


def key_fields(*names: str):
    """A part's `state_key()`: its fields `names`, what decides its future, as a tuple.

    Each part lists every field either there (its STATE_KEY) or in NOT_KEYED with the
    reason it may be left out; tests/test_vm_surface.py fails when a field is in neither,
    and when a keyed field holds a mutable value (a key must not change with the part).
    """
    get = attrgetter(*names)
    if len(names) == 1:
        def state_key(part) -> tuple:
            return (get(part),)
    else:
        def state_key(part) -> tuple:
            return get(part)
    return state_key


def logged(event) -> bool:
    """Whether an event is part of a pass's effects: all but flow, and skips that emitted."""
    if isinstance(event, ev.FastForwarded):
        return bool(event.shape)
    return not isinstance(event, FLOW)


def shape(events: list, start: int) -> tuple | None:
    """A pass's effects relative to its start; None if one of them cannot repeat."""
    items = []
    for e in events:
        if type(e) is ev.Reported:
            items.append((REPORT, e.t - start, e.text, e.where))
        elif type(e) is ev.OutputsChanged:
            items.append((OUTPUTS, e.t - start, e.pattern))
        elif type(e) is ev.FastForwarded:
            if e.shift or not plain(e.shape):  # moves proven exact for its own passes only
                return None
            items.append((SKIP, e.t - start, e.passes, e.period, e.shape, e.loop))
        elif type(e) is not Mark:  # motion, inputs, hazards: not the same in the next pass
            return None
    return tuple(items)


def moved_shape(events: list, start: int, position: int) -> tuple | None:
    """A pass's effects relative to its start time and position; None if one cannot shift."""
    items, requested = [], None
    for e in events:
        kind = type(e)
        if kind is Mark:
            if e.what == UNSHIFTABLE:
                return None
            if e.what == REQUESTED:
                requested = (e.value[0] - position, *e.value[1:])
            elif e.what == ABSOLUTE:
                items.append((ABSOLUTE,))
            else:  # PLACED: the report just logged shows a position
                report = items.pop()
                items.append((PLACED, report[1], e.value[0], e.value[1] - position, report[3]))
        elif kind is ev.Reported:
            items.append((REPORT, e.t - start, e.text, e.where))
        elif kind is ev.OutputsChanged:
            items.append((OUTPUTS, e.t - start, e.pattern))
        elif kind is ev.FastForwarded and (e.shift or not plain(e.shape)):
            items.append((SHIFTED, e.t - start, e.passes, e.period, e.shape, e.loop,
                          e.position - position, e.shift))
        elif kind is ev.FastForwarded:
            items.append((SKIP, e.t - start, e.passes, e.period, e.shape, e.loop))
        elif kind is ev.MoveStarted and (e.kind == "move" or not e.segments):
            if e.kind == "move" and requested is None:
                return None
            # from rest (else a Mark): the profile runs from segs[0].x0 to the target, one way
            origin = round(e.segments[0].x0) - position if e.segments else e.target - position
            items.append((MOVE, e.t - start, e.kind, e.target - position, origin,
                          requested, e.arrival - e.t, tuple(s.dt for s in e.segments)))
            requested = None
        elif kind is ev.MoveEnded and e.how == "arrived":
            items.append((ARRIVE, e.t - start, e.position - position))
        else:  # a reference search, joystick, limit hit, DH, hazard, input
            return None
    return tuple(items)


def plain(shape: tuple) -> bool:
    """Whether a shape is the same at any position (no moves, no position reports)."""
    return all(item[0] in (REPORT, OUTPUTS) or (item[0] == SKIP and plain(item[4]))
               for item in shape)


def same_pass(previous: Visit, now: Visit) -> bool:
    """True when the pass from `previous` to `now` will repeat exactly.

    Two passes in a row start from the same state and emit the same (shape is only
    known when the pass started from the state it ended in): what a pass does
    then depends only on the jumping RP's own counter, which a TI would show (it
    differs from pass to pass) and which `remaining` bounds. Two, not one, so
    that no loop inside the pass first found a busy loop in the passes skipped.
    """
    return (now.key is not None and now.key == previous.key and now.inputs == previous.inputs
            and now.wake > previous.wake and now.shape is not None
            and now.shape == previous.shape)


def count(shape: tuple, kind: str) -> int:
    """How many reports (or output changes) one pass of `shape` emits."""
    kinds = (kind, PLACED) if kind == REPORT else (kind,)
    return sum(1 if item[0] in kinds else item[2] * count(item[4], kind)
               for item in shape if item[0] in kinds or item[0] in (SKIP, SHIFTED))


def expand(shape: tuple, start: int, period: int, passes: int, kind: str,
           position: int = 0, shift: int = 0) -> Iterator:
    """The events of `kind` that `passes` passes of `shape` from `start` emit, in time order;
    the first pass starts at `position`, each next one `shift` further (a shifted skip)."""
    kinds = (kind, PLACED) if kind == REPORT else (kind,)
    items = [item for item in shape
             if item[0] in kinds or (item[0] in (SKIP, SHIFTED) and count(item[4], kind))]
    if not items:
        return
    for p in range(passes):
        base = start + p * period
        for item in items:
            if item[0] == REPORT:
                yield ev.Reported(base + item[1], item[2], item[3])
            elif item[0] == PLACED:
                value = position + p * shift + item[3]
                yield ev.Reported(base + item[1], number(item[2], value), item[4])
            elif item[0] == OUTPUTS:
                yield ev.OutputsChanged(base + item[1], item[2])
            elif item[0] == SHIFTED:
                yield from expand(item[4], base + item[1], item[3], item[2], kind,
                                  position + p * shift + item[6], item[7])
            else:
                yield from expand(item[4], base + item[1], item[3], item[2], kind)


def skippable(previous: Visit, now: Visit, horizon: float, remaining: float) -> int:
    """How many whole passes fit before `horizon` (next input, event or end of run)."""
    period = now.wake - previous.wake
    if horizon == math.inf:
        if remaining == math.inf:
            return 0
        fit = remaining
    else:
        fit = max(int(horizon - now.wake) // period, 0)
    return int(min(fit, remaining))


def same_shifted_pass(previous: Visit, now: Visit) -> bool:
    """True when the pass from `previous` to `now` repeats `now.delta` further on: two passes
    in a row from the same state but the position, alike relative to their starts."""
    return (now.skey is not None and now.skey == previous.skey and now.moved is not None
            and now.inputs == previous.inputs and now.wake > previous.wake
            and now.delta == previous.delta and now.moved == previous.moved)


def shifted_passes(now: Visit, period: int, fit: int, bounds: tuple, hard: tuple | None) -> int:
    """How many of `fit` passes shifted by now.delta each stay clear of every boundary.

    bounds: the soft range (max(JL, -MAX_POSITION), min(JH, MAX_POSITION)) at the anchor;
    hard: the limit switches in present coordinates, or None.
    """
    delta, pos = now.delta, now.position
    if delta and _shows_switches(now.moved):
        return 0  # TS shows the switches: where they are crossed is not counted here
    for item, latest, starts in _moves(now.moved, 0, (0,)):
        for start in starts:
            fit = min(fit, _unclamped(item, pos + start, delta, fit),
                      _clear(item, pos + start, delta, fit, hard))
        fit = min(fit, _same_arrival(item, now.wake + latest, period, fit))
    return max(fit, 0)


def _shows_switches(shape: tuple) -> bool:
    return any(item[0] == ABSOLUTE or (item[0] == SHIFTED and _shows_switches(item[4]))
               for item in shape)


def _moves(shape: tuple, latest: int, starts: tuple) -> Iterator:
    """Each move of a pass, with a bound on its pass's start time (relative) and the
    relative start positions of its first and last copy (inner shifted skips repeat it)."""
    for item in shape:
        if item[0] == MOVE:
            yield item, latest, starts
        elif item[0] == SHIFTED:
            n, period, rel, shift = item[2], item[3], item[6], item[7]
            inner = tuple({s + rel + q * shift for s in starts for q in (0, n - 1)})
            yield from _moves(item[4], latest + item[1] + n * period, inner)


def _last_inside(lo: float, hi: float, first: int, delta: int, fit: int) -> int:
    """How many passes p = 0, 1, ... keep first + p*delta within [lo, hi] (at most fit)."""
    if not lo <= first <= hi:
        return 0
    if delta > 0:
        return min(fit, int((hi - first) // delta) + 1)
    if delta < 0:
        return min(fit, int((first - lo) // -delta) + 1)
    return fit


def _unclamped(item: tuple, pos: int, delta: int, fit: int) -> int:
    """Passes whose move targets stay unclamped (a clamp is a soft-limit boundary)."""
    requested = item[5]
    if requested is None or delta == 0:  # a stop, or the very same targets every pass
        return fit
    rel, lo, hi = requested
    return _last_inside(lo, hi, pos + rel, delta, fit)


def _clear(item: tuple, pos: int, delta: int, fit: int, hard: tuple | None) -> int:
    """Passes whose move stays 2 counts clear of the limit switches, in float and all (even
    unshifted: a profile's float end, taken at another time, could touch a switch it ends on)."""
    if hard is None:
        return fit
    lo, hi = hard[0] + 2, hard[1] - 2
    low, high = sorted((item[3], item[4]))
    return min(_last_inside(lo - low, hi - low, pos, delta, fit),
               _last_inside(lo - high, hi - high, pos, delta, fit))


def _same_arrival(item: tuple, wake: int, period: int, fit: int) -> int:
    """Passes in which the profile's end, summed in floats from its start time, still rounds
    up to the same microsecond: each of the sums adds at most half an ulp of the time."""
    dts = item[7]
    if not dts:
        return fit
    exact = sum(map(Fraction, dts), Fraction(0))
    up = math.ceil(exact)
    gap = min(exact - (up - 1), up - exact)
    if gap <= 0 or item[6] != up:
        return 0

    def safe(n: int) -> bool:
        latest = wake + n * period + item[1] + up + 1
        return Fraction(math.ulp(float(latest))) * len(dts) < gap

    lo, hi = 0, fit
    while lo < hi:  # the error grows with the time: the largest n that is safe
        mid = (lo + hi + 1) // 2
        if safe(mid):
            lo = mid
        else:
            hi = mid - 1
    return lo
