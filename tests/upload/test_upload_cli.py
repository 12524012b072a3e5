"""`mercmac flash`, `pull`, `scan`, `ports` and `emulate` as a user runs them."""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import pytest

from helpers.cli import cli
from mercmac.compiler import compile_source
from mercmac.source import Source
from mercmac.emulator.virtual import Faults
from mercmac.upload.survey import PortInfo
from helpers.emulator import FAST, line_clock, serve
from helpers.paths import EXAMPLE4

PROGRAM = "target C-863\n[MC00] EM5\n[MC05] MR5000,WS100\n"


def command_line(*args: str) -> list[str]:
    """The same, as a separate process."""
    return [sys.executable, "-m", "mercmac", *args]


def test_flash_prints_the_controller_the_table_and_the_backup(tmp_path, program_file):
    with serve() as (server, vc):
        result = cli("flash", server.path, program_file, "--backup", tmp_path / "b.mcm", *FAST)
    assert result.exit_code == 0, result.output
    out = result.output
    assert "controller: C-863, firmware 2.30, at address 0" in out
    assert "MC05" in out and "written" in out
    assert "ok: flashed and verified: 2 written" in out
    assert f"backup: {tmp_path / 'b.mcm'}" in out
    assert vc.macros == {0: "EM5", 5: "MR5000,WS100"}


def test_default_backup_goes_to_the_per_user_data_directory(tmp_path, program_file, monkeypatch):
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    with serve(macros={3: "TP"}) as (server, vc):
        result = cli("flash", server.path, program_file, *FAST)
    assert result.exit_code == 0, result.output
    backups = list((tmp_path / "data" / "mercmac" / "backups").glob("*-addr0-*.mcm"))
    assert len(backups) == 1 and f"backup: {backups[0]}" in result.output
    assert "[MC03] TP" in backups[0].read_text()


def test_a_file_with_errors_is_not_flashed(tmp_path):
    bad = tmp_path / "bad.mcm"
    bad.write_text("[MC05] MR\n")
    result = cli("flash", "/dev/does-not-exist", bad, *FAST)  # the port is never opened
    assert result.exit_code == 1
    assert "bad-argument" in result.output and "nothing was flashed" in result.output


def test_a_file_without_target_is_checked_against_the_controller(tmp_path):
    prog = tmp_path / "dc.mcm"
    prog.write_text("[MC05] DP200,MR5\n")  # DP exists on the C-863 only
    with serve(model="C-663") as (server, vc):
        result = cli("flash", server.path, prog, *FAST)
    assert result.exit_code == 1
    assert "model-unsupported" in result.output and "errors for the C-663" in result.output
    assert vc.md_count == 0


def test_wrong_model_needs_force(tmp_path, program_file):
    with serve(model="C-663") as (server, vc):
        refused = cli("flash", server.path, program_file, "--backup", tmp_path / "b.mcm", *FAST)
        assert refused.exit_code == 1 and "is a C-663" in refused.output and vc.md_count == 0
        forced = cli("flash", server.path, program_file, "--force", "--backup",
                         tmp_path / "b.mcm", *FAST)
    assert forced.exit_code == 0 and "flashing anyway" in forced.output


def test_dry_run_shows_the_bytes_and_writes_nothing(program_file):
    with serve() as (server, vc):
        result = cli("flash", server.path, program_file, "--dry-run", *FAST)
    assert result.exit_code == 0
    assert "<01>0" in result.output and "MD5,MR5000,WS100<CR>" in result.output
    assert "TM5<CR>" in result.output and "dry run: nothing written" in result.output
    assert vc.md_count == 0


def test_missing_port_exit_code_2(program_file):
    result = cli("flash", "/dev/does-not-exist-mercmac", program_file, *FAST)
    assert result.exit_code == 2 and "cannot open /dev/does-not-exist-mercmac" in result.output


def test_lost_port_exit_code_1_with_the_state(tmp_path, program_file):
    with serve(macros={0: "EM1"}, faults=Faults(vanish_after_md=1)) as (server, vc):
        result = cli("flash", server.path, program_file, "--backup", tmp_path / "b.mcm", *FAST)
    assert result.exit_code == 1
    assert "the port went away" in result.output and "not written: MC00" in result.output
    assert "Traceback" not in result.output


