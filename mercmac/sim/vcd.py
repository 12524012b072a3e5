"""A Value Change Dump of a run for GTKWave or Surfer, written with pyvcd (`--vcd`).

A writer per controller listens to its machine's events as they happen: inputs, outputs,
the running macro, and the position sampled every millisecond while a profile
runs (exact at its ends). A fast-forwarded stretch is written compactly: the
wire `vm.fast_forward` is 1 while its passes are left out, and the last pass is
dumped in full (a day of blinking is not a million value changes).
The dump stops cleanly before it would pass `limit` bytes; `cut_at` says when.

A rig of several controllers is one dump with a scope per controller (x.box, x.axis,
x.vm, y.box, ...). The machines' events come in time order across the rig, but a skip
has a controller dump the last skipped pass after it while the next controller's events
start before that; so their changes are kept and written in time order at the end.
"""
from __future__ import annotations

from typing import IO

from vcd import VCDWriter

from mercmac.vm import events as ev
from mercmac.vm import shapes

SAMPLE_US = 1000  # position samples while moving
MOVES_KEPT = 64  # moves remembered for the last pass of a shifted skip (a longer pass: some)
CLOSING = 65_536  # bytes kept in hand below the limit: far more than one event writes


class _Counted:
    """A text stream that counts the characters written (ASCII: bytes)."""

    def __init__(self, stream: IO[str]):
        self.stream, self.written = stream, 0

    def write(self, text: str) -> int:
        self.written += len(text)
        return self.stream.write(text)

    def flush(self) -> None:
        self.stream.flush()


class VcdObserver:
    """An event listener that writes value changes; call `close(t_us)` at the end."""

    def __init__(self, stream: IO[str] | None, limit: int | None = None, *,
                 writer=None, scope: str = ""):
        """`writer` and `scope`: one controller of a rig writing into a shared dump (its
        scopes under `scope`, Dump); else a dump of its own on `stream`."""
        self.out = _Counted(stream) if writer is None else _Counted(None)
        self.limit = limit
        self.cut_at: int | None = None  # us: where the dump stopped at the size limit
        self.writer = writer or VCDWriter(self.out, timescale="1 us", date="",
                                          comment="mercmac sim")
        reg = self.writer.register_var
        box, axis, vm = (f"{scope}.{s}" if scope else s for s in ("box", "axis", "vm"))
        self.inputs = [None] + [reg(box, f"in{n}", "wire", size=1, init=0) for n in range(1, 7)]
        self.outputs = [reg(box, f"out{n}", "wire", size=1, init=0) for n in range(1, 5)]
        self.position = reg(axis, "position", "integer", size=32, init=0)
        self.target = reg(axis, "target", "integer", size=32, init=0)
        self.macro = reg(vm, "macro", "reg", size=6, init="z")
        self.skipping = reg(vm, "fast_forward", "wire", size=1, init=0)
        self.segments: tuple = ()
        self.sampled_to = 0
        self.last = 0
        self.moves: list = []  # the latest moves: a shifted skip's last pass copies them
        self.planned = None  # what a kept profile was planned from (MoveStarted.plan)
        self.retarget: tuple[int, int] | None = None  # (t, target): a steady skip's target

    def on_event(self, event) -> None:
        if self.cut_at is None:
            t = max(getattr(event, "t", self.last), self.last)
            self._sample(t)
            self.last = t
            if self.cut_at is None:
                self._change(event, t)
                self._check_size(self.last)

    def _full(self) -> bool:
        return self.limit is not None and self.out.written + CLOSING > self.limit

    def _check_size(self, t: int) -> None:
        """Stop the dump at t, a valid file, before it passes the limit."""
        if self._full():
            self.cut_at = t
            self.writer.close(t)

    def _change(self, event, t: int) -> None:
        w = self.writer
        match event:
            case ev.InputChanged(_, n, on):
                w.change(self.inputs[n], t, int(on))
            case ev.OutputsChanged(_, pattern):
                self._outputs(t, pattern)
            case ev.MacroEntered(_, slot):
                w.change(self.macro, t, slot)
            case ev.MacroLeft(back_slot=back):
                w.change(self.macro, t, back if back is not None and back >= 0 else "z")
            case ev.MoveStarted(_, _, target, _, segments):
                w.change(self.target, t, target)
                self.segments, self.sampled_to = segments, t
                self.planned = event.plan
                self.moves = self.moves[-MOVES_KEPT + 1:] + [event]
            case ev.MoveEnded(_, _, position) | ev.HomeDefined(_, position):
                self.segments = ()
                w.change(self.position, t, position)
            case ev.FastForwarded():
                self._stretch(event)

    def _outputs(self, t: int, pattern: int) -> None:
        for i, var in enumerate(self.outputs):
            self.writer.change(var, t, pattern >> i & 1)

    def _stretch(self, skip: ev.FastForwarded) -> None:
        """Skipped passes: marked, all but the last left out; the last one dumped (of a
        shifted skip with the position: vcd changes must come in time order)."""
        changes = []
        for step in shapes.compact(skip.shape, skip.t, skip.period, skip.passes):
            match step:
                case shapes.Stretch(start, last, n):
                    if n > 1:
                        changes += [(start, self.skipping, 1), (last, self.skipping, 0)]
                case ev.OutputsChanged(at, pattern):
                    changes += [(at, var, pattern >> i & 1)
                                for i, var in enumerate(self.outputs)]
        moves = not skip.steady and (skip.shift or not shapes.plain(skip.shape))
        if moves:
            changes += self._last_pass(skip)
        elif skip.steady and skip.shift:  # the stage follows the profile, planned from its
            final = skip.position + skip.passes * skip.shift  # start to the last target
            self.segments = self.planned._replace(target=final).segments()
            self.retarget = (skip.t_to, final)  # told once the samples reach it
        for t, var, value in sorted(changes, key=lambda change: change[0]):
            if skip.steady:  # the stage goes on along its profile through the passes
                self._sample(t)
                if self.cut_at is not None:  # the samples filled the file
                    return
            self.writer.change(var, t, value)
            self.last = max(self.last, t)
        if moves:  # a move running across the skip's end runs on as the copy of the one
            # before it (the machine moved its profile so: Axis.translate); its samples go
            # on after what the last pass wrote
            span, moved = skip.t_to - skip.t, skip.passes * skip.shift
            self.segments = tuple(seg.moved(span, moved) for seg in self.segments)
            self.sampled_to = max(skip.t_to, self.last)

    def _last_pass(self, skip: ev.FastForwarded) -> list:
        """The position in a shifted skip: where its passes start and, sampled, the moves of
        its last pass (copies of the stepped pass before the skip, `shift` further on)."""
        last = skip.t + (skip.passes - 1) * skip.period
        # where the stage is as the passes start: on its way (the skip's `position` is the
        # target it runs to), or at rest on it; rounded as a sample is, at each end (a
        # position half-way between counts rounds to the even one: not by `shift`)
        x = _position(self.segments, skip.t) if self.segments else skip.position
        at_last = round(x + (skip.passes - 1) * skip.shift)
        changes = [(skip.t, self.position, round(x)), (last, self.position, at_last)]
        dt, dx = (skip.passes - 1) * skip.period, (skip.passes - 1) * skip.shift
        for move in [m for m in self.moves if skip.t - skip.period <= m.t < skip.t]:
            changes.append((move.t + skip.period + dt, self.target, move.target + skip.shift + dx))
            segments = tuple(seg.moved(skip.period + dt, skip.shift + dx)
                             for seg in move.segments)
            if segments:
                end = min(int(segments[-1].t1), skip.t_to - 1)
                # from the copy's command on (a kept profile began before it: MoveStarted.kept)
                begin = max(int(segments[0].t0), move.t + skip.period + dt)
                changes += [(t, self.position, round(_position(segments, t)))
                            for t in range(begin, end, SAMPLE_US)]
                changes.append((end, self.position, round(_position(segments, end))))
        return changes

    def _sample(self, until: int) -> None:
        """Position samples of the running profile up to `until`, and the target a steady
        skip left where it left it."""
        if self.segments:
            end = min(until, int(self.segments[-1].t1) + 1)
            t = self.sampled_to
            while t < end:
                if self._full():
                    self._check_size(t)
                    return
                self._retargeted(t)
                self.writer.change(self.position, t, round(_position(self.segments, t)))
                t += SAMPLE_US
            self.sampled_to = t
        self._retargeted(until)

    def _retargeted(self, t: int) -> None:
        if self.retarget is not None and self.retarget[0] <= t:
            self.writer.change(self.target, *self.retarget)
            self.retarget = None

    def close(self, t_us: int) -> None:
        if self.cut_at is None:
            self._sample(t_us)
        if self.cut_at is None:
            self.writer.close(t_us)


