"""The bounds of a skip: when the passes of a loop repeat, and how many of them may be
skipped (docs/simulator.md, "Fast-forward"). The optimiser (vm/optimiser.py) applies these
rules to a running machine; a rig's joint skip (sim/rig_skip.py) bounds each machine's shifted
passes with shifted_passes.

A loop anchor is an RP jump or the entry of a macro by EM. When a loop comes back to its
anchor with the whole machine state equal to the last visit (apart from the clock and the
jumping RP's own counter), with no input change, and the pass emitted what the one before it
did (the same shape, vm/shapes.py), the next passes are copies of that one: each lasts
`period` and does the same, until an input changes, the run ends or the RP counter runs out
(same_pass, skippable). So they can be skipped with the clock and counter advanced exactly.

Shifted passes (a jog loop with a button held, a scan stepping forever): a pass is the same
pass, `delta` counts further on, when the machine state apart from the position and target
is the same; the axis may rest on a whole count or, at the anchor, still run the profile a
pass started, keyed by what it was planned from relative to the time and the target
(Axis.relative), and the trigger by where it fires relative to the target
(Trigger.relative). Two such passes in a row with the same moved shape (moves, arrivals and
position reports relative to the pass's start position: shapes.moved_shape) and the same
delta are copies (same_shifted_pass); the skip (shifted_passes) stops before the next
boundary: a soft limit or +-MAX_POSITION clamp, a hard limit switch, the end of the run, an
input change, the RP counter's end, and the time from which the float sum of a profile's
segment lengths could round to another arrival microsecond; and for a pass that reads TS,
the edges of the reference and limit switches, whose lines its text shows (`_one_side`).
A pass that computes with fractional positions (a move started on the way, a report or a
trigger pulse while the axis moves: `Note.FLOATS`) repeats bit for bit only while its
positions and times stay within the powers of two of the pass seen (`_same_binade`), which
bound its skips too. What a pass does that cannot shift exactly (ZM/ZP/ZI in the pass, a
reference search, DH, AB1, a limit hit, a position exactly half-way when reported) leaves
`Note.UNSHIFTABLE` in the effect log and makes the pass unskippable.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum
from fractions import Fraction
from typing import Iterator, NamedTuple

from mercmac.vm.motion import Plan, shared
from mercmac.vm.shapes import (ABSOLUTE, FLOATING, Absolute, Arrive, Kept, Move, Placed,
                               Requested, Shifted)


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
    logged: int  # effects logged so far (the optimiser's effect log)
    shape: tuple | None  # what the pass that ended here emitted; None: unknown or unrepeatable
    skey: tuple | None = None  # key without position and target; None unless at rest on target
    position: int = 0  # the target (= position) here, when skey is not None
    delta: int | None = None  # position - the last visit's; None unless skeys were equal
    moved: tuple | None = None  # shapes.moved_shape of the pass that ended here
    t: int = 0  # when the loop came round, us
    fresh: bool = False  # the axis ran a profile planned since the visit before
    flows: int = 0  # macro entries and exits so far, those of skipped passes too


class Pass(NamedTuple):
    """What shifted_passes reads of the pass that ended at an anchor (a Visit has it too; a
    rig's joint skip, sim/rig_skip.py, has no Visit of its own)."""

    wake: int  # when the pass ended, us
    position: int  # the target there
    delta: int  # how much further on it ended than it began
    moved: tuple  # its shapes.moved_shape


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


# ---------------------------------------------------------------- how far a shifted skip goes
def shifted_passes(now: Visit | Pass, period: int, fit: int, bounds: tuple, hard: tuple | None,
                   reference: float | None = None, grid: int = 0) -> int:
    """How many of `fit` passes shifted by now.delta each stay clear of every boundary.

    bounds: the soft range (max(JL, -MAX_POSITION), min(JH, MAX_POSITION)) at the anchor;
    hard: the limit switches in present coordinates, or None; reference: the reference
    switch's edge in present coordinates, or None to skip no pass that shows the switches;
    grid: ZI of a trigger in grid mode (ZM3), whose pulses divide positions by it, else 0.
    """
    delta, pos = now.delta, now.position
    floats = _holds(now.moved, FLOATING)
    if floats:
        fit = _same_binade(now, period, fit, grid)
    if delta and _holds(now.moved, ABSOLUTE):
        if reference is None:
            return 0  # TS shows the switches: where they are crossed is not counted here
        for edge in (reference, *(hard or ())):  # the reference and limit lines (§6.4 TS)
            fit = min(fit, _one_side(now, edge, fit))
    same_times = None  # passes within the same power of two of time, when first needed
    for move, latest, starts in _moves(now.moved, 0, (0,)):
        for start in starts:
            fit = min(fit, _unclamped(move.requested, pos + start, delta, fit),
                      _clear(move, pos + start, delta, fit, hard))
        if floats:  # (_same_binade covers the arrivals of a pass with floats)
            continue
        arrives = _same_arrival(move, now.wake + latest, period, fit)
        if arrives < fit:  # an arrival a hair from a whole us (2000.0000000000002 twice)
            if same_times is None:
                same_times = _same_time_binade(now, period, fit)
            arrives = max(arrives, same_times)
        fit = min(fit, arrives)
    return max(fit, 0)


def _holds(shape: tuple, mark: Absolute) -> bool:
    """Whether a pass, or a skip inside it, has `mark` (ABSOLUTE: TS; FLOATING: floats)."""
    for item in shape:
        match item:
            case Absolute() if item == mark:
                return True
            case Shifted(shape=inner) if _holds(inner, mark):
                return True
    return False


def _span(shape: tuple) -> tuple[float, float]:
    """The positions a pass visits, relative to its start: its start, its moves (overshoot
    and all), arrivals and reports, and those of the skips inside it."""
    low = high = 0
    for item in shape:
        match item:
            case Move():
                low, high = min(low, item.low, item.target), max(high, item.high, item.target)
            case Arrive(position=x) | Placed(position=x):
                low, high = min(low, x), max(high, x)
            case Shifted(passes=n, shape=inner, position=relative, shift=shift):
                lo, hi = _span(inner)
                for start in (relative, relative + (n - 1) * shift):
                    low, high = min(low, start + lo), max(high, start + hi)
    return low, high


def _same_binade(now: Visit, period: int, fit: int, grid: int = 0) -> int:
    """Passes that repeat bit for bit a pass computed with fractional positions and times.

    A float x + r (an absolute position or time plus a relative amount) rounds to the grid
    of x's power of two; moved on by whole counts or microseconds, which that grid divides
    evenly below 2**52, it rounds alike while it stays within the same power of two and
    sign, and the difference of two such values is exact (Sterbenz). So the skipped passes
    compute what the pass just seen computed, moved on, while every position they take (a
    count of margin) and every time stays within the powers of two of that pass and of the
    one before it: the profile still running at the anchor was planned there, and the key
    holds it relative to the target (Axis.relative), a difference exact only within them.
    """
    low, high = _span(now.moved)
    first = now.position - now.delta  # where the pass just seen started
    before = first - now.delta  # and the one before it
    lo, hi = math.floor(min(first, before) + low) - 1, math.ceil(max(first, before) + high) + 1
    fit = _within_binade(lo, hi, now.delta, fit)
    if grid and now.delta % grid == 0:  # grid pulses: position / ZI rounds alike too
        fit = _within_binade(lo // grid - 1, -(-hi // grid) + 1, now.delta // grid, fit)
    return _same_time_binade(now, period, fit)


def _same_time_binade(now: Visit, period: int, fit: int) -> int:
    """Passes whose times (from the start of the pass before the one just seen to the last
    arrival) stay within the power of two of those two passes': their float sums of segment
    lengths round alike (_same_binade)."""
    tail = max((latest + move.offset + math.ceil(move.arrival)
                for move, latest, _ in _moves(now.moved, 0, (0,))), default=0)
    return _within_binade(now.wake - 2 * period - 1, now.wake + max(period, tail) + 1, period,
                          fit)


def _within_binade(lo: int, hi: int, step: int, fit: int) -> int:
    """How many of `fit` steps keep lo..hi, moved on by `step` each, within the power of two
    and the sign it has now (0 if it is not within one now); all of them for a step of 0,
    which computes the very same values every time."""
    if step == 0:
        return fit
    if lo <= 0 <= hi:
        return 0
    if hi < 0:
        lo, hi, step = -hi, -lo, -step
    top = 1 << hi.bit_length()  # lo..hi must lie in [top / 2, top)
    if lo < top >> 1:
        return 0
    if step > 0:
        return min(fit, (top - 1 - hi) // step)
    if step < 0:
        return min(fit, (lo - (top >> 1)) // -step)
    return fit


EXACT_US = 2**53  # below this, sums of whole floats are exact (_same_arrival)
FAR = 2**64  # beyond any position (a finite bound: last_inside divides by the shift)


def _one_side(now: Visit, edge: float, fit: int) -> int:
    """Passes that stay, with the pass just seen, on one side of a switch's edge: TS at rest
    shows the reference line (§6.4 FE2) and the limit lines, so its text repeats until a
    pass's span reaches an edge."""
    low, high = _span(now.moved)
    first = now.position - now.delta  # the pass just seen, whose TS texts the skip repeats
    # a count clear of the edge: Axis.reference_high and limit_switch compare position - DH
    # shift in floats
    if first + high <= edge - 1:
        lo, hi = -FAR, math.floor(edge - 1) - high
    elif first + low >= edge + 1:
        lo, hi = math.ceil(edge + 1) - low, FAR
    else:
        return 0
    return max(last_inside(lo, hi, first, now.delta, fit + 1) - 1, 0)


def _moves(shape: tuple, latest: int, starts: tuple) -> Iterator[tuple[Move, int, tuple]]:
    """Each move of a pass, with a bound on its pass's start time (relative) and the
    relative start positions of its first and last copy (inner shifted skips repeat it)."""
    for item in shape:
        match item:
            case Move():
                yield item, latest, starts
            case Shifted(offset, n, period, inner, _, relative, shift):
                inner_starts = tuple({s + relative + q * shift for s in starts for q in (0, n - 1)})
                yield from _moves(inner, latest + offset + n * period, inner_starts)


def last_inside(lo: float, hi: float, first: int, delta: int, fit: int) -> int:
    """How many passes p = 0, 1, ... keep first + p*delta within [lo, hi] (at most fit)."""
    if not lo <= first <= hi:
        return 0
    if delta > 0:
        return min(fit, int((hi - first) // delta) + 1)
    if delta < 0:
        return min(fit, int((first - lo) // -delta) + 1)
    return fit


def _unclamped(requested: Requested | None, pos: int, delta: int, fit: int) -> int:
    """Passes whose move targets stay unclamped (a clamp is a soft-limit boundary)."""
    if requested is None or delta == 0:  # a stop, or the very same targets every pass
        return fit
    return last_inside(requested.lo, requested.hi, pos + requested.target, delta, fit)


def steady_passes(now: Visit, period: int, fit: int, plan: Plan | None,
                  switches: tuple[float, float] | None) -> int:
    """How many of `fit` passes that leave the running profile going on (shapes.steady),
    their targets each `now.delta` further on, keep every move they make on it: no target
    clamped by the soft limits (a clamp is a hazard) or within 2 counts of a limit switch,
    and each move to another target made while the stage still takes the path that profile
    shares with the running one (motion.shared), with a pass to spare. Both sides of that
    are straight lines in the pass's number, so the passes between the first and the last
    that hold hold too. `plan`: what the running profile was planned from (None when its
    segments are no longer those it plans: no move to another target is skipped)."""
    delta, pos = now.delta, now.position
    kept = [item for item in now.shape if type(item) is Kept]
    for item in kept:
        fit = _unclamped(item.requested, pos, delta, fit)
        if switches is not None and delta:  # a profile to a target clear of the switches
            fit = last_inside(switches[0] + 2 - item.target, switches[1] - 2 - item.target,
                              pos, delta, fit)  # never reaches them
    moving = [item for item in kept if item.target != item.before]
    if not moving or fit <= 0:
        return fit
    if plan is None:
        return 0

    def holds(j: int) -> bool:  # pass j of the skip (0: the first) keeps its moves
        start, begins = pos + j * delta, now.wake + j * period
        for item in moving:
            before = plan._replace(target=start + item.before)
            if shared(before, before.segments(), begins + item.offset + period,
                      start + item.target) is None:
                return False
        return True

    if not holds(0):
        return 0
    lo, hi = 0, fit - 1  # the last pass that holds
    while lo < hi:
        mid = (lo + hi + 1) // 2
        if holds(mid):
            lo = mid
        else:
            hi = mid - 1
    return lo + 1


def _clear(move: Move, pos: int, delta: int, fit: int, hard: tuple | None) -> int:
    """Passes whose move stays 2 counts clear of the limit switches, in float and all (even
    unshifted: a profile's float end, taken at another time, could touch a switch it ends on)."""
    if hard is None:
        return fit
    lo, hi = hard[0] + 2, hard[1] - 2
    low, high = min(move.target, move.low), max(move.target, move.high)
    return min(last_inside(lo - low, hi - low, pos, delta, fit),
               last_inside(lo - high, hi - high, pos, delta, fit))


def _same_arrival(move: Move, wake: int, period: int, fit: int) -> int:
    """Passes in which the profile's end, summed in floats from its start time, still rounds
    up to the same microsecond: each of the sums adds at most half an ulp of the time."""
    offset, arrival, dts = move.offset, move.arrival, move.dts
    if not dts:
        return fit
    if arrival == sum(dts) and all(float(d).is_integer() for d in dts):
        # whole microseconds from a command's whole time: every float sum is exact below 2**53
        return min(fit, max((EXACT_US - wake) // period - 1, 0))
    exact = sum(map(Fraction, dts), Fraction(0))
    up = math.ceil(exact)
    gap = min(exact - (up - 1), up - exact)
    if gap <= 0 or arrival != up:
        return 0

    def safe(n: int) -> bool:
        latest = wake + n * period + offset + up + 1
        return Fraction(math.ulp(float(latest))) * len(dts) < gap

    lo, hi = 0, fit
    while lo < hi:  # the error grows with the time: the largest n that is safe
        mid = (lo + hi + 1) // 2
        if safe(mid):
            lo = mid
        else:
            hi = mid - 1
    return lo