def test_pull_gives_a_file_that_checks_and_flashes_back_exactly(tmp_path):
    original = compile_source(Source("ex4", EXAMPLE4.read_text())).program
    stored = {slot: m.line for slot, m in original.macros.items()}
    with serve(macros=stored) as (server, vc):
        pulled = cli("pull", server.path, "-o", tmp_path / "pulled.mcm", *FAST)
        assert pulled.exit_code == 0, pulled.output
        again = cli("flash", server.path, tmp_path / "pulled.mcm", "--backup", tmp_path / "b.mcm", *FAST)
        assert again.exit_code == 0 and "nothing to write" in again.output
    text = (tmp_path / "pulled.mcm").read_text()
    assert "controller: C-863, firmware 2.30" in text and "address 0" in text
    check = compile_source(Source("pulled.mcm", text))
    assert not check.report.has_errors
    with serve() as (server, fresh):
        result = cli("flash", server.path, tmp_path / "pulled.mcm", "--backup", tmp_path / "c.mcm", *FAST)
        assert result.exit_code == 0
    assert fresh.macros == vc.macros


def test_pull_to_standard_output(tmp_path):
    with serve(macros={4: "XN1,MR5"}) as (server, vc):
        result = cli("pull", server.path, *FAST)
    assert result.exit_code == 0 and "[MC04] XN1,MR5\n" in result.output


def test_scan_lists_who_answers(tmp_path):
    # 15 silent addresses, each waited out on the line's clock: fast, and 11's answer,
    # however late a loaded machine makes it, is never taken for silence
    with serve(address=11, macros={2: "TP"}) as (server, vc), line_clock(server):
        result = cli("scan", server.path, *FAST)
    assert result.exit_code == 0, result.output
    row = [line for line in result.output.splitlines() if line.startswith("11 ")]
    assert row and "C-863" in row[0] and "2.30" in row[0]


def test_scan_leaves_a_running_macro_alone(tmp_path):
    with serve(address=4, macros={0: "SC4,WA10,RP"}) as (server, vc), line_clock(server):
        result = cli("scan", server.path, *FAST)
        assert server.call(lambda _c: vc.running)
    assert "macro running, left alone" in result.output


def test_scan_of_silence_exits_1():
    with serve(faults=Faults(silent=True)) as (server, vc), line_clock(server):
        result = cli("scan", server.path, *FAST)
    assert result.exit_code == 1 and "no controller answered" in result.output


def test_ports_marks_pi_devices():
    assert PortInfo("/dev/ttyUSB0", "", 0x1A72, 0x1007, None).mercury == "C-863"
    assert PortInfo("/dev/ttyUSB1", "", 0x1A72, 0x1234, None).mercury == "PI device"
    assert PortInfo("/dev/ttyS0", "", 0x0403, 0x6001, None).mercury is None
    from mercmac.render.upload import ports_lines

    lines = ports_lines([PortInfo("/dev/ttyUSB0", "Mercury", 0x1A72, 0x1007, "X")])
    assert "likely Mercury (C-863)" in "".join(t for t, _ in lines[1])
    assert cli("ports").exit_code == 0


@pytest.mark.skipif(not hasattr(os, "openpty"), reason="needs pseudo-terminals")
def test_emulate_serves_a_pty_and_keeps_its_state(tmp_path, program_file):
    state = tmp_path / "flash.json"
    for round_ in range(2):
        proc = subprocess.Popen(command_line("emulate", "--state", str(state), "--address", "12"),
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            assert "virtual C-863" in proc.stdout.readline()
            path = proc.stdout.readline().strip()
            if round_ == 0:
                result = cli("flash", path, program_file, "--address", "12", "--backup",
                                 tmp_path / "b.mcm", *FAST)
                assert result.exit_code == 0, result.output
            else:
                result = cli("pull", path, "--address", "12", *FAST)
                assert "[MC00] EM5" in result.output and "[MC05] MR5000,WS100" in result.output
        finally:
            proc.send_signal(signal.SIGINT)
            assert proc.wait(timeout=5) == 130  # Ctrl-C, as `scan` and `sim --interactive`


@pytest.mark.skipif(not hasattr(os, "openpty"), reason="needs pseudo-terminals")
def test_ctrl_c_in_a_real_process(tmp_path, program_file):
    with serve(macros={0: "EM1", 1: "TP"}, faults=Faults(md_delay=0.2)) as (server, vc):
        proc = subprocess.Popen(command_line("flash", server.path, str(program_file), "--backup",
                                             str(tmp_path / "b.mcm"), *FAST),
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        end = time.monotonic() + 10
        while server.call(lambda _c: vc.md_count) < 1 and time.monotonic() < end:
            time.sleep(0.005)
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=10)
    assert proc.returncode == 130, out + err
    assert "interrupted (Ctrl-C)" in err and str(tmp_path / "b.mcm") in err
    assert "Traceback" not in err
    assert 0 not in vc.macros  # RZ went first; the autostart is not left half-written
