"""Serving virtual controllers on a pseudo-terminal: the path opens like a serial port.

POSIX only (os.openpty). The server keeps its own handle on the terminal
side open, so hosts may open and close the path as often as they like, and
a `vanish` fault closes both ends to look like a pulled USB cable. With a
log, every byte both ways goes to it as it passes, timestamped. What is served is a chain
(chain.py): one controller is a chain of one; on a chain of several each line of the log also
says which controller was selected or answered.
"""
from __future__ import annotations

import logging
import os
import select
import threading
import time
import tty
from typing import IO, Callable

from mercmac.emulator.chain import Chain
from mercmac.outfile import reason
from mercmac.upload.protocol import show

TICK_S = 0.002  # how often running macros advance when no bytes arrive
log = logging.getLogger(__name__)


class PtyServer:
    """A Chain of virtual controllers (one, or several) behind a pty; `path` is what to give
    `mercmac flash`."""

    def __init__(self, chain: Chain, log: IO[str] | None = None,
                 clock: Callable[[], float] = time.monotonic):
        if not hasattr(os, "openpty"):
            raise OSError("pseudo-terminals need a POSIX system (Linux, macOS)")
        self.chain = chain
        self._master, self._slave = os.openpty()
        tty.setraw(self._slave)  # no echo, no CR->LF translation: bytes pass unchanged
        os.set_blocking(self._master, False)  # a host that stops reading must not stall us
        self.path = os.ttyname(self._slave)
        self._stop = threading.Event()
        self._lock = threading.Lock()
        self._busy = False  # a turn runs: from before its read to after its send (served())
        self._thread: threading.Thread | None = None
        self._clock = clock  # the controller's time: a test may hold it (typing speed tests)
        self._t0 = clock()
        self._failures: set[str] = set()  # logged once each, however often they recur
        self._log = log  # `mercmac emulate --log`: the caller opens and closes it
        self._note(f"# {time.strftime('%Y-%m-%d %H:%M:%S %z')} {self._what()} on "
                   f"{self.path}; seconds since then, -> host to controller, <- back")

    def __enter__(self) -> "PtyServer":
        self.start()
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def start(self) -> None:
        """Serve in a background thread (tests); `serve_forever` serves in this one."""
        self._thread = threading.Thread(target=self.serve_forever, name="mercmac-emulator",
                                        daemon=True)
        self._thread.start()

    def serve_forever(self) -> None:
        # The fds are closed by this thread only (here, or by close() once it has ended):
        # closed under a running select or read, they would be None or another file's.
        try:
            while not self._stop.is_set():
                if self._turn():
                    break
        finally:
            if self._thread is None or self._thread is threading.current_thread():
                self._close_fds()

    def _turn(self) -> bool:
        """Read what the host sent, serve it, send the answer; whether the port vanished."""
        ready, _, _ = select.select([self._master], [], [], TICK_S)
        self._busy = True  # before the read, until the answer is sent: see served()
        now = self._clock() - self._t0
        data = self._read() if ready else b""
        with self._lock:
            out, vanished = self._serve(data, now)
        if data:
            self._record(now, "->", data, self._selection())
        if out:
            self._send(out, self._clock() - self._t0)
        self._busy = False
        return vanished

    def _serve(self, data: bytes, now: float) -> tuple[bytes, bool]:
        """One turn of the controller; a bug in it is logged, and serving goes on."""
        try:
            if data:
                self.chain.receive(data, now)
            self.chain.tick(now)
            return self.chain.take(), self.chain.vanished
        except Exception as e:  # noqa: BLE001 - an emulator that dies loses every macro
            message = f"emulator: {type(e).__name__}: {e}; still serving"
            if message not in self._failures:
                self._failures.add(message)
                log.error(message, exc_info=log.isEnabledFor(logging.DEBUG))
            return b"", False

    def call(self, fn):
        """Run `fn(chain)` between bytes, e.g. to press a button from a test."""
        with self._lock:
            return fn(self.chain)

    def close(self) -> None:
        """Stop serving; the serving thread closes the pty as it ends (never under its feet)."""
        self._stop.set()
        if self._thread is None:
            self._close_fds()
        elif self._thread is not threading.current_thread():
            self._thread.join()  # one turn: at most TICK_S in select, then out

    def idle(self) -> bool:
        """Whether nothing is in flight on the line: every byte the host sent is served and
        every answer is read. A test's clock runs only then (tests/helpers/emulator.py)."""
        slave = self._slave
        try:
            return self.served() and (slave is None or not _readable(slave))
        except (OSError, ValueError):  # closed meanwhile: the line is gone, nothing in flight
            return True

    def served(self) -> bool:
        """Whether every byte the host sent has been read and answered (idle() says more):
        none waits in the pty, in a turn of this server, or in a controller busy with a line."""
        # Checked in the order a byte goes: the master's queue, a turn (_busy is set before
        # the read), a controller's input (filled in that turn), the turn that takes it from
        # there and sends the answer (_busy again, cleared after the send). Each stage
        # overlaps the next, so checks in this order cannot all miss a byte on its way.
        # select, not FIONREAD: a pty passes bytes on in a kernel worker, which poll() waits
        # for and FIONREAD does not.
        if not self.received():
            return False
        with self._lock:
            if any(c.waiting for c in self.chain.controllers):
                return False
        return not self._busy

    def received(self) -> bool:
        """Whether every byte the host sent has been handed to the controllers (served()
        says whether they have read it)."""
        master = self._master
        try:
            return master is None or not (_readable(master) or self._busy)
        except (OSError, ValueError):
            return True

    def _what(self) -> str:
        """The header's words for what is served: a controller, or a chain by address."""
        cs = self.chain.controllers
        if len(cs) == 1:
            return f"virtual {cs[0].model}"
        return "virtual chain of " + ", ".join(
            f"{c.model} at {self.chain.label(c.address)}" for c in cs)

    def _selection(self) -> str:
        """After bytes from the host, which controller of a chain takes the next ones."""
        if len(self.chain.controllers) == 1:
            return ""
        chosen = [self.chain.label(c.address) for c in self.chain.selected()]
        return f"  [selected: {', '.join(chosen) or 'none'}]"

    def _speakers(self, data: bytes) -> list[tuple[bytes, str]]:
        """The reply, and on a chain each controller's part of it with its name."""
        if len(self.chain.controllers) == 1:
            return [(data, "")]
        return [(part, f"  [from {self.chain.label(a)}]") for a, part in self.chain.parts]

    def _record(self, now: float, way: str, data: bytes, who: str = "") -> None:
        """One line of the log: time, direction, the bytes in hex and as text (<CR>, <ETX>),
        and on a chain which controller was selected or answered."""
        self._note(f"{now:12.6f} {way} {data.hex(' ')}  {show(data)}{who}")

    def _note(self, line: str) -> None:
        if self._log is None:
            return
        try:
            self._log.write(line + "\n")  # line-buffered: a `tail -f` sees each at once
        except (OSError, ValueError) as e:  # disk full, file closed: serving goes on
            log.error("emulator: the log stopped (%s); still serving", reason(e))
            self._log = None

    def _read(self) -> bytes:
        # _master is open here: only the serving thread closes it (serve_forever)
        try:
            return os.read(self._master, 4096)
        except OSError:
            return b""

    def _send(self, data: bytes, now: float) -> None:
        # logged first: a host (or Ctrl-C) that acts on the reply at once finds it in the log
        for part, who in self._speakers(data):
            self._record(now, "<-", part, who)
        if len(self.chain.parts) > 1:  # §3.2: only the selected one talks; a real bus garbles
            self._note(f"{now:12.6f} <- several controllers answered at once: a collision "
                       "on a real chain (SC in macro 0 of networked controllers, §3.1.2?)")
        sent = self._write(data)
        if sent < len(data):
            self._note(f"{now:12.6f} <- the last {len(data) - sent} of these bytes were lost: "
                       "the host does not read")

    def _write(self, data: bytes) -> int:
        """How many bytes went out; the rest is lost, as on a real wire."""
        try:
            return os.write(self._master, data)
        except OSError:
            return 0  # buffer full or nobody listening

    def _close_fds(self) -> None:
        for name in ("_master", "_slave"):
            fd = getattr(self, name)
            if fd is not None:
                try:
                    os.close(fd)
                except OSError:
                    pass
                setattr(self, name, None)


def _readable(fd: int) -> bool:
    """Whether fd has bytes to read, without reading them."""
    return bool(select.select([fd], [], [], 0)[0])
