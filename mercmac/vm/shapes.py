"""The shape of a pass: what one pass of a loop emitted, relative to its start, as typed
items, and what the skipped copies of a pass emit (docs/simulator.md, "Fast-forward").

A pass that reports or switches outputs (a blinking LED, `every 20ms { TT }`) repeats when
two passes in a row start from the same state and emit the same things at the same offsets:
the same `shape`. A skip carries that shape (FastForwarded.shape), so that its listeners can
count, and list up to their cap, exactly what plain stepping would have emitted (count,
expand), and a plot or a VCD can draw it without listing every change (compact). The shape
of a shifted pass (moved_shape) is also relative to the pass's start position: its moves,
arrivals and the positions its reports show. Besides events, the optimiser's effect log
holds notes on how a pass depends on the position (NOTES); they are never emitted. A pass
that sees an input change or reports a hazard has no shape: it does not repeat.
"""
from __future__ import annotations

from enum import Enum
from typing import Iterator, NamedTuple

from mercmac.vm import events as ev
from mercmac.vm.motion import Ended
from mercmac.vm.reports import number


class Tag(Enum):
    """What a shape item is. It is each item's first field: shapes are compared as tuples
    (in C, at every loop anchor), and two items of different kinds must never be equal."""

    REPORT = "report"
    OUTPUTS = "outputs"
    SKIP = "skip"  # an inner skip whose passes are the same at any position
    SHIFTED = "shifted"  # an inner skip that moves or shifts
    PLACED = "placed"  # a report that shows the position (moved_shape)
    MOVE = "move"
    ARRIVE = "arrive"
    ABSOLUTE = "absolute"  # a TS report: it shows the switches, not a relative position
    FLOATS = "floats"  # the pass computes with fractional positions (skips._same_binade)
    KEPT = "kept"  # a move that keeps the running profile (steady)


REPORT, OUTPUTS = Tag.REPORT, Tag.OUTPUTS  # what count and expand select


class Report(NamedTuple):
    tag: Tag  # Tag.REPORT
    offset: int  # us from the pass's start, as in every item
    text: str
    where: ev.Where | None
    __match_args__ = ("offset", "text", "where")


class Outputs(NamedTuple):
    tag: Tag  # Tag.OUTPUTS
    offset: int
    pattern: int
    __match_args__ = ("offset", "pattern")


class Skip(NamedTuple):
    """An inner loop's skip: `passes` passes of `shape`, `period` us each."""

    tag: Tag  # Tag.SKIP
    offset: int
    passes: int
    period: int
    shape: tuple
    loop: ev.Where
    __match_args__ = ("offset", "passes", "period", "shape", "loop")


class Shifted(NamedTuple):
    """An inner skip whose first pass starts `position` counts from the outer pass's start
    position, and each next one `shift` further."""

    tag: Tag  # Tag.SHIFTED
    offset: int
    passes: int
    period: int
    shape: tuple
    loop: ev.Where
    position: int
    shift: int
    __match_args__ = ("offset", "passes", "period", "shape", "loop", "position", "shift")


class Placed(NamedTuple):
    """A report of `ident` showing a position `position` counts from the pass's start one."""

    tag: Tag  # Tag.PLACED
    offset: int
    ident: str
    position: int
    where: ev.Where | None
    __match_args__ = ("offset", "ident", "position", "where")


class Absolute(NamedTuple):
    tag: Tag  # Tag.ABSOLUTE or Tag.FLOATS


class Kept(NamedTuple):
    """A move that kept the running profile (MoveStarted.kept), from the target `before` to
    `target`, both relative to the pass's start target; `requested`, what it asked for."""

    tag: Tag  # Tag.KEPT
    offset: int
    kind: ev.Motion
    target: int
    before: int
    requested: Requested | None
    __match_args__ = ("offset", "kind", "target", "before", "requested")


class Requested(NamedTuple):
    """A note: a move asked for `target`; a target outside lo..hi is clamped (§4.4.2)."""

    target: int
    lo: int
    hi: int


class Move(NamedTuple):
    """A profile: to `target` from `origin` (relative to the pass's start position; origin a
    float when it starts on the way), lasting `arrival` us in segments of `dts` us, through
    positions from `low` to `high` (a profile that turns round overshoots both)."""

    tag: Tag  # Tag.MOVE
    offset: int
    kind: ev.Motion
    target: int
    origin: int
    requested: Requested | None  # relative to the pass's start; None for a stop
    arrival: float
    dts: tuple[float, ...]
    low: float
    high: float
    __match_args__ = ("offset", "kind", "target", "origin", "requested", "arrival", "dts")


