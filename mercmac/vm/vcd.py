"""A Value Change Dump of a run for GTKWave or Surfer, written with pyvcd (issue 3, `--vcd`).

The writer listens to the machine's events as they happen, so nothing is
capped: inputs, outputs, the running macro, and the position sampled every
millisecond while a profile runs (exact at its ends).
"""
from __future__ import annotations

from typing import IO

from vcd import VCDWriter

from mercmac.vm import events as ev

SAMPLE_US = 1000  # position samples while moving


class VcdObserver:
    """An event listener that writes value changes; call `close(t_us)` at the end."""

    def __init__(self, stream: IO[str], then=None):
        self.then = then  # the next listener (the recorder)
        self.writer = VCDWriter(stream, timescale="1 us", date="", comment="mercmac sim")
        reg = self.writer.register_var
        self.inputs = [None] + [reg("box", f"in{n}", "wire", size=1, init=0) for n in range(1, 7)]
        self.outputs = [reg("box", f"out{n}", "wire", size=1, init=0) for n in range(1, 5)]
        self.position = reg("axis", "position", "integer", size=32, init=0)
        self.target = reg("axis", "target", "integer", size=32, init=0)
        self.macro = reg("vm", "macro", "reg", size=6, init="z")
        self.segments: tuple = ()
        self.sampled_to = 0
        self.last = 0

    def on_event(self, event) -> None:
        t = max(getattr(event, "t", self.last), self.last)
        self._sample(t)
        self.last = t
        self._change(event, t)
        if self.then:
            self.then(event)

    def _change(self, event, t: int) -> None:
        w = self.writer
        match event:
            case ev.InputChanged(_, n, on):
                w.change(self.inputs[n], t, int(on))
            case ev.OutputsChanged(_, pattern):
                for i, var in enumerate(self.outputs):
                    w.change(var, t, pattern >> i & 1)
            case ev.MacroEntered(_, slot):
                w.change(self.macro, t, slot)
            case ev.MacroLeft(back_slot=back):
                w.change(self.macro, t, back if back is not None and back >= 0 else "z")
            case ev.MoveStarted(_, _, target, _, segments):
                w.change(self.target, t, target)
                self.segments, self.sampled_to = segments, t
            case ev.MoveEnded(_, _, position) | ev.HomeDefined(_, position):
                self.segments = ()
                w.change(self.position, t, position)

    def _sample(self, until: int) -> None:
        """Position samples of the running profile up to `until`."""
        if not self.segments:
            return
        end = min(until, int(self.segments[-1].t1) + 1)
        t = self.sampled_to
        while t < end:
            self.writer.change(self.position, t, round(_position(self.segments, t)))
            t += SAMPLE_US
        self.sampled_to = t

    def close(self, t_us: int) -> None:
        self._sample(t_us)
        self.writer.close(t_us)


def _position(segments: tuple, t: float) -> float:
    for seg in segments:
        if t < seg.t1:
            return seg.x(t)
    return segments[-1].x(segments[-1].t1)
