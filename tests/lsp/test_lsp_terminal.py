"""How `mercmac lsp` starts and stops.

- vscode-languageclient 9 with `TransportKind.stdio` runs `mercmac lsp --stdio` (pygls
  servers and most others take the flag); `mercmac lsp` refused it ("No such option").
- Started by a person in a terminal it said nothing and seemed to hang; Ctrl-C was
  ignored once and then killed it with "Fatal Python error: _enter_buffered_busy"
  (exit 134). It now says what it is on stderr when stdin is a terminal, and the first
  Ctrl-C ends it with 130. The terminal is a real pseudo-terminal (pty); the server is
  started with Ctrl-C at its default even when this suite runs as a background job.
"""
from __future__ import annotations

import json
import os
import select
import signal
import subprocess
import sys
import time

import pytest

pytest.importorskip("pygls", reason="the lsp extra installs pygls")
from helpers.lsp_wire import INITIALIZE, Server, frame  # noqa: E402

WAIT_S = 30.0
SERVER = [sys.executable, "-m", "mercmac", "lsp"]


def _default_sigint() -> None:
    signal.signal(signal.SIGINT, signal.SIG_DFL)  # a background job's shell ignores it


def _answer(stdout, wait_s: float = WAIT_S) -> dict:
    """One LSP message read from `stdout` (a pipe), within `wait_s`."""
    data, end = b"", time.monotonic() + wait_s
    while b"\r\n\r\n" not in data or len(data) < data.index(b"\r\n\r\n") + 4 + int(
            data.split(b"Content-Length:")[1].split(b"\r\n")[0]):
        ready, _, _ = select.select([stdout], [], [], max(0.0, end - time.monotonic()))
        assert ready, f"no answer in {wait_s:.0f} s"
        chunk = os.read(stdout.fileno(), 65536)
        assert chunk, f"the server ended: {data!r}"
        data += chunk
    return json.loads(data[data.index(b"\r\n\r\n") + 4:])


def test_lsp_takes_stdio_as_vscode_languageclient_starts_it():
    process = subprocess.Popen([*SERVER, "--stdio"], stdin=subprocess.PIPE,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               preexec_fn=_default_sigint)
    try:
        process.stdin.write(frame(INITIALIZE))
        process.stdin.flush()
        answer = _answer(process.stdout)
        assert answer["id"] == 1 and "hoverProvider" in answer["result"]["capabilities"]
        process.stdin.close()
        assert process.wait(timeout=WAIT_S) == 0
        assert process.stderr.read() == b""  # an editor's stdin is no terminal: no notice
    finally:
        process.kill()
        process.wait()


def test_lsp_help_names_stdio():
    out = subprocess.run([*SERVER, "--help"], capture_output=True, text=True, timeout=WAIT_S)
    assert out.returncode == 0 and "--stdio" in out.stdout


# The child of _in_a_terminal: a new session whose controlling terminal is its stdin, Ctrl-C
# at its default, then `args`. A fresh Python does it, not pty.fork(): Python code run in a fork
# of this multi-threaded worker may deadlock (Python 3.12+ warns of forkpty: DeprecationWarning).
_LOGIN = """import fcntl, os, signal, sys, termios
fcntl.ioctl(0, termios.TIOCSCTTY, 0)
signal.signal(signal.SIGINT, signal.SIG_DFL)  # a background job's shell ignores it
os.execv(sys.argv[1], sys.argv[1:])
"""


def _in_a_terminal(args: list[str]) -> tuple[subprocess.Popen, int]:
    """Start `args` on a new pseudo-terminal, Ctrl-C at its default: (process, terminal fd)."""
    fd, terminal = os.openpty()
    try:  # the terminal is its stdin, stdout and stderr
        process = subprocess.Popen([sys.executable, "-c", _LOGIN, *args], stdin=terminal,
                                   stdout=terminal, stderr=terminal, start_new_session=True)
    finally:
        os.close(terminal)
    return process, fd


def _read_until(fd: int, wanted: bytes, wait_s: float = WAIT_S) -> bytes:
    """What the terminal shows, up to `wanted` (or the end, or WAIT_S)."""
    shown, end = b"", time.monotonic() + wait_s
    while wanted not in shown and time.monotonic() < end:
        ready, _, _ = select.select([fd], [], [], 0.1)
        if ready:
            try:
                chunk = os.read(fd, 4096)
            except OSError:  # EIO: the child closed the terminal
                break
            if not chunk:
                break
            shown += chunk
    return shown


def _exit_code(process: subprocess.Popen, wait_s: float = WAIT_S) -> int | None:
    try:
        return process.wait(timeout=wait_s)
    except subprocess.TimeoutExpired:
        return None


def test_in_a_terminal_it_says_what_it_waits_for_and_the_first_ctrl_c_ends_it():
    process, fd = _in_a_terminal(SERVER)
    code = None
    try:
        shown = _read_until(fd, b"Ctrl-C quits.", wait_s=5.0)
        assert b"language server" in shown and b"waits for an editor" in shown, shown
        assert b"stdin/stdout" in shown and b"Ctrl-C quits." in shown, shown
        os.write(fd, b"\x03")  # the terminal's Ctrl-C: SIGINT to the foreground process
        shown += _read_until(fd, b"interrupted")
        code = _exit_code(process)
        assert code == 130, (code, shown)
        assert b"Fatal Python error" not in shown and b"Traceback" not in shown
    finally:
        if code is None:
            process.kill()
            process.wait()
        os.close(fd)


def test_ctrl_c_while_serving_an_editor_ends_it_cleanly():
    server = Server()  # stdin and stdout are pipes, as an editor starts it
    try:
        server.write(frame(INITIALIZE))
        assert server.answer(1) is not None
        server.process.send_signal(signal.SIGINT)
        assert server.process.wait(timeout=WAIT_S) == 130
        time.sleep(0.2)  # the stderr reader thread takes what is left
        assert b"Fatal Python error" not in server.stderr and b"Traceback" not in server.stderr
    finally:
        server.close()
