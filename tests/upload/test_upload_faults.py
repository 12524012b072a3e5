"""Faults of the link and the controller (mercmac/emulator/faults.py), each over a real
pseudo-terminal: the uploader stops cleanly, says why, writes nothing before the backup, and
never leaves a half-written program autostarting."""
from __future__ import annotations

import os
import signal
import threading
import time

import pytest

from mercmac.errors import EXIT_INTERRUPTED, EXIT_USAGE
from mercmac.emulator.virtual import Faults
from mercmac.upload.errors import FlashFailed, FlashInterrupted, PortError, Refused
from mercmac.upload.flasher import FlashOptions, flash
from mercmac.upload.connect import check_model, identify, open_controller
from mercmac.upload.transport import Timing
from helpers.compiling import program_of
from helpers.emulator import FAST_TIMING, connect, run_flash, serve, serve_clocked, timeouts

PROGRAM = "target C-863\n[MC00] EM5\n[MC05] MR5000,WS100\n[MC06] XN1,MR-10\n[MC07] TP\n"
SILENCE_TIMING = Timing(timeout=0.3, settle=0.05)


def test_nothing_answers_at_that_address(tmp_path, monkeypatch):
    waits = timeouts(monkeypatch)
    with serve_clocked(address=3) as (server, vc):
        with pytest.raises(Refused) as caught:
            run_flash(server, program_of(PROGRAM), tmp_path, address=0)
        assert len(waits) == 3  # one timeout each: the %, the VE and its one retry
        assert "nothing answers at address 0" in caught.value.message
        assert "scan" in caught.value.hint
        assert vc.md_count == 0 and not (tmp_path / "backup.mcm").exists()


def test_nothing_at_all_on_the_other_end_of_the_line(tmp_path):
    master, slave = os.openpty()
    try:
        with pytest.raises(Refused) as caught:
            # nobody reads the other end: silence at any speed, so a short timeout is exact
            with open_controller(os.ttyname(slave), 0, timing=SILENCE_TIMING) as c:
                identify(c)
        assert "nothing answers" in caught.value.message
    finally:
        os.close(master)
        os.close(slave)


def test_a_missing_port_is_a_usage_error_with_a_hint():
    with pytest.raises(PortError) as caught:
        with open_controller("/dev/does-not-exist-mercmac", 0, timing=FAST_TIMING):
            pass
    assert caught.value.exit_code == EXIT_USAGE
    assert "/dev/does-not-exist-mercmac" in caught.value.message and "ports" in caught.value.hint


def test_a_port_in_use_is_refused():
    with serve() as (server, vc), connect(server):
        with pytest.raises(PortError) as caught:
            with open_controller(server.path, 0, timing=FAST_TIMING):
                pass
        assert "another program" in caught.value.hint


def test_wrong_model_is_refused_before_any_write(tmp_path):
    with serve(model="C-663", macros={5: "MR1"}) as (server, vc), connect(server) as c:
        who = identify(c)
        with pytest.raises(Refused) as caught:
            check_model(who, "C-863", "prog.mcm", force=False)
        assert "is a C-663" in caught.value.message and "--force" in caught.value.hint
        assert "flashing anyway" in check_model(who, "C-863", "prog.mcm", force=True)
    assert vc.md_count == 0


def test_garbled_replies_as_at_a_wrong_baud_rate(tmp_path):
    with serve_clocked(faults=Faults(garble=True)) as (server, vc):
        with pytest.raises(Refused) as caught:
            run_flash(server, program_of(PROGRAM), tmp_path)
        assert "does not answer like a Mercury controller" in caught.value.message
        assert "baud" in caught.value.hint
        assert vc.md_count == 0


def test_a_macro_running_and_reporting_when_we_connect(tmp_path):
    # SC0 selects the controller from its autostart macro, which then reports every 5 ms
    chatter = {0: "SC0,TP,WA5,RP", 3: "TT"}
    with serve(macros=chatter) as (server, vc):
        time.sleep(0.1)  # reports pile up in the port before we open it
        with connect(server) as c:
            who = identify(c)
            assert who.stopped_macro
            result = flash(c, who, program_of(PROGRAM), FlashOptions(backup=tmp_path / "b.mcm"))
        assert result.plan.before == {0: "SC0,TP,WA5,RP", 3: "TT"}
        assert vc.macros == {0: "EM5", 3: "TT", 5: "MR5000,WS100", 6: "XN1,MR-10", 7: "TP"}
        assert "[MC00] SC0,TP,WA5,RP" in (tmp_path / "b.mcm").read_text()


def test_a_character_lost_once_is_caught_and_written_again(tmp_path):
    # the 2nd MD line ("MD6,XN1,MR-10") loses its 6th character
    with serve(faults=Faults(drop_char={2: 5})) as (server, vc):
        result, _ = run_flash(server, program_of(PROGRAM), tmp_path)
        assert result.retried == [6]
        assert vc.macros == {0: "EM5", 5: "MR5000,WS100", 6: "XN1,MR-10", 7: "TP"}


