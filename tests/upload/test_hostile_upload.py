"""Nothing hangs, nothing is lost, no traceback, against peers
that misbehave on purpose — a nan timeout, an endless TM listing, a flood of junk, a TCP
peer that hangs up mid-flash, and Ctrl-C at the worst moments."""
from __future__ import annotations

import os
import select
import signal
import socket
import subprocess
import sys
import threading
import time

import pytest

from helpers.cli import cli
from mercmac.emulator.virtual import Faults, VirtualController
from mercmac.upload.transport import Timing
from helpers.emulator import FAST, serve

PROGRAM = "target C-863\n[MC00] EM5\n[MC05] MR5000,WS100\n[MC06] XN1,MR-10\n[MC07] TP\n"
END = b"\r\n\x03"  # MS176E §6.1.3: every report ends CR LF ETX
VERSION = b"(c)2009 Physik Instrumente(PI) Karlsruhe, C-863, Ver. 2.30, 2009-21-07" + END
STATUS = b"S:00 00 00 00 00 00" + END
BOUND_S = 10  # every hostile run below must be over well before this
# the answer timeout where an endless reply is tested, not the timeout: room for a loaded
# machine to run the peer's thread (0.3 s once failed), within BOUND_S with the budget
PEER_TIMEOUT = ("--timeout", "2")


def mercmac(*args):
    """Run a command in-process; exceptions are kept, so a traceback shows as one."""
    return cli(*args, catch=True)


def no_traceback(result) -> bool:
    return result.exception is None or isinstance(result.exception, SystemExit)


# -- a misbehaving controller on socket://127.0.0.1 -----------------------------

class Peer:
    """A fake controller over TCP: `answer(line)` gives bytes, or an iterator of bytes
    that is streamed until the host hangs up (a flood). Lives at most `lifetime` s."""

    def __init__(self, answer, lifetime: float = 30.0):
        self.answer, self.lifetime = answer, lifetime
        self._listener = socket.create_server(("127.0.0.1", 0))
        self.url = f"socket://127.0.0.1:{self._listener.getsockname()[1]}"
        threading.Thread(target=self._serve, daemon=True).start()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self._listener.close()

    def _serve(self) -> None:
        end = time.monotonic() + self.lifetime
        conn, _ = self._listener.accept()
        with conn:
            line, after_select = b"", False
            while time.monotonic() < end:
                if not select.select([conn], [], [], 0.01)[0]:
                    continue
                data = conn.recv(4096)
                if not data:
                    return
                for byte in data:
                    if after_select:  # the address character after 0x01
                        after_select = False
                    elif byte == 0x01:
                        after_select = True
                    elif byte == ord("%") and not line:
                        self._reply(conn, self.answer("%"), end)
                    elif byte == 0x0D:
                        self._reply(conn, self.answer(line.decode()), end)
                        line = b""
                    else:
                        line += bytes([byte])

    def _reply(self, conn, out, end) -> None:
        chunks = [out] if isinstance(out, bytes) else (out or [])
        try:
            for chunk in chunks:
                conn.sendall(chunk)
                if time.monotonic() > end:
                    return
        except OSError:  # the host hung up: the flood is over
            pass


def mercury(line: str):
    """What a well-behaved, empty C-863 answers."""
    return {"%": STATUS, "VE": VERSION, "TM": END, "TZ": END}.get(line)


def forever(chunk: bytes, pace: float = 0.0):
    while True:
        yield chunk
        if pace:
            time.sleep(pace)


def with_tm(tm):
    return lambda line: tm() if line == "TM" else mercury(line)


def timed(fn):
    started = time.monotonic()
    result = fn()
    return result, time.monotonic() - started


# -- item 4: --timeout nan --------------------------------------------------------

@pytest.mark.parametrize("value", ["nan", "inf", "-inf", "NaN", "infinity"])
@pytest.mark.parametrize("command", ["flash", "pull", "scan"])
def test_timeout_refuses_nan_and_inf(command, value, program_file):
    args = [command, "/dev/does-not-exist-mercmac"]
    if command == "flash":
        args.append(program_file)
    result = mercmac(*args, "--timeout", value)
    assert result.exit_code == 2, result.output
    assert "not a finite number" in result.output and "--timeout" in result.output


def test_timeout_range_still_checked(program_file):
    result = mercmac("scan", "/dev/does-not-exist-mercmac", "--timeout", "0.001")
    assert result.exit_code == 2 and "at least 0.05" in result.output


