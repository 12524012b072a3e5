"""The controller's clock: integer microseconds and the command cycle
(docs/simulator.md, "Time")."""
from __future__ import annotations

from dataclasses import dataclass

from mercmac.vm.statekey import key, keyed, unkeyed


class CycleError(ValueError):
    """A command cycle the clock cannot count in (not finite, or outside 1 us to 1 s)."""


@keyed()
@dataclass(init=False, eq=False)
class Clock:
    """Now, in us since power-on, and how long one executed command takes."""

    cycle: int = key()  # us per executed command
    now: int = unkeyed("the clock itself: passes are compared at different times")

    def __init__(self, cycle_ms: float = 1.0):
        # bounded before rounding: round() fails on nan and inf, and 1e308 ms * 1000 is inf
        sane = isinstance(cycle_ms, (int, float)) and 0 < cycle_ms <= 2000
        cycle_us = round(cycle_ms * 1000) if sane else 0
        if not 1 <= cycle_us <= 1_000_000:
            raise CycleError(f"command cycle {cycle_ms!r} ms: use 0.001 ms to 1000 ms")
        self.cycle = cycle_us
        self.now = 0

    @property
    def now_ms(self) -> float:
        return self.now / 1000
