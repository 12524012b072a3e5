"""The controller's clock: integer microseconds and the command cycle (SPEC §3 Time)."""
from __future__ import annotations

from mercmac.errors import UsageError


class Clock:
    """Now, in us since power-on, and how long one executed command takes."""

    def __init__(self, cycle_ms: float = 1.0):
        cycle_us = round(cycle_ms * 1000)
        if not 1 <= cycle_us <= 1_000_000:
            raise UsageError(f"command cycle {cycle_ms} ms: use 0.001 ms to 1000 ms")
        self.cycle = cycle_us
        self.now = 0

    @property
    def now_ms(self) -> float:
        return self.now / 1000
