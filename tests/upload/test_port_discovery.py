"""The uploader as esptool and mpremote users expect it.

PORT and --address may be left out, a swapped `flash FILE PORT` is recognised,
`scan` shows its progress, the flash bar a rate and the time left, a dry run
says what would happen, and a backup flashed back says how to restore it exactly.
Through a real pty with the virtual controller (tests/test_upload_emulator.serve).
"""
from __future__ import annotations

import io
import re
import time
from contextlib import contextmanager
from types import SimpleNamespace

import pytest

from helpers.cli import cli
from mercmac.upload import survey
from mercmac.upload.survey import PortInfo
from helpers import emulator
from helpers.emulator import FAST

PROGRAM = "target C-863\n[MC00] EM5\n[MC05] MR5000,WS100\n"
# the search of addresses 1-15 waits this long at each, on the line's clock (serve, below)
SEARCH_TIMEOUT = list(FAST)


@contextmanager
def serve(**kw):
    """helpers.emulator.serve on its line's clock: the silent addresses of a search or a
    scan pass in milliseconds, and an answer however late is never taken for silence."""
    with emulator.serve(**kw) as (server, vc), emulator.line_clock(server):
        yield server, vc


@pytest.fixture(autouse=True)
def no_port_variable(monkeypatch):
    monkeypatch.delenv("MERCMAC_PORT", raising=False)


def pi(device: str) -> PortInfo:
    return PortInfo(device, "PI Mercury", 0x1A72, 0x1007, "X1")


def other(device: str) -> PortInfo:
    return PortInfo(device, "FT232R USB UART", 0x0403, 0x6001, None)


# -- the address ------------------------------------------------------------------

@pytest.mark.slow
def test_flash_finds_the_only_controller_without_address(tmp_path, program_file):
    with serve(address=3) as (server, vc):
        result = cli("flash", server.path, program_file, "--backup", tmp_path / "b.mcm", *SEARCH_TIMEOUT)
    assert result.exit_code == 0, result.output
    assert "at address 3 on" in result.output
    assert "address 3 is the only one that answers" in result.output
    assert vc.macros == {0: "EM5", 5: "MR5000,WS100"}
    assert "address 3" in (tmp_path / "b.mcm").read_text()


@pytest.mark.slow
def test_dry_run_bytes_select_the_address_found(program_file):
    with serve(address=3) as (server, vc):
        result = cli("flash", server.path, program_file, "--dry-run", *SEARCH_TIMEOUT)
    assert result.exit_code == 0, result.output
    assert "<01>3" in result.output and vc.md_count == 0


@pytest.mark.slow
def test_pull_finds_the_only_controller_without_address(tmp_path):
    with serve(address=7, macros={4: "XN1,MR5"}) as (server, vc):
        result = cli("pull", server.path, "-o", tmp_path / "p.mcm", *SEARCH_TIMEOUT)
    assert result.exit_code == 0, result.output
    assert "[MC04] XN1,MR5" in (tmp_path / "p.mcm").read_text()
    assert "address 7" in result.output


def test_address_0_is_used_at_once_without_a_search(program_file, tmp_path, monkeypatch):
    waits = emulator.timeouts(monkeypatch)
    with serve() as (server, vc):
        result = cli("flash", server.path, program_file, "--backup", tmp_path / "b.mcm", *FAST)
    assert result.exit_code == 0, result.output
    assert "only one that answers" not in result.output
    assert waits == []  # a search of 1-15 would wait at each of them


def test_an_explicit_address_is_not_searched(program_file):
    with serve(address=3) as (server, vc):
        result = cli("flash", server.path, program_file, "--address", "2", *SEARCH_TIMEOUT)
    assert result.exit_code == 1
    assert "nothing answers at address 2" in result.output and vc.md_count == 0


@pytest.mark.slow
def test_no_answer_at_any_address(program_file):
    from mercmac.emulator.virtual import Faults

    with serve(faults=Faults(silent=True)) as (server, vc):
        result = cli("flash", server.path, program_file, *SEARCH_TIMEOUT)
    assert result.exit_code == 1
    assert "nothing answers at addresses 0-15" in result.output and vc.md_count == 0


