"""A serial link with a timeout on every read: pyserial under, reports on top.

Anything `serial.serial_for_url` opens works: COM3, /dev/ttyUSB0, a pty
path, socket://host:port. The port is opened exclusively so that a terminal
program left open cannot interleave its bytes with an upload.
"""
from __future__ import annotations

import math
import time
from contextlib import contextmanager
from dataclasses import dataclass, replace
from typing import Callable, Iterator

from mercmac.errors import held_signals
from mercmac.upload.protocol import ProtocolError, ReportSplitter

DEFAULT_BAUD = 9600  # MS176E §3.3: MMCRun's rate, DIP switches 5 and 6 ON
POLL_S = 0.02  # how long one pyserial read may block; bounds the reaction to Ctrl-C
LONGEST_REPLY = 4096  # bytes: a TM listing of 31 full macros stays under this
SEARCH_TIMEOUT = 0.3  # s: the wait at each address when looking for controllers, unless told


class TransportError(Exception):
    """The port cannot be used: missing, busy, lost, or the controller is silent."""


class PortUnavailable(TransportError):
    """Opening the port failed."""


class PortLost(TransportError):
    """The port went away while in use (USB cable pulled, adapter reset)."""


class ReadTimeout(TransportError):
    """No complete report came in time; `partial` holds what did come, `endless` is
    true when bytes kept coming (a flood without ETX) rather than falling silent."""

    def __init__(self, message: str, partial: str = "", endless: bool = False):
        super().__init__(message)
        self.partial, self.endless = partial, endless


@dataclass(frozen=True, slots=True)
class Timing:
    """Read timeouts in seconds: per report, the quiet time that ends a listing, and the
    wait at each address of a search (16 addresses, so short unless the user says)."""

    timeout: float = 1.0  # silence after which a reply is given up (flash writes take a while)
    settle: float = 0.25  # quiet time after an ETX that ends a multi-report TM listing
    search: float = SEARCH_TIMEOUT  # silence after which an address is taken for empty

    def __post_init__(self) -> None:
        # nan compares false with everything: a nan timeout would never expire
        for name in ("timeout", "settle", "search"):
            if not 0 < getattr(self, name) < math.inf:
                raise ValueError(f"{name} must be a positive number of seconds, "
                                 f"not {getattr(self, name)!r}")

    @classmethod
    def waiting(cls, timeout: float, *, searching_too: bool = False) -> "Timing":
        """The timing for a `--timeout` option: a listing settles within the reply timeout,
        and a search waits as long at each address when the user gave the timeout
        (`searching_too`: a slow link is slow at every address), else SEARCH_TIMEOUT at most."""
        search = timeout if searching_too else min(timeout, SEARCH_TIMEOUT)
        return cls(timeout=timeout, settle=min(0.25, timeout), search=search)

    def budget(self, baud: int, size: int = LONGEST_REPLY) -> float:
        """Longest time one exchange may take: a timeout plus `size` bytes at `baud`."""
        return self.timeout + size * 10 / max(baud, 300) + 2.0