@pytest.mark.parametrize("value", [float("nan"), float("inf"), 0.0, -1.0])
def test_a_timing_that_never_expires_is_refused(value):
    with pytest.raises(ValueError):
        Timing(timeout=value)


# -- item 5: endless listings and floods ------------------------------------------

ENDLESS_TM = {  # what TM answers, made afresh for each request
    "fast": lambda: forever(b"MC001 MR1" + END),
    "paced": lambda: forever(b"MC001 MR1" + END, pace=0.05),  # never quiet for `settle`
    "cycling": lambda: (b"MC%03d MR1" % (1 + i % 31) + END for i in range(10 ** 9)),
    "one-report": lambda: b"MC001 MR1\r\n" * 200 + b"\x03",
    "no-etx": lambda: forever(b"MC001 MR1\r\n"),
}


@pytest.mark.slow
@pytest.mark.parametrize("kind", ENDLESS_TM)
def test_an_endless_tm_listing_ends_pull_with_what_came(kind):
    with Peer(with_tm(ENDLESS_TM[kind])) as peer:
        result, took = timed(lambda: mercmac("pull", peer.url, *PEER_TIMEOUT, "--baud", "115200"))
    assert took < BOUND_S, f"pull took {took:.1f} s"
    assert result.exit_code == 1 and no_traceback(result), result.output
    assert "TM" in result.output and "'MC0" in result.output  # quotes what came


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["fast", "paced", "one-report"])
def test_an_endless_tm_listing_refuses_the_flash_before_any_write(kind, program_file, tmp_path):
    backup = tmp_path / "b.mcm"
    with Peer(with_tm(ENDLESS_TM[kind])) as peer:
        result, took = timed(lambda: mercmac("flash", peer.url, program_file, "--backup", backup,
                                             *PEER_TIMEOUT))
    assert took < BOUND_S, f"flash took {took:.1f} s"
    assert result.exit_code == 1 and no_traceback(result), result.output
    assert "nothing was written" in result.output and "'MC001 MR1" in result.output
    assert not backup.exists()


def test_a_long_tm_listing_of_31_macros_is_still_read(tmp_path):
    macros = {slot: f"MR{slot}" for slot in range(0, 32)}
    with serve(macros=macros) as (server, vc):
        result = mercmac("pull", server.path, *FAST)
    assert result.exit_code == 0, result.output
    assert "read 32 macros" in result.output


JUNK = {
    "reports": lambda: forever(b"\x7f\x13junk\xfe" + END),
    "paced": lambda: forever(b"\x7f\x13junk\xfe" + END, pace=0.04),
    "no-etx": lambda: forever(b"\x7f\x13junk\xfe"),
}


@pytest.mark.slow
@pytest.mark.parametrize("kind", JUNK)
def test_a_flood_of_junk_ends_the_scan_quickly_and_quotes_it(kind):
    with Peer(lambda line: JUNK[kind]() if line == "%" else None) as peer:
        result, took = timed(lambda: mercmac("scan", peer.url, *PEER_TIMEOUT,
                                             "--baud", "115200"))
    assert took < BOUND_S, f"scan took {took:.1f} s"
    assert result.exit_code == 1 and no_traceback(result), result.output
    assert "junk" in result.output and "scan stopped" in result.output
    assert "no controller answered like a Mercury" in result.output


def test_a_flood_after_identifying_ends_the_flash_before_any_write(program_file, tmp_path):
    flood = with_tm(lambda: forever(b"S:00 00 00 00 00 00" + END))  # never the answer asked for
    with Peer(flood) as peer:
        result, took = timed(lambda: mercmac("flash", peer.url, program_file, "--backup",
                                             tmp_path / "b.mcm", "--timeout", "0.3"))
    assert took < BOUND_S
    assert result.exit_code == 1 and "nothing was written" in result.output
    assert "'S:00 00 00 00 00 00" in result.output


# -- item 12: a TCP peer that hangs up mid-flash ------------------------------------

class Bridge:
    """The virtual controller on TCP, hanging up once the host has sent `cut` bytes."""

    def __init__(self, cut: int, reset: bool):
        self.vc = VirtualController(macros={0: "EM1", 5: "GH", 9: "TP"})
        self.cut, self.reset, self.received = cut, reset, 0
        self._listener = socket.create_server(("127.0.0.1", 0))
        self.url = f"socket://127.0.0.1:{self._listener.getsockname()[1]}"
        threading.Thread(target=self._serve, daemon=True).start()

    def _serve(self) -> None:
        conn, _ = self._listener.accept()
        t0 = time.monotonic()
        try:
            while True:
                ready = select.select([conn], [], [], 0.002)[0]
                data = conn.recv(4096) if ready else b""
                if ready and not data:
                    return
                data = data[:max(0, self.cut - self.received)]
                self.received += len(data)
                self.vc.receive(data, time.monotonic() - t0)
                if out := self.vc.take():
                    conn.sendall(out)
                if self.received >= self.cut:
                    return
        finally:
            if self.reset:  # RST instead of FIN: the host sees "connection reset"
                conn.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, b"\x01\x00\x00\x00\x00\x00\x00\x00")
            conn.close()
            self._listener.close()