def test_several_answering_need_address(program_file, monkeypatch):
    status = SimpleNamespace(layout="C-863", macro_running=False)
    chain = [survey.Found(2, status, None), survey.Found(9, status, None)]
    monkeypatch.setattr(survey, "scan", lambda *a, **k: chain)
    with serve(address=2) as (server, vc):
        result = cli("flash", server.path, program_file, *SEARCH_TIMEOUT)
    assert result.exit_code == 2, result.output
    assert "2 controllers answer" in result.output and "addresses 2 (C-863), 9 (C-863)" in result.output
    assert "--address 2" in result.output and vc.md_count == 0


# -- the port ---------------------------------------------------------------------

def test_swapped_arguments_are_recognised(program_file):
    with serve() as (server, vc):
        result = cli("flash", program_file, server.path, *SEARCH_TIMEOUT)
    assert result.exit_code == 2
    assert "arguments are swapped" in result.output
    assert f"mercmac flash {server.path} {program_file}" in result.output
    assert "Could not configure port" not in result.output and vc.md_count == 0


def test_a_program_where_pull_wants_its_port(program_file):
    result = cli("pull", program_file, *SEARCH_TIMEOUT)
    assert result.exit_code == 2 and "is a program file where the port goes" in result.output


def test_port_from_the_environment(tmp_path, program_file, monkeypatch):
    with serve() as (server, vc):
        monkeypatch.setenv("MERCMAC_PORT", server.path)
        result = cli("flash", program_file, "--backup", tmp_path / "b.mcm", *SEARCH_TIMEOUT)
    assert result.exit_code == 0, result.output
    assert f"port: {server.path} (MERCMAC_PORT)" in result.output
    assert vc.macros == {0: "EM5", 5: "MR5000,WS100"}


def test_port_option(tmp_path, program_file):
    with serve(macros={2: "TP"}) as (server, vc):
        flashed = cli("flash", "-p", server.path, program_file, "--backup", tmp_path / "b.mcm", *SEARCH_TIMEOUT)
        pulled = cli("pull", "--port", server.path, *SEARCH_TIMEOUT)
        scanned = cli("scan", "-p", server.path, *FAST)
    assert flashed.exit_code == 0, flashed.output
    assert pulled.exit_code == 0 and "[MC05] MR5000,WS100" in pulled.output
    assert scanned.exit_code == 0 and "C-863" in scanned.output


def test_two_different_ports_are_refused(program_file):
    result = cli("flash", "/dev/ttyUSB0", program_file, "-p", "/dev/ttyUSB1")
    assert result.exit_code == 2 and "two ports given" in result.output


def test_auto_detects_the_only_pi_device(tmp_path, program_file, monkeypatch):
    with serve() as (server, vc):
        monkeypatch.setattr(survey, "list_ports", lambda: [pi(server.path), other("/dev/ttyS0")])
        result = cli("flash", program_file, "--backup", tmp_path / "b.mcm", *SEARCH_TIMEOUT)
    assert result.exit_code == 0, result.output
    assert f"port: {server.path} (the only PI USB device (C-863))" in result.output
    assert vc.macros == {0: "EM5", 5: "MR5000,WS100"}


def test_auto_detects_the_only_serial_port(monkeypatch):
    with serve(macros={4: "TP"}) as (server, vc):
        monkeypatch.setattr(survey, "list_ports", lambda: [other(server.path)])
        result = cli("pull", *SEARCH_TIMEOUT)
    assert result.exit_code == 0, result.output
    assert "the only serial port" in result.output and "[MC04] TP" in result.output


@pytest.mark.parametrize("found, said", [
    ([pi("/dev/ttyUSB0"), pi("/dev/ttyUSB1")], "2 PI USB devices: /dev/ttyUSB0 (C-863), /dev/ttyUSB1"),
    ([other("/dev/ttyUSB0"), other("/dev/ttyS0")], "none of them a PI USB device"),
    ([], "no serial ports"),
])
def test_no_single_candidate_is_a_usage_error(program_file, monkeypatch, found, said):
    monkeypatch.setattr(survey, "list_ports", lambda: found)
    result = cli("flash", program_file)
    assert result.exit_code == 2 and said in result.output, result.output
    assert "MERCMAC_PORT" in result.output


def test_flash_without_any_argument_says_what_is_missing(monkeypatch):
    result = cli("flash")
    assert result.exit_code == 2 and "no program file given" in result.output


# -- what is shown ----------------------------------------------------------------