class Arrive(NamedTuple):
    tag: Tag  # Tag.ARRIVE
    offset: int
    position: int
    __match_args__ = ("offset", "position")


ABSOLUTE = Absolute(Tag.ABSOLUTE)
FLOATING = Absolute(Tag.FLOATS)


class Shows(NamedTuple):
    """A note: the report just logged shows the position `value` (TP, TD, TT at rest)."""

    ident: str
    value: int


class Note(Enum):
    """A note in the effect log about the pass it is in; never emitted."""

    SWITCHES = "switches"  # the report just logged (TS) shows the switches
    FLOATS = "floats"  # a profile or a report of the pass took a fractional position
    UNSHIFTABLE = "unshiftable"  # the pass did something a shifted pass cannot repeat


class Stretch(NamedTuple):
    """Skipped passes as a plot or a VCD draws them: those from t on left out, the last
    one, starting at `last`, drawn in full."""

    t: int
    last: int
    passes: int


NOTES = (Requested, Shows, Note)  # what the effect log holds besides events


def shape(events: list, start: int) -> tuple | None:
    """A pass's effects relative to its start; None if one of them cannot repeat."""
    return _shape(events, start, None)


def steady(events: list, start: int, position: int) -> tuple | None:
    """The shape of a pass that leaves the running profile going on (vm/optimiser.py, a
    steady key), relative to its start time and its start target `position`: its moves keep
    the profile (Kept), the targets its reports show (TT) are Placed, and nothing in it may
    show where the stage is on the profile (a position or velocity report, the switches, a
    trigger pulse: the notes the optimiser logs for them), so that the next pass does the
    same wherever the stage is, its targets each `delta` further on; None otherwise."""
    return _shape(events, start, position)


def _shape(events: list, start: int, position: int | None) -> tuple | None:
    """shape (`position` None: a pass at rest, whose notes change nothing) or steady."""
    items, requested, target = [], None, position
    for e in events:
        match e:
            case ev.Reported(t, text, where):
                items.append(Report(Tag.REPORT, t - start, text, where))
            case ev.OutputsChanged(t, pattern):
                items.append(Outputs(Tag.OUTPUTS, t - start, pattern))
            case ev.FastForwarded() if e.shift or e.steady or not plain(e.shape):
                return None  # moves proven exact for its own passes only
            case ev.FastForwarded():
                items.append(_skip(e, start))
            case Requested() | Shows() | Note() if position is None:  # NOTES
                pass
            case Shows(ident, value):  # the report just logged shows the target (TT)
                report = items.pop()
                items.append(Placed(Tag.PLACED, report.offset, ident, value - position,
                                    report.where))
            case Requested(asked, lo, hi):
                requested = Requested(asked - position, lo, hi)
            case ev.MoveStarted() if position is not None and e.kept:
                items.append(Kept(Tag.KEPT, e.t - start, e.kind, e.target - position,
                                  target - position, requested))
                requested, target = None, e.target
            case _:  # motion, inputs, hazards, a note of the position on a running profile
                return None
    return tuple(items)


def silent(events: list, start: int) -> tuple | None:
    """() when a pass emitted nothing (its effects are notes only), else None: all a
    machine that skips only quiet passes needs of its shape."""
    for e in events:
        if not isinstance(e, NOTES):
            return None
    return ()


def moved_shape(events: list, start: int, position: int) -> tuple | None:
    """A pass's effects relative to its start time and position; None if one cannot shift."""
    items, requested = [], None
    for e in events:
        match e:
            case ev.Reported(t, text, where):
                items.append(Report(Tag.REPORT, t - start, text, where))
            case ev.OutputsChanged(t, pattern):
                items.append(Outputs(Tag.OUTPUTS, t - start, pattern))
            case Shows(ident, value):  # the report just logged shows a position
                report = items.pop()
                items.append(Placed(Tag.PLACED, report.offset, ident, value - position,
                                    report.where))
            case Requested(target, lo, hi):
                requested = Requested(target - position, lo, hi)
            case ev.FastForwarded() if e.steady:  # its profile is from before the pass
                return None
            case ev.FastForwarded() if e.shift or not plain(e.shape):
                items.append(Shifted(Tag.SHIFTED, e.t - start, e.passes, e.period, e.shape,
                                     e.loop, e.position - position, e.shift))
            case ev.FastForwarded():
                items.append(_skip(e, start))
            case ev.MoveStarted() if e.kind == ev.Motion.MOVE or not e.segments:
                if e.kind == ev.Motion.MOVE and requested is None:
                    return None
                items.append(_move(e, start, position, requested))
                requested = None
            case ev.MoveEnded(t, Ended.ARRIVED, at):
                items.append(Arrive(Tag.ARRIVE, t - start, at - position))
            case Note.SWITCHES:  # compared by value: after the events (their __eq__ is slow)
                items.append(ABSOLUTE)
            case Note.FLOATS:
                if FLOATING not in items:
                    items.append(FLOATING)
            case _:  # a reference search, joystick, limit hit, DH, hazard, input, UNSHIFTABLE
                return None
    return tuple(items)


