"""The virtual controller on a real pseudo-terminal, and how tests talk to it."""
from __future__ import annotations

import time
import types
from contextlib import contextmanager

import serial

from mercmac.emulator.chain import Chain
from mercmac.emulator.ptyserver import PtyServer
from mercmac.emulator.virtual import Faults, VirtualController
from mercmac.upload import controller as controller_module, transport as transport_module
from mercmac.upload.connect import identify, open_controller
from mercmac.upload.flasher import FlashOptions, flash
from mercmac.upload.transport import Timing

# The answer timeout of the tests' exchanges, FAST_TIMING for the library and FAST for the
# command line (`--timeout`): seconds of room, as the timeout is not what these tests test;
# on a loaded machine the emulator's thread or a mercmac process may wait a second for a
# core (0.3 s once failed at load 10). A test that waits out a silence (nothing at an
# address, a silent controller) does so on a LineClock (below), in milliseconds. The settle
# time stays short: a TM listing comes in one write of the emulator.
FAST_TIMING = Timing(timeout=5.0, settle=0.05)
FAST = ("--timeout", str(FAST_TIMING.timeout))
# For a mercmac process that looks for controllers (pull --rig, flash without --address): a
# given --timeout is also the wait at each of the 16 addresses, most of them empty, and a
# process cannot run on a LineClock: 1.5 s, five times the default search wait.
SEARCHING = ("--timeout", "1.5")
ROOM_S = 20.0  # how long an event that comes at once on a quiet machine may take under load


@contextmanager
def serve(clock=time.monotonic, **kw):
    """A virtual controller (a chain of one) on a pty: yields (server, controller); `clock` is
    its time."""
    faults = kw.pop("faults", None) or Faults()
    vc = VirtualController(faults=faults, **kw)
    with PtyServer(Chain([vc]), clock=clock) as server:
        yield server, vc


@contextmanager
def serve_clocked(**kw):
    """serve, with mercmac's timeouts in this process on the line's clock (line_clock): for a
    controller that answers at once or never (no md_delay), where silences are waited out."""
    with serve(**kw) as (server, vc), line_clock(server):
        yield server, vc


class HeldClock:
    """The emulator's time as the test moves it (`advance`), until `release`d to run on as
    real time: a typing-speed test types at the gaps it names, however loaded the machine."""

    def __init__(self):
        self._now, self._since = 0.0, None

    def __call__(self) -> float:
        if self._since is None:
            return self._now
        return self._now + time.monotonic() - self._since

    def advance(self, seconds: float) -> None:
        self._now += seconds

    def release(self) -> None:
        self._since = time.monotonic()


def typed(server: PtyServer, port, text: bytes, clock: HeldClock, gap: float) -> None:
    """TEXT written a byte at a time, `gap` seconds of CLOCK apart, each taken by the server
    before the next; the clock runs on `gap` after the last byte too."""
    for byte in text:
        port.write(bytes([byte]))
        assert until(server.received), "the emulator never took the byte"
        clock.advance(gap)


def until(condition, seconds: float = ROOM_S) -> bool:
    """Whether CONDITION() becomes true, as soon as it is; `seconds` only guards a hang."""
    end = time.monotonic() + seconds
    while not condition():
        if time.monotonic() >= end:
            return False
        time.sleep(0.005)
    return True


@contextmanager
def connect(server, address: int = 0, timing: Timing = FAST_TIMING):
    with open_controller(server.path, address, timing=timing) as c:
        yield c


def run_flash(server, program, tmp_path, address=0, **options):
    """Flash `program` through the library at `address` (backup in tmp_path unless given):
    (the flash's result, the transport that carried it)."""
    with connect(server, address) as c:
        who = identify(c)
        options.setdefault("backup", tmp_path / "backup.mcm")
        result = flash(c, who, program, FlashOptions(**options))
        return result, c.transport


@contextmanager
def raw_port(server):
    """pyserial straight on the pty, for byte-level checks; read_for knows its server."""
    port = serial.serial_for_url(server.path, baudrate=9600, timeout=0.3)
    port.mercmac_server = server
    try:
        yield port
    finally:
        port.close()


class LineClock:
    """A clock the test controls for the host side of `server`: it stands still while bytes
    are in flight (the emulator has not served what the host sent, or the host has not read
    the answer) and runs `speed` times real time while the line is idle. A timeout then
    expires only on a silence, never on a slow machine, and a silence of seconds passes in
    milliseconds. Only for controllers that answer at once (no md_delay, no running macro
    that reports later)."""

    def __init__(self, server: PtyServer, speed: float = 100.0):
        self._server, self._speed = server, speed
        self._now, self._last = 0.0, time.monotonic()

    def monotonic(self) -> float:
        real = time.monotonic()
        if self._server.idle():  # after the host's read: an answer that came since is seen
            self._now += (real - self._last) * self._speed
        self._last = real
        return self._now


