"""Trigger pulses on output 4 at positions set by ZM, ZP, ZI (MS176E §4.5.2, §6.4 ZM).

The manual gives no pulse width; 100 us keeps pulses distinct up to 10,000 a
second. Grid mode (ZM3) pulses whenever the position crosses a multiple of ZI.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from mercmac.vm.motion import Axis
from mercmac.vm.statekey import key, keyed, unkeyed

PULSE_US = 100


@keyed()
@dataclass(eq=False)
class Trigger:
    """Trigger mode and positions; finds the time of the next pulse on a profile."""

    mode: int = key(init=False)  # ZM: 0 off, 1 single, 2 multiple, 3 grid
    position: int = key(init=False)  # ZP
    increment: int = key(init=False)  # ZI
    next_at: int = key(init=False)  # where the next pulse of mode 1 or 2 fires
    done: bool = key(init=False)  # single mode has fired
    # a time, compared with the pulse times of a profile; the key is taken only while
    # no profile runs, and a pass that moves never repeats
    last_t: float = unkeyed("the time of the last pulse", init=False)

    def __post_init__(self):
        self.reset()

    def reset(self) -> None:
        """Power-on: trigger off (§6.4 ZM factory default)."""
        self.mode, self.position, self.increment = 0, 0, 0
        self.rearm()

    def rearm(self) -> None:
        """Any ZM/ZP/ZI restarts the sequence at ZP."""
        self.next_at = self.position
        self.last_t = -math.inf
        self.done = False

    def next_time(self, axis: Axis, now: float) -> float:
        """The time of the next pulse after `now` (inf if none while the profile runs)."""
        if self.mode == 0 or self.done or (self.mode == 3 and self.increment == 0):
            return math.inf
        for seg in axis.segs:
            if seg.t1 <= now:
                continue
            start = max(seg.t0, now)
            when = seg.time_at(self._goal(seg, start)) if self.mode == 3 else seg.time_at(self.next_at)
            if when is not None and when >= start and when > self.last_t:
                return math.ceil(when)
        return math.inf

    def _goal(self, seg, start: float) -> float:
        """The next grid line beyond the position at `start`, in the segment's direction."""
        step, x = abs(self.increment), seg.x(start)
        ahead = seg.x(seg.t1) >= seg.x0
        return (math.floor(x / step) + 1) * step if ahead else (math.ceil(x / step) - 1) * step

    def fire(self, t: float) -> None:
        """A pulse went out at t: single mode is done, multiple mode moves on by ZI."""
        self.last_t = t
        if self.mode == 1:
            self.done = True  # ZM1 again rearms
        elif self.mode == 2:
            self.next_at += self.increment