def test_a_character_lost_every_time_fails_clearly_and_leaves_no_autostart(tmp_path):
    with serve(macros={0: "EM5", 5: "MR1"}, faults=Faults(always_drop_slot=6)) as (server, vc):
        with pytest.raises(FlashFailed) as caught:
            run_flash(server, program_of(PROGRAM), tmp_path)
        text = caught.value.message
        assert "MC06 does not verify after a second write" in text
        assert "'XN1,MR-10'" in text  # what was expected, and what came back
        assert "written and verified: MC00 (autostart removed), MC05\n" in text
        assert "failed verification: MC06" in text
        assert "not written: MC07, MC00" in text
        assert str(tmp_path / "backup.mcm") in text
        assert 0 not in vc.macros  # parked before the first write, never written back
        assert "[MC00] EM5" in (tmp_path / "backup.mcm").read_text()


def test_a_lost_digit_that_sends_a_macro_to_another_slot_is_repaired(tmp_path):
    # "MD15,MR7" losing its '5' becomes "MD1,MR7": it overwrites macro 1, already verified
    program = program_of("[MC01] TP\n[MC15] MR7\n")
    with serve(faults=Faults(drop_char={2: 3})) as (server, vc):
        result, _ = run_flash(server, program, tmp_path)
        assert result.retried == [15] and result.repaired == [1]
        assert vc.macros == {1: "TP", 15: "MR7"}


def test_macro_0_that_does_not_verify_is_removed(tmp_path):
    with serve(faults=Faults(always_drop_slot=0)) as (server, vc):
        with pytest.raises(FlashFailed) as caught:
            run_flash(server, program_of(PROGRAM), tmp_path)
        assert "MC00 does not verify" in caught.value.message
        assert "removed: the controller will not autostart" in caught.value.message
        assert 0 not in vc.macros and vc.macros[7] == "TP"


def test_the_port_disappears_mid_flash(tmp_path, monkeypatch):
    waits = timeouts(monkeypatch)
    with serve(macros={0: "EM5", 5: "GH"}, faults=Faults(vanish_after_md=2)) as (server, vc):
        with pytest.raises(FlashFailed) as caught:
            run_flash(server, program_of(PROGRAM), tmp_path)
        assert waits == []  # the loss is seen at once, not waited out
        text = caught.value.message
        assert "the port went away" in text
        assert "written and verified: MC00 (autostart removed), MC05\n" in text
        assert "in progress, state unknown: MC06" in text
        assert "not written: MC07, MC00" in text
        assert "will not autostart" in text
        assert f"backup of the controller as it was: {tmp_path / 'backup.mcm'}" in text
        assert 0 not in vc.macros  # RZ came first, so a power cut now autostarts nothing
        assert "flash" in caught.value.hint


def test_ctrl_c_mid_flash(tmp_path):
    main, over = threading.get_ident(), threading.Event()
    with serve(macros={0: "EM5", 5: "GH"}, faults=Faults(md_delay=0.05)) as (server, vc):
        def interrupt_after_two_writes():
            # never after the test: a late SIGINT would stop whichever test runs then
            while not over.is_set() and server.call(lambda _c: vc.md_count) < 2:
                time.sleep(0.002)
            if not over.is_set():
                signal.pthread_kill(main, signal.SIGINT)  # a real SIGINT, as Ctrl-C sends

        interrupter = threading.Thread(target=interrupt_after_two_writes, daemon=True)
        interrupter.start()
        try:
            with pytest.raises(FlashInterrupted) as caught:
                run_flash(server, program_of(PROGRAM), tmp_path)
        finally:
            over.set()
            interrupter.join()
        assert caught.value.exit_code == EXIT_INTERRUPTED
        text = caught.value.message
        assert "interrupted (Ctrl-C)" in text and "not written:" in text and "MC00" in text
        assert str(tmp_path / "backup.mcm") in text
        assert 0 not in vc.macros


def test_a_controller_that_falls_silent_after_identifying_is_refused_before_writing(tmp_path):
    with serve_clocked() as (server, vc), connect(server) as c:
        who = identify(c)
        server.call(lambda _c: setattr(vc.faults, "silent", True))
        with pytest.raises(Refused) as caught:
            flash(c, who, program_of(PROGRAM), FlashOptions(backup=tmp_path / "b.mcm"))
        assert "no answer to TM" in caught.value.message
        assert vc.md_count == 0 and not (tmp_path / "b.mcm").exists()


def test_an_unwritable_backup_refuses_the_flash(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("")
    with serve() as (server, vc):
        with pytest.raises(Refused) as caught:
            run_flash(server, program_of(PROGRAM), tmp_path, backup=blocker / "b.mcm")
        assert "nothing was written" in caught.value.message
        assert vc.md_count == 0


def test_timing_budget_is_bounded():
    assert Timing(timeout=0.3).budget(9600) < 10