def test_scan_shows_each_address_on_a_terminal(monkeypatch):
    monkeypatch.setenv("FORCE_COLOR", "1")
    monkeypatch.delenv("NO_COLOR", raising=False)
    with serve(address=11) as (server, vc):
        result = cli("scan", server.path, *FAST)
    assert result.exit_code == 0
    assert "scanning: address 0 of 0-15" in result.stderr
    assert "scanning: address 15 of 0-15" in result.stderr


def test_scan_shows_no_progress_in_a_log(monkeypatch):
    monkeypatch.delenv("FORCE_COLOR", raising=False)
    with serve(address=11) as (server, vc):
        result = cli("scan", server.path, *FAST)
    assert "scanning" not in result.output


def test_flash_progress_shows_a_rate_and_the_time_left(monkeypatch):
    from mercmac.render.upload import FlashProgress
    from mercmac.upload.flasher import Event

    monkeypatch.setenv("FORCE_COLOR", "1")
    monkeypatch.delenv("NO_COLOR", raising=False)
    out = io.StringIO()
    with FlashProgress(out) as progress:
        progress(Event("step", "write MC01", 0, 3, 0, 300))
        time.sleep(0.05)
        progress(Event("verified", "write MC01: verified", 1, 3, 100, 300))
        time.sleep(0.05)
        progress(Event("step", "write MC02", 1, 3, 100, 300))
    text = out.getvalue()
    assert "1/3" in text and re.search(r"\d B/s", text)
    assert re.search(r"0:0\d left", text)  # the time left


def test_dry_run_says_what_a_flash_would_do(tmp_path):
    prog = tmp_path / "p.mcm"
    prog.write_text("target C-863\nautostart { EM 5 }\n[MC05] MR5000,WS100\n[MC06] TP\n")
    with serve(macros={0: "EM1", 6: "TP", 9: "TT"}) as (server, vc):
        result = cli("flash", server.path, prog, "--dry-run", *SEARCH_TIMEOUT)
    assert result.exit_code == 0, result.output
    out = result.output
    assert "would be written" in out and "unchanged" in out and "kept (not in file)" in out
    assert "dry run: nothing written; a flash would write 2, leave 1 unchanged, " \
           "keep 1 not in the file" in out
    assert not re.search(r"  written$", out, re.M) and "(2 written" not in out
    assert "remove autostart (MC00) first" in out and "(autostart) until the end" not in out
    assert vc.md_count == 0


def test_park_step_reads_well_without_a_label():
    from mercmac.upload.plan import Action, Step

    assert Step(Action.PARK, 0, "MC00").describe == "remove the autostart macro MC00 first"
    assert Step(Action.PARK, 0, "autostart (MC00)").describe == "remove autostart (MC00) first"


def test_restoring_a_backup_says_it_needs_erase_unused(tmp_path):
    with serve(macros={0: "EM1", 3: "TP"}) as (server, vc):
        saved = cli("pull", server.path, "-o", tmp_path / "saved.mcm", *SEARCH_TIMEOUT)
        assert saved.exit_code == 0, saved.output
        server.call(lambda _c: vc._store({**vc.macros, 7: "TT", 8: "TP"}))  # the controller gains two
        kept = cli("flash", server.path, tmp_path / "saved.mcm", "--backup", tmp_path / "b1.mcm", *SEARCH_TIMEOUT)
        assert kept.exit_code == 0, kept.output
        assert "this backup holds 2 macros; the controller also holds MC07, MC08" in kept.output
        assert "--erase-unused" in kept.output
        assert vc.macros == {0: "EM1", 3: "TP", 7: "TT", 8: "TP"}
        exact = cli("flash", server.path, tmp_path / "saved.mcm", "--erase-unused",
                    "--backup", tmp_path / "b2.mcm", *SEARCH_TIMEOUT)
    assert exact.exit_code == 0, exact.output
    assert "this backup holds" not in exact.output
    assert vc.macros == {0: "EM1", 3: "TP"}


def test_an_ordinary_program_gets_no_restore_note(tmp_path, program_file):
    with serve(macros={7: "TT"}) as (server, vc):
        result = cli("flash", server.path, program_file, "--backup", tmp_path / "b.mcm", *SEARCH_TIMEOUT)
    assert result.exit_code == 0 and "this backup holds" not in result.output
