"""The pty server's own life: closing it while a turn is still running (once, after
close, its thread read from a closed pty, a TypeError in the thread)."""
from __future__ import annotations

import os
import threading

import pytest

from helpers.emulator import eventually, raw_port, serve, until

pytestmark = pytest.mark.skipif(not hasattr(os, "openpty"), reason="needs pseudo-terminals")

WAIT_S = 10  # for events that come at once on a quiet machine


@pytest.fixture
def thread_errors(monkeypatch) -> list[BaseException]:
    """The exceptions any thread ends with while the test runs."""
    seen: list[BaseException] = []
    monkeypatch.setattr(threading, "excepthook", lambda args: seen.append(args.exc_value))
    return seen


def test_close_during_a_long_turn_waits_for_it(thread_errors):
    """A turn held up (here by the test holding the controller) past close: the pty stays
    open until the turn has sent its answer, and the thread ends without an error."""
    held, release = threading.Event(), threading.Event()
    with serve() as (server, vc), raw_port(server) as port:
        holder = threading.Thread(target=server.call,
                                  args=(lambda _c: (held.set(), release.wait(WAIT_S)),))
        holder.start()
        assert held.wait(WAIT_S)
        port.write(b"\x010TP\r")  # read by the server's thread, which then waits for the turn
        closing = threading.Thread(target=server.close)
        closing.start()
        closing.join(WAIT_S / 4)  # the old close gave up here after 2 s and closed the pty
        release.set()
        holder.join(WAIT_S)
        closing.join(WAIT_S)
        assert not closing.is_alive()
    assert thread_errors == []


def test_idle_is_false_while_the_host_has_an_answer_to_read():
    with serve() as (server, vc), raw_port(server) as port:
        assert until(server.idle)
        port.write(b"\x010TP\r")
        assert eventually(server, lambda _c: "TP" in vc.lines, seconds=WAIT_S)
        assert not server.idle()  # "P:+0000000000" waits in the pty for the host
        assert port.read_until(b"\x03").endswith(b"\x03")
        assert until(server.idle)
