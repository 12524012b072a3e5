"""The I/O lines: inputs 1-6 with their scheduled changes, outputs 1-4 (the C-170.PB LEDs)."""
from __future__ import annotations

import heapq
import math
from dataclasses import dataclass

from mercmac.vm.statekey import key, keyed, unkeyed

INPUTS = range(1, 7)  # 1-4 pushbuttons, 5 joystick (ON above mid-scale), 6 joystick button


class Inputs:
    """Input lines and the changes scheduled for them (a button script)."""

    def __init__(self):
        self.state = [False] * 7  # index 0 unused
        # changes by time, in scheduling order, and a heap of those times: a button script
        # of 100,000 presses costs O(log n) per distinct time, not a list shift per change
        self._due: dict[int, list[tuple[int, bool]]] = {}
        self._times: list[int] = []

    def __getitem__(self, n: int) -> bool:
        return self.state[n]

    def schedule(self, t_us: int, n: int, on: bool) -> None:
        """Set input n at time t_us; changes at the same time apply in scheduling order."""
        changes = self._due.get(t_us)
        if changes is None:
            changes = self._due[t_us] = []
            heapq.heappush(self._times, t_us)
        changes.append((n, on))

    def next_change(self) -> float:
        return self._times[0] if self._times else math.inf

    def pop_due(self, t_us: int) -> list[tuple[int, bool]]:
        """Changes due at or before t_us, removed from the schedule, that change a line."""
        changed = []
        while self._times and self._times[0] <= t_us:
            for n, on in self._due.pop(heapq.heappop(self._times)):
                if self.set(n, on):
                    changed.append((n, on))
        return changed

    def set(self, n: int, on: bool) -> bool:
        """Set a line now; True if it changed."""
        if self.state[n] == on:
            return False
        self.state[n] = on
        return True

    def pattern(self) -> int:
        """Inputs 1-4 as bits 0-3 (TC0, §6.4 TC); spelled out, as every TS reads it."""
        state = self.state
        return state[1] | state[2] << 1 | state[3] << 2 | state[4] << 3


@keyed()
@dataclass(eq=False)
class Outputs:
    """Four digital outputs; output 4 also carries trigger pulses (§4.5.2)."""

    set_bits: int = key(default=0)  # what CN/CF/CP programmed
    # a time: a pulse still on bounds a skip as a hardware event (Machine._next_hardware),
    # and one that ended shows nothing
    pulse_until: float = unkeyed("when the trigger pulse on output 4 ends", default=-math.inf)

    def pattern(self, t_us: float) -> int:
        """The 4-bit pattern the LEDs show at t_us (bit 0 = output 1, §6.4 CP)."""
        return self.set_bits | (8 if t_us < self.pulse_until else 0)