@contextmanager
def line_clock(server: PtyServer, speed: float = 100.0):
    """mercmac's serial timeouts (transport, controller) on a LineClock of `server` inside;
    for hosts in this process (helpers.cli.cli, the library), not a mercmac process."""
    fake = types.SimpleNamespace(monotonic=LineClock(server, speed).monotonic)
    modules = (transport_module, controller_module)
    saved = [m.time for m in modules]
    for module in modules:
        module.time = fake
    try:
        yield
    finally:
        for module, real in zip(modules, saved):
            module.time = real


def timeouts(monkeypatch) -> list[str]:
    """The reads of mercmac's transport that wait out a silence from now on in this process,
    each as its message, whatever the machine's speed (not the quiet `settle` that ends
    every TM listing)."""
    seen: list[str] = []
    read_report = transport_module.Transport.read_report

    def counted(self, timeout=None, deadline=None):
        try:
            return read_report(self, timeout, deadline)
        except transport_module.ReadTimeout as e:
            if timeout != self.timing.settle:
                seen.append(str(e))
            raise
    monkeypatch.setattr(transport_module.Transport, "read_report", counted)
    return seen


def eventually(server, check, seconds: float = ROOM_S) -> bool:
    """Whether check(chain) becomes true: the emulator reads bytes in its own thread."""
    return until(lambda: server.call(check), seconds)


def read_for(port, seconds: float = 0.15) -> bytes:
    """What comes in `seconds`, and after them until the line is idle (a raw_port's server
    has served every byte sent and every answer is read): a slow machine delays an answer,
    never cuts it off. A running macro's reports that have not come by then are not read."""
    server = getattr(port, "mercmac_server", None)
    end, data = time.monotonic() + seconds, b""
    while True:
        data += port.read(port.in_waiting or 1)
        now = time.monotonic()
        if now >= end and (server is None or server.idle() or now >= end + ROOM_S):
            return data


@contextmanager
def emulating(*args: str):
    """`mercmac emulate ARGS` as a process: yields (its first line, the pty path); Ctrl-C ends it."""
    import signal
    import subprocess
    import sys

    proc = subprocess.Popen([sys.executable, "-m", "mercmac", "emulate", *args],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        first = proc.stdout.readline()
        assert first, proc.stderr.read()
        yield first, proc.stdout.readline().strip()
    finally:
        proc.send_signal(signal.SIGINT)
        assert proc.wait(timeout=5) == 130  # Ctrl-C, as `scan` and `sim --interactive`


@contextmanager
def basil_mercury(server: PtyServer, write_termination: str):
    """basil-daq's Dut with its Mercury driver on SERVER's path over its pyserial transport,
    inited: it probes boards 0-15 with two TBs each and reads one answer (skipped without
    basil). Its reads end a silence when the line is idle (hears_silence), not after a
    timeout: basil's own 0.05 s cut answers off under load, and seconds for each of the
    silent boards would make the probe slow."""
    import pytest

    dut_module = pytest.importorskip("basil.dut", reason="basil-daq is not installed "
                                     "(pip install '.[test]' installs it)")
    conf = {"transfer_layer": [{"name": "Serial", "type": "Serial", "init": {
                "port": server.path, "baudrate": 9600, "timeout": SLICE_S,
                "read_termination": "\x03", "write_termination": write_termination}}],
            "hw_drivers": [{"name": "Mercury", "type": "mercury", "interface": "Serial"}]}
    dut = dut_module.Dut(conf)
    serial_layer = dut["Serial"]
    opened = serial_layer.init  # opens its pyserial port, before the driver's probe

    def init() -> None:
        opened()
        hears_silence(serial_layer._port, server)
    serial_layer.init = init
    dut.init()
    try:
        yield dut
    finally:
        dut.close()


SLICE_S = 0.02  # one pyserial read of a host that hears_silence


def hears_silence(port, server: PtyServer) -> None:
    """PORT's reads (pyserial, timeout SLICE_S) wait while bytes are in flight to or from
    SERVER and return empty once the line is idle: a silence, whatever the machine's speed."""
    read = port.read

    def read_until_idle(size: int = 1) -> bytes:
        while True:
            data = read(size)
            if data or server.idle():  # idle after the read: an answer since is not lost
                return data
    port.read = read_until_idle


def drain(port) -> bytes:
    """Every answer still on its way to a port that hears_silence, read."""
    data = b""
    while chunk := port.read(4096):
        data += chunk
    return data
