"""One Value Change Dump of a rig: a scope per controller (x.box, x.axis, x.vm, y.box, ...),
each written by the VcdObserver of one machine (sim/vcd.py).

The machines' events come in time order across the rig, but a rig's skip (sim/rig_ff.py)
has each controller dump the last skipped pass after it, while the next controller's skip
starts before that; so the observers' changes are kept and written in time order at the
end, stopping cleanly before the file would pass `limit` bytes.
"""
from __future__ import annotations

from typing import IO

from vcd import VCDWriter

from mercmac.sim.vcd import CLOSING, VcdObserver, _Counted


class _Kept:
    """What a VcdObserver writes to: variables on the real writer, changes kept."""

    def __init__(self, writer: VCDWriter, changes: list):
        self.writer, self.changes = writer, changes

    def register_var(self, *args, **kwargs):
        return self.writer.register_var(*args, **kwargs)

    def change(self, var, t: int, value) -> None:
        self.changes.append((t, len(self.changes), var, value))

    def close(self, t: int) -> None:
        pass


class RigVcd:
    """The dump of a rig run; `listeners()` per controller, then `close(end_us)`."""

    def __init__(self, stream: IO[str], names: list[str], limit: int | None = None):
        self.out = _Counted(stream)
        self.limit = limit
        self.cut_at: int | None = None
        self.writer = VCDWriter(self.out, timescale="1 us", date="", comment="mercmac sim (rig)")
        self.changes: list = []
        kept = _Kept(self.writer, self.changes)
        self.observers = {name: VcdObserver(None, writer=kept, scope=name) for name in names}

    def listeners(self) -> dict[str, list]:
        return {name: [o.on_event] for name, o in self.observers.items()}

    def close(self, end_us: int) -> None:
        for observer in self.observers.values():
            observer.close(end_us)  # samples each profile to the end
        self.changes.sort(key=lambda c: (c[0], c[1]))
        for t, _, var, value in self.changes:
            if self.limit is not None and self.out.written + CLOSING > self.limit:
                self.cut_at = t
                break
            self.writer.change(var, t, value)
        self.writer.close(self.cut_at if self.cut_at is not None else end_us)
