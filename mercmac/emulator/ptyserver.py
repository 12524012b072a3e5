"""Serving a virtual controller on a pseudo-terminal: the path opens like a serial port.

POSIX only (os.openpty). The server keeps its own handle on the terminal
side open, so hosts may open and close the path as often as they like, and
a `vanish` fault closes both ends to look like a pulled USB cable.
"""
from __future__ import annotations

import logging
import os
import select
import threading
import time
import tty

from mercmac.emulator.virtual import VirtualController

TICK_S = 0.002  # how often running macros advance when no bytes arrive
log = logging.getLogger(__name__)


class PtyServer:
    """A VirtualController behind a pty; `path` is what to give `mercmac flash`."""

    def __init__(self, controller: VirtualController):
        if not hasattr(os, "openpty"):
            raise OSError("pseudo-terminals need a POSIX system (Linux, macOS)")
        self.controller = controller
        self._master, self._slave = os.openpty()
        tty.setraw(self._slave)  # no echo, no CR->LF translation: bytes pass unchanged
        os.set_blocking(self._master, False)  # a host that stops reading must not stall us
        self.path = os.ttyname(self._slave)
        self._stop = threading.Event()
        self._lock = threading.Lock()
        self._thread: threading.Thread | None = None
        self._t0 = time.monotonic()
        self._failures: set[str] = set()  # logged once each, however often they recur

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
        while not self._stop.is_set() and self._master is not None:
            ready, _, _ = select.select([self._master], [], [], TICK_S)
            now = time.monotonic() - self._t0
            data = self._read() if ready else b""
            with self._lock:
                out, vanished = self._serve(data, now)
            if out:
                self._write(out)
            if vanished:
                self._close_fds()
                return

    def _serve(self, data: bytes, now: float) -> tuple[bytes, bool]:
        """One turn of the controller; a bug in it is logged, and serving goes on."""
        try:
            if data:
                self.controller.receive(data, now)
            self.controller.tick(now)
            return self.controller.take(), self.controller.vanished
        except Exception as e:  # noqa: BLE001 - an emulator that dies loses every macro
            message = f"emulator: {type(e).__name__}: {e}; still serving"
            if message not in self._failures:
                self._failures.add(message)
                log.error(message, exc_info=log.isEnabledFor(logging.DEBUG))
            return b"", False

    def call(self, fn):
        """Run `fn(controller)` between bytes, e.g. to press a button from a test."""
        with self._lock:
            return fn(self.controller)

    def close(self) -> None:
        self._stop.set()
        if self._thread and self._thread is not threading.current_thread():
            self._thread.join(timeout=2)
        self._close_fds()

    def _read(self) -> bytes:
        try:
            return os.read(self._master, 4096)
        except OSError:
            return b""

    def _write(self, data: bytes) -> None:
        try:
            os.write(self._master, data)
        except OSError:
            pass  # buffer full or nobody listening: bytes are lost, as on a real wire

    def _close_fds(self) -> None:
        for name in ("_master", "_slave"):
            fd = getattr(self, name)
            if fd is not None:
                try:
                    os.close(fd)
                except OSError:
                    pass
                setattr(self, name, None)
