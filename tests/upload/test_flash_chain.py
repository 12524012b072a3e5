"""One flash for a program file and a rig (mercmac.upload.chain): a program file is a chain of
one controller, so what one side guarded against now holds for both (docs/uploader.md,
"Signals and lost ports"; docs/rigs.md, "Flashing and pulling a rig")."""
from __future__ import annotations

import io
import re
import signal
import time
from contextlib import contextmanager

import pytest

from helpers.emulator import FAST_TIMING, ROOM_S
from mercmac.emulator.chain import Chain
from mercmac.emulator.ptyserver import PtyServer
from mercmac.emulator.virtual import VirtualController
from mercmac.errors import interrupt
from mercmac.upload import history
from mercmac.upload.chain import Watch, flash_chain
from mercmac.upload.controller import Controller, LinkLost
from mercmac.upload.errors import FlashFailed, FlashInterrupted
from mercmac.upload.flasher import FlashOptions

PROGRAM = "target C-663\n[MC00] EM5\n[MC03] MR200,WS0\n"


@contextmanager
def serving(*addresses: int):
    """C-663s at ADDRESSES on one pty, holding {0: EM1}: yields the server and its byte log
    once macro 0 has ended on each (a macro still running when the flash asks `%` makes it
    ask again after VE, MS176E §3.8.3: on a loaded machine that was the only difference)."""
    log = io.StringIO()
    vcs = [VirtualController("C-663", a, macros={0: "EM1"}) for a in addresses]
    with PtyServer(Chain(vcs), log) as server:
        deadline = time.monotonic() + ROOM_S
        while any(vc.running for vc in vcs):
            assert time.monotonic() < deadline, "macro 0 did not end"
            time.sleep(0.01)
        yield server, log


def rig_of(folder, *addresses: int):
    """A rig file of a controller at each of ADDRESSES (a0, a1, ...), each with PROGRAM."""
    (folder / "p.mcm").write_text(PROGRAM, encoding="utf-8")
    lines = ['name = "bench"']
    for a in addresses:
        lines += ["", f"[controllers.a{a}]", f"address = {a}", 'model = "C-663"',
                  'program = "p.mcm"']
    path = folder / "bench.rig.toml"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def host_bytes(log: io.StringIO) -> bytes:
    return b"".join(bytes.fromhex(m[1]) for m in
                    re.finditer(r"^\s*[\d.]+ -> ((?:[0-9a-f]{2} ?)+)", log.getvalue(), re.M))


def test_a_program_file_and_a_rig_of_one_send_the_same_bytes(tmp_path, data_dir):
    rig = rig_of(tmp_path, 2)
    sent = []
    for path in (tmp_path / "p.mcm", rig):
        with serving(2) as (server, log):
            flash_chain(server.path, str(path), address=2, timing=FAST_TIMING,
                        options=FlashOptions(reset=True))
        sent.append(host_bytes(log))
    assert sent[0] == sent[1] and b"MD3,MR200,WS0\r" in sent[0]


def test_a_signal_while_rt_goes_to_a_rig_says_what_each_controller_holds(tmp_path, data_dir,
                                                                        monkeypatch):
    """The rig's RT had no guard: the signal left without the state of each controller."""
    def cut(self):
        raise interrupt(signal.SIGTERM)

    monkeypatch.setattr(Controller, "reset", cut)
    with serving(0, 1) as (server, _), pytest.raises(FlashInterrupted) as caught:
        flash_chain(server.path, str(rig_of(tmp_path, 0, 1)), timing=FAST_TIMING,
                    options=FlashOptions(reset=True))
    said = caught.value.message
    assert caught.value.exit_code == 128 + signal.SIGTERM
    assert said.startswith("rig flash stopped at a0 (address 0): all macros are written and "
                           "verified (backup: "), said
    assert "interrupted while sending RT" in said
    assert "a1 (address 1): flashed and verified; backup of what it held: " in said


def test_a_program_file_whose_rt_fails_is_in_the_history_all_the_same(tmp_path, data_dir,
                                                                       monkeypatch):
    """Verified is verified: the record (which `pull` gives the source back by) is written
    before RT, as a rig's always was."""
    def lost(self):
        raise LinkLost("gone")

    monkeypatch.setattr(Controller, "reset", lost)
    (tmp_path / "p.mcm").write_text(PROGRAM, encoding="utf-8")
    with serving(0) as (server, _), pytest.raises(FlashFailed, match="but RT failed: the port "
                                                                     "went away \\(gone\\)"):
        flash_chain(server.path, str(tmp_path / "p.mcm"), timing=FAST_TIMING,
                    options=FlashOptions(reset=True))
    assert [r.address for r in history.read().records] == [0]


class LostAfter(Watch):
    """The port fails (every selection code after it) once controller NAME is written."""

    def __init__(self, name: str, monkeypatch):
        self.name, self.monkeypatch = name, monkeypatch

    @contextmanager
    def writing(self, part):
        yield lambda event: None
        if part.name == self.name:
            def lost(controller):
                raise LinkLost("gone")

            self.monkeypatch.setattr(Controller, "select", lost)


def test_a_port_that_fails_between_two_controllers_says_what_each_holds(tmp_path, data_dir,
                                                                       monkeypatch):
    """Selecting the next controller was outside every guard: a lost port there left with a
    traceback instead of the report."""
    with serving(0, 1) as (server, _), pytest.raises(FlashFailed) as caught:
        flash_chain(server.path, str(rig_of(tmp_path, 0, 1)), timing=FAST_TIMING,
                    watch=LostAfter("a0", monkeypatch))
    said = caught.value.message
    assert said.startswith("rig flash stopped at a1 (address 1): the port failed before "
                           "anything was written to it: the port went away (gone)"), said
    assert "a0 (address 0): flashed and verified" in said and "a1 (address 1): untouched" in said