@pytest.mark.slow
@pytest.mark.parametrize("cut", [1, 2, 3, 4, 6, 9, 12, 15, 20, 27, 35, 50, 70, 95])
def test_a_peer_hanging_up_mid_flash_gives_a_message_never_a_traceback(cut, program_file, tmp_path):
    for reset in (False, True):
        bridge = Bridge(cut, reset)
        result, took = timed(lambda: mercmac("flash", bridge.url, program_file, "--backup",
                                             tmp_path / f"b{cut}{reset}.mcm", "--timeout", "0.3"))
        assert no_traceback(result), f"cut at {cut}: {result.exception!r}\n{result.output}"
        assert took < BOUND_S
        assert result.exit_code in (0, 1), result.output
        if result.exit_code:
            assert "mercmac: " in result.output
            assert "written" in result.output  # what was written, or that nothing was


@pytest.mark.parametrize("cut", [1, 2, 3, 5, 8])
def test_a_peer_hanging_up_mid_scan_gives_a_message(cut):
    bridge = Bridge(cut, reset=False)
    result = mercmac("scan", bridge.url, "--timeout", "0.1")
    assert no_traceback(result), f"cut at {cut}: {result.exception!r}\n{result.output}"
    assert result.exit_code == 1 and "mercmac: scan stopped" in result.output


# -- item 12: Ctrl-C once the flash is complete, and a second Ctrl-C ----------------

def test_ctrl_c_while_the_final_table_prints_says_the_flash_succeeded(program_file, tmp_path,
                                                                     monkeypatch):
    from mercmac.render import upload as view

    def interrupted(*args):
        raise KeyboardInterrupt

    monkeypatch.setattr(view, "flash_summary", interrupted)
    with serve(macros={0: "EM1"}) as (server, vc):
        result = mercmac("flash", server.path, program_file, "--backup", tmp_path / "b.mcm",
                         *FAST)
    assert result.exit_code == 130 and no_traceback(result), result.output
    assert "flashed and verified: 4 written" in result.output
    assert f"backup: {tmp_path / 'b.mcm'}" in result.output
    assert vc.macros[7] == "TP"


def test_ctrl_c_while_the_progress_bar_closes_says_the_flash_succeeded(program_file, tmp_path,
                                                                      monkeypatch):
    from mercmac.render import upload as view

    def interrupted(self, *exc):
        raise KeyboardInterrupt

    monkeypatch.setattr(view.FlashProgress, "__exit__", interrupted)
    with serve() as (server, vc):
        result = mercmac("flash", server.path, program_file, "--backup", tmp_path / "b.mcm",
                         *FAST)
    assert result.exit_code == 130, result.output
    assert "the flash had finished: flashed and verified" in result.output


@pytest.mark.skipif(not hasattr(os, "openpty"), reason="needs pseudo-terminals")
@pytest.mark.parametrize("gap", [0.0, 0.003, 0.01, 0.03])
def test_a_second_ctrl_c_exits_cleanly_with_the_same_message(gap, program_file, tmp_path):
    backup = tmp_path / "b.mcm"
    env = dict(os.environ, FORCE_COLOR="1")  # the rich progress bar, as on a terminal
    with serve(macros={0: "EM1", 1: "TP"}, faults=Faults(md_delay=0.2)) as (server, vc):
        proc = subprocess.Popen([sys.executable, "-m", "mercmac", "flash", server.path,
                                 str(program_file), "--backup", str(backup), *FAST],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
        end = time.monotonic() + 10
        while server.call(lambda _c: vc.md_count) < 1 and time.monotonic() < end:
            time.sleep(0.005)
        proc.send_signal(signal.SIGINT)
        time.sleep(gap)
        if proc.poll() is None:
            proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=10)
    assert proc.returncode == 130, err
    assert "Exception ignored" not in err and "Traceback" not in err
    assert "flash stopped: interrupted (Ctrl-C)" in err and str(backup) in err