class Transport:
    """One open serial port; counts bytes both ways (benchmarks/flash_bytes.py)."""

    def __init__(self, port: str, baud: int = DEFAULT_BAUD, timing: Timing = Timing(),
                 tap: Callable[[str, bytes], None] | None = None):
        self.port, self.baud, self.timing = port, baud, timing
        self.sent = self.received = 0
        self._tap = tap
        self._splitter = ReportSplitter()
        self._reports: list[str] = []
        self._serial = _open(port, baud)

    def __enter__(self) -> "Transport":
        return self

    @contextmanager
    def per_address(self) -> Iterator[None]:
        """Inside, each reply is waited for `timing.search` s: a search of addresses, most of
        them empty (scan in pull --rig, find_address)."""
        timing = self.timing
        self.timing = replace(timing, timeout=timing.search)
        try:
            yield
        finally:
            self.timing = timing

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        """Close the port whole: a signal waits until it is closed (errors.held_signals)."""
        with held_signals():
            try:
                self._serial.close()
            except Exception:  # closing a port that vanished must not hide the real error
                pass

    def write(self, data: bytes) -> None:
        """Send `data` in one write, waiting until it has left
        (docs/uploader.md, "The serial link")."""
        try:
            written = self._serial.write(data)
            self._serial.flush()
        except Exception as e:
            raise PortLost(f"writing to {self.port} failed: {_reason(e)}") from None
        if written is not None and written != len(data):
            raise PortLost(f"{self.port} took {written} of {len(data)} bytes")
        self.sent += len(data)
        if self._tap:
            self._tap("out", data)

    def discard_input(self) -> None:
        """Forget bytes that arrived unasked: stale reports of a running macro."""
        try:
            self._serial.reset_input_buffer()
            waiting = self._serial.in_waiting
            if waiting:
                self._take(self._serial.read(waiting))
        except Exception as e:
            raise PortLost(f"reading from {self.port} failed: {_reason(e)}") from None
        self._splitter.clear()
        self._reports.clear()

    def read_report(self, timeout: float | None = None, deadline: float | None = None) -> str:
        """The next report (text before ETX); ReadTimeout after `timeout` s of silence,
        or at `deadline` (time.monotonic) or the budget however many bytes still come."""
        limit = self.timing.timeout if timeout is None else timeout
        started = quiet_since = time.monotonic()
        hard_stop = min(started + self.timing.budget(self.baud), deadline or math.inf)
        came = False  # a byte in this read: only then can the hard stop mean a flood
        while True:
            if self._reports:
                return self._reports.pop(0)
            data = self._read_some()
            now = time.monotonic()
            if data:
                came, quiet_since = True, now
                try:
                    self._reports.extend(self._splitter.feed(data))
                except ProtocolError as e:
                    raise ReadTimeout(str(e), e.reply or "", endless=True) from None
                if self._reports:
                    continue
            if now - quiet_since >= limit:
                raise ReadTimeout(f"no complete reply within {limit:g} s", self._splitter.pending())
            # bytes kept coming: never an ETX, or reports the caller skips. Not after silence
            # alone: a process stalled past the stop (a loaded machine, a laptop's sleep) saw
            # nothing come, and that is the silence above, not a flood
            if came and now >= hard_stop:
                pending = self._splitter.pending()
                what = f"{now - started:.1f} s of bytes without an end of report (ETX)" if pending \
                    else "replies kept coming, none of them the answer"
                raise ReadTimeout(what, pending, endless=True)

    def _read_some(self) -> bytes:
        try:
            self._serial.timeout = POLL_S
            waiting = self._serial.in_waiting
            return self._take(self._serial.read(max(1, waiting)))
        except Exception as e:
            raise PortLost(f"reading from {self.port} failed: {_reason(e)}") from None

    def _take(self, data: bytes) -> bytes:
        self.received += len(data)
        if data and self._tap:
            self._tap("in", data)
        return data


def _open(port: str, baud: int):
    """The pyserial object for a port name or URL; PortUnavailable with the reason."""
    import serial

    try:
        # 8N1, no flow control: the Mercury defaults (MS176E §3.3, User Manual)
        return serial.serial_for_url(port, baudrate=baud, timeout=POLL_S, write_timeout=10,
                                     exclusive=True)
    except (serial.SerialException, OSError, ValueError) as e:
        raise PortUnavailable(f"cannot open {port}: {_reason(e)}") from None


def _reason(e: BaseException) -> str:
    """pyserial's message, shortened: 'No such file or directory', 'port is locked by ...'."""
    text = str(e).strip()
    if "exclusively lock" in text:
        return "the port is locked by another program"
    if "returned no data" in text:  # pyserial's words for a vanished USB adapter or pty
        return "the device disconnected"
    errno = getattr(e, "errno", None)
    if isinstance(errno, int) and errno > 0:
        import os

        return os.strerror(errno)
    from mercmac.outfile import reason

    return reason(e)  # words, never the tuple a termios.error prints as (5, 'Input/output error')
