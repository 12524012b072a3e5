"""A host that stalls (a loaded machine, a laptop that sleeps) past a read's hard stop while
nothing comes hears silence, not a flood: once a stall of the tests' line clock turned a
silent address of a search into "garbled replies" and stopped the search there."""
from __future__ import annotations

import os
import types

import pytest

from mercmac.upload import controller as controller_module
from mercmac.upload import transport as transport_module
from mercmac.upload.controller import NoAnswer
from mercmac.upload.transport import ReadTimeout, Timing, Transport

pytestmark = pytest.mark.skipif(not hasattr(os, "openpty"), reason="needs pseudo-terminals")
TIMING = Timing(timeout=0.3, settle=0.05)


class Stalling:
    """A clock that stands still, then jumps `stall` s at its `at`-th reading: the process
    was not run for that long."""

    def __init__(self, stall: float, at: int):
        self.t, self.calls, self.stall, self.at = 100.0, 0, stall, at

    def monotonic(self) -> float:
        self.calls += 1
        if self.calls == self.at:
            self.t += self.stall
        self.t += 0.1  # then time goes on as the polls ask for it
        return self.t


@pytest.fixture
def silent_port():
    master, slave = os.openpty()  # nobody answers on the other end
    try:
        yield os.ttyname(slave)
    finally:
        os.close(master)
        os.close(slave)


def test_a_stall_past_the_deadline_with_nothing_come_is_silence(silent_port, monkeypatch):
    """The caller's deadline (its flood bound) was taken before the stall."""
    clock = Stalling(stall=TIMING.budget(9600) + 5, at=2)
    monkeypatch.setattr(transport_module, "time", types.SimpleNamespace(monotonic=clock.monotonic))
    with Transport(silent_port, timing=TIMING) as transport:
        deadline = clock.monotonic() + TIMING.budget(9600)
        with pytest.raises(ReadTimeout) as caught:
            transport.read_report(deadline=deadline)
    assert not caught.value.endless and "no complete reply" in str(caught.value)


def test_a_probe_after_a_stall_is_no_answer_not_a_flood(silent_port, monkeypatch):
    """The controller's own stop is taken before the read starts: a stall between the two."""
    clock = Stalling(stall=TIMING.budget(9600) + 5, at=2)
    fake = types.SimpleNamespace(monotonic=clock.monotonic)
    monkeypatch.setattr(transport_module, "time", fake)
    monkeypatch.setattr(controller_module, "time", fake)
    with Transport(silent_port, timing=TIMING) as transport:
        with pytest.raises(NoAnswer):
            controller_module.Controller(transport, 0).probe()