def _skip(e: ev.FastForwarded, start: int) -> Skip:
    return Skip(Tag.SKIP, e.t - start, e.passes, e.period, e.shape, e.loop)


def _move(e: ev.MoveStarted, start: int, position: int, requested: Requested | None) -> Move:
    """A profile from segs[0].x0 to the target, relative to the pass's start position (from
    rest on a count, a whole count; else a float, the same within one power of two)."""
    segments = e.segments
    if not segments:
        here = e.target - position
        return Move(Tag.MOVE, e.t - start, e.kind, here, here, requested, e.arrival - e.t, (),
                    here, here)
    x0 = segments[0].x0
    origin = int(x0) - position if float(x0).is_integer() else x0 - position
    x, ends = origin, [origin]
    for s in segments:  # summed relative to the origin: the same in any pass
        x += (s.v0 + 0.5 * s.a * s.dt) * s.dt
        ends.append(x)
    return Move(Tag.MOVE, e.t - start, e.kind, e.target - position, origin, requested,
                e.arrival - e.t, tuple(s.dt for s in segments), min(ends), max(ends))


def plain(shape: tuple) -> bool:
    """Whether a shape is the same at any position (no moves, no position reports; a move
    that keeps the running profile changes nothing: Kept)."""
    for item in shape:
        match item:
            case Report() | Outputs() | Kept():
                pass
            case Skip(shape=inner) if plain(inner):
                pass
            case _:
                return False
    return True


_SELECTS = {Tag.REPORT: (Tag.REPORT, Tag.PLACED), Tag.OUTPUTS: (Tag.OUTPUTS,)}


def count(shape: tuple, kind: Tag) -> int:
    """How many reports (REPORT) or output changes (OUTPUTS) one pass of `shape` emits."""
    selected, total = _SELECTS[kind], 0
    for item in shape:
        match item:
            case Skip(passes=n, shape=inner) | Shifted(passes=n, shape=inner):
                total += n * count(inner, kind)
            case _ if item.tag in selected:
                total += 1
    return total


def expand(shape: tuple, start: int, period: int, passes: int, kind: Tag,
           position: int = 0, shift: int = 0) -> Iterator[ev.Reported | ev.OutputsChanged]:
    """The events of `kind` that `passes` passes of `shape` from `start` emit, in time order;
    the first pass starts at `position`, each next one `shift` further (a shifted skip)."""
    selected = _SELECTS[kind]
    items = [item for item in shape if item.tag in selected or
             (item.tag in (Tag.SKIP, Tag.SHIFTED) and count(item.shape, kind))]
    if not items:
        return
    for p in range(passes):
        base, at = start + p * period, position + p * shift
        for item in items:
            match item:
                case Report(offset, text, where):
                    yield ev.Reported(base + offset, text, where)
                case Placed(offset, ident, relative, where):
                    yield ev.Reported(base + offset, number(ident, at + relative), where)
                case Outputs(offset, pattern):
                    yield ev.OutputsChanged(base + offset, pattern)
                case Shifted(offset, n, inner_period, inner, _, relative, inner_shift):
                    yield from expand(inner, base + offset, inner_period, n, kind,
                                      at + relative, inner_shift)
                case Skip(offset, n, inner_period, inner):
                    yield from expand(inner, base + offset, inner_period, n, kind)


def compact(shape: tuple, start: int, period: int,
            passes: int) -> Iterator[Stretch | ev.OutputsChanged]:
    """A skip as a plot or a VCD draws it: the Stretch of its passes, then the output changes
    of the last pass, each inner skip drawn alike (a day of blinking is not a million
    changes)."""
    last = start + (passes - 1) * period
    yield Stretch(start, last, passes)
    for item in shape:
        match item:
            case Outputs(offset, pattern):
                yield ev.OutputsChanged(last + offset, pattern)
            case Skip(offset, n, inner_period, inner) | Shifted(offset, n, inner_period, inner):
                yield from compact(inner, last + offset, inner_period, n)