def _position(segments: tuple, t: float) -> float:
    for seg in segments:
        if t < seg.t1:
            return seg.x(t)
    return segments[-1].x(segments[-1].t1)


class _Kept:
    """What a controller's VcdObserver writes to in a rig's dump: variables on the real
    writer, changes kept for the end."""

    def __init__(self, writer: VCDWriter, changes: list):
        self.writer, self.changes = writer, changes

    def register_var(self, *args, **kwargs):
        return self.writer.register_var(*args, **kwargs)

    def change(self, var, t: int, value) -> None:
        self.changes.append((t, len(self.changes), var, value))

    def close(self, t: int) -> None:
        pass


class Dump:
    """The dump of a run: `listeners()` per controller, then `close(end_us)`. One controller
    (a lone program) writes as it goes, with its scopes at the top (box, axis, vm); several
    write a scope each, in time order at the end."""

    def __init__(self, stream: IO[str], names: list[str], limit: int | None = None):
        self.limit = limit
        self.changes: list = []
        if len(names) == 1:
            self.out, self.writer = None, None
            self.observers = {names[0]: VcdObserver(stream, limit)}
            return
        self.out = _Counted(stream)
        self.writer = VCDWriter(self.out, timescale="1 us", date="", comment="mercmac sim (rig)")
        kept = _Kept(self.writer, self.changes)
        self.observers = {name: VcdObserver(None, writer=kept, scope=name) for name in names}
        self._cut_at: int | None = None

    @property
    def cut_at(self) -> int | None:
        """Where the dump stopped at its size limit (us); None: it holds the whole run."""
        if self.writer is None:
            (only,) = self.observers.values()
            return only.cut_at
        return self._cut_at

    def listeners(self) -> dict[str, list]:
        return {name: [o.on_event] for name, o in self.observers.items()}

    def close(self, end_us: int) -> None:
        for observer in self.observers.values():
            observer.close(end_us)  # samples each profile to the end
        if self.writer is None:
            return
        self.changes.sort(key=lambda c: (c[0], c[1]))
        for t, _, var, value in self.changes:
            if self.limit is not None and self.out.written + CLOSING > self.limit:
                self._cut_at = t
                break
            self.writer.change(var, t, value)
        self.writer.close(self._cut_at if self._cut_at is not None else end_us)
