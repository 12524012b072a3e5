"""Fast-forward: skip the identical passes of a polling loop in one step (issue 3, item 5).

A loop anchor is an RP jump or the entry of a macro by EM. When a loop comes
back to its anchor with the whole machine state equal to the last visit (apart
from the clock and the jumping RP's own counter), with nothing observable in
between and no input change, the next passes are copies of that one: each
lasts `period` and does the same, until an input changes, the run ends or the
RP counter runs out. So they can be skipped with the clock and counter advanced
exactly.
"""
from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class Visit:
    """The machine at one arrival at an anchor."""

    key: tuple | None  # state without clock and own counter; None when moving
    wake: int  # when the pass starts, us
    effects: int  # observable events so far
    inputs: int  # input change count so far
    waits: int  # wait instructions executed so far


class Anchors:
    """The last visit of every loop anchor."""

    def __init__(self):
        self.visits: dict[tuple, Visit] = {}

    def arrive(self, anchor: tuple, visit: Visit) -> Visit | None:
        """Record a visit; return the previous one if it bounds a pass."""
        previous = self.visits.get(anchor)
        self.visits[anchor] = visit
        return previous

    def forget_slot(self, slot: int) -> None:
        """A macro was entered: its RP counters restart, so its loop visits are void."""
        for anchor in [a for a in self.visits if a[0] == "rp" and a[1] == slot]:
            del self.visits[anchor]

    def forget(self, anchor: tuple) -> None:
        self.visits.pop(anchor, None)

    def clear(self) -> None:
        self.visits.clear()


def same_pass(previous: Visit, now: Visit) -> bool:
    """True when the pass from `previous` to `now` will repeat exactly."""
    return (now.key is not None and now.key == previous.key and now.effects == previous.effects
            and now.inputs == previous.inputs and now.wake > previous.wake)


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
