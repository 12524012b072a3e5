"""The virtual controller on a real pseudo-terminal, and how tests talk to it."""
from __future__ import annotations

import time
import types
from contextlib import contextmanager

import serial

from mercmac.emulator.ptyserver import PtyServer
from mercmac.emulator.virtual import Faults, VirtualController
from mercmac.upload import controller as controller_module, transport as transport_module
from mercmac.upload.connect import open_controller
from mercmac.upload.transport import Timing

# The answer timeout of the tests' exchanges, FAST_TIMING for the library and FAST for the
# command line (`--timeout`): seconds of room, as the timeout is not what these tests test;
# on a loaded machine the emulator's thread or a mercmac process may wait a second for a
# core (issue 26: 0.3 s failed at load 10). A test that waits out a silence (nothing at an
# address, a silent controller) does so on a LineClock (below), in milliseconds. The settle
# time stays short: a TM listing comes in one write of the emulator.
FAST_TIMING = Timing(timeout=5.0, settle=0.05)
FAST = ("--timeout", str(FAST_TIMING.timeout))


@contextmanager
def serve(**kw):
    """A virtual controller on a pty: yields (server, controller)."""
    faults = kw.pop("faults", None) or Faults()
    vc = VirtualController(faults=faults, **kw)
    with PtyServer(vc) as server:
        yield server, vc


@contextmanager
def connect(server, address: int = 0, timing: Timing = FAST_TIMING):
    with open_controller(server.path, address, timing=timing) as c:
        yield c


@contextmanager
def raw_port(server):
    """pyserial straight on the pty, for byte-level checks."""
    port = serial.serial_for_url(server.path, baudrate=9600, timeout=0.3)
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


def eventually(server, check, seconds: float = 1.0) -> bool:
    """Whether check(controller) becomes true: the emulator reads bytes in its own thread."""
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if server.call(check):
            return True
        time.sleep(0.005)
    return False


def read_for(port, seconds: float = 0.15) -> bytes:
    end, data = time.monotonic() + seconds, b""
    while time.monotonic() < end:
        data += port.read(port.in_waiting or 1)
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
def basil_mercury(path: str, write_termination: str):
    """basil-daq's Dut with its Mercury driver on PATH over its pyserial transport, inited:
    it probes boards 0-15 with two TBs each and reads one answer (skipped without basil)."""
    import pytest

    dut_module = pytest.importorskip("basil.dut", reason="basil-daq is not installed "
                                     "(pip install '.[test]' installs it)")
    conf = {"transfer_layer": [{"name": "Serial", "type": "Serial", "init": {
                "port": path, "baudrate": 9600, "timeout": 0.05,
                "read_termination": "\x03", "write_termination": write_termination}}],
            "hw_drivers": [{"name": "Mercury", "type": "mercury", "interface": "Serial"}]}
    dut = dut_module.Dut(conf)
    dut.init()
    try:
        yield dut
    finally:
        dut.close()
