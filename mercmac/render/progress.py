"""The progress line of a long simulation on a terminal: simulated time reached, and rate."""
from __future__ import annotations

import time
from typing import TextIO

from mercmac.timespec import format_clock

DELAY_S = 1.0  # only runs that take more than a second show progress
EVERY_S = 0.2  # redraw at most this often


class ProgressLine:
    """`update(now_ms)` redraws one stderr line in place; `close()` erases it."""

    def __init__(self, stream: TextIO, until_ms: float):
        self.stream, self.until_ms = stream, until_ms
        self.start = self.drawn = time.perf_counter()
        self.shown = False

    def update(self, now_ms: float) -> None:
        wall = time.perf_counter()
        if wall - self.start < DELAY_S or wall - self.drawn < EVERY_S:
            return
        self.drawn = wall
        rate = now_ms / 1000 / (wall - self.start)
        share = now_ms / self.until_ms if self.until_ms else 1
        # \r and ESC [K (erase to end of line): the line is redrawn where it stands
        self.stream.write(f"\r\x1b[Ksimulating: {_clock(now_ms)} of {_clock(self.until_ms)} "
                          f"({share:.0%}), {rate:,.0f} simulated s per s")
        self.stream.flush()
        self.shown = True

    def close(self) -> None:
        if self.shown:
            self.stream.write("\r\x1b[K")
            self.stream.flush()


def _clock(ms: float) -> str:
    """'1500d 00:00:00': whole seconds in a field of steady width, the line is redrawn."""
    return format_clock(ms * 1000, places=0, fixed=True)
