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
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum
from operator import attrgetter
from typing import Iterator, NamedTuple

from mercmac.vm import events as ev

REPORT, OUTPUTS, SKIP = "report", "outputs", "skip"  # what a shape's items are
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
            items.append((SKIP, e.t - start, e.passes, e.period, e.shape, e.loop))
        else:  # motion, inputs, hazards: not the same in the next pass
            return None
    return tuple(items)


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
    return sum(1 if item[0] == kind else item[2] * count(item[4], kind)
               for item in shape if item[0] in (kind, SKIP))


def expand(shape: tuple, start: int, period: int, passes: int, kind: str) -> Iterator:
    """The events of `kind` that `passes` passes of `shape` from `start` emit, in time order."""
    items = [item for item in shape
             if item[0] == kind or (item[0] == SKIP and count(item[4], kind))]
    if not items:
        return
    for p in range(passes):
        base = start + p * period
        for item in items:
            if item[0] == REPORT:
                yield ev.Reported(base + item[1], item[2], item[3])
            elif item[0] == OUTPUTS:
                yield ev.OutputsChanged(base + item[1], item[2])
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
