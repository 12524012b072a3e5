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
    # where the next pulse of mode 1 or 2 fires; a shifted pass keys it relative to the
    # target (`relative`)
    next_at: int = key(init=False, shifts=True)
    done: bool = key(init=False)  # single mode has fired
    # a time, compared with the pulse times of a profile: only a pulse of the running
    # profile can be as late, and a skip moves it on with the profile (`translate`)
    last_t: float = unkeyed("the time of the last pulse, moved on by a skip", init=False)

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

    def relative(self, target: int) -> tuple:
        """What decides the next pulses relative to the target: the same in two passes that
        repeat shifted (vm/optimiser.py). Multiple mode fires at next_at, then ZI further on;
        grid mode at multiples of ZI, the same relative to a target a whole number of ZI on."""
        if self.mode == 2 or (self.mode == 1 and not self.done):
            return self.next_at - target,
        if self.mode == 3 and self.increment:
            return target % abs(self.increment),
        return ()

    def translate(self, dt: int, dx: int) -> None:
        """Moved on with the axis by a skip of passes (Axis.translate): multiple mode's next
        position as the pulses of the skipped passes moved it, the last pulse's time."""
        if self.mode == 2:
            self.next_at += dx
        self.last_t += dt

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
