"""Ports and counts said right: `-p A -p B` is refused, a file that is
no serial port is named as such (a FIFO is never waited on), and one macro is "1 macro"."""
from __future__ import annotations

import os
import subprocess
import sys

import pytest

from helpers.cli import cli
from helpers.emulator import FAST, serve

pytestmark = pytest.mark.skipif(not hasattr(os, "openpty"), reason="needs pseudo-terminals")


@pytest.mark.parametrize("command", [["pull"], ["scan"], ["flash", "x.mcm"]])
def test_a_port_given_twice_is_refused(command):
    result = cli(*command, "-p", "/dev/a", "-p", "/dev/b")
    assert result.exit_code == 2, result.output
    assert "give the port once" in result.output and "'/dev/b'" in result.output


def _not_a_port(path) -> subprocess.CompletedProcess:
    """`mercmac pull -p PATH` as a process: a hang on opening it fails after a minute."""
    try:
        return subprocess.run([sys.executable, "-m", "mercmac", "pull", "-p", str(path), *FAST],
                              capture_output=True, text=True, timeout=60)
    except subprocess.TimeoutExpired:
        pytest.fail(f"pull -p {path} hangs")


def test_a_regular_file_is_not_a_serial_port(tmp_path):
    (tmp_path / "port").write_text("")
    done = _not_a_port(tmp_path / "port")
    assert done.returncode == 2 and "it is a regular file, not a serial port" in done.stderr
    assert "ioctl" not in done.stderr and "(25" not in done.stderr


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_a_fifo_is_not_a_serial_port_and_is_not_opened(tmp_path):
    os.mkfifo(tmp_path / "port")
    done = _not_a_port(tmp_path / "port")
    assert done.returncode == 2 and "it is a FIFO (named pipe), not a serial port" in done.stderr


@pytest.mark.skipif(not os.path.exists("/dev/null"), reason="needs /dev/null")
def test_a_device_without_a_line_is_not_a_serial_port():
    done = _not_a_port("/dev/null")
    assert done.returncode == 2 and "it is a device, but not a serial port" in done.stderr
    assert "ioctl" not in done.stderr


def test_one_macro_is_one_macro_in_pull_and_in_the_flash_backup(tmp_path):
    program = tmp_path / "p.mcm"
    program.write_text("target C-863\n[MC05] MR5000\n")
    with serve(macros={3: "MR5"}) as (server, vc):
        flashed = cli("flash", server.path, program, "--backup", tmp_path / "b.mcm", *FAST)
        pulled = cli("pull", server.path, "--raw", *FAST)
    assert flashed.exit_code == 0, flashed.output
    assert f"backup of 1 stored macro: {tmp_path / 'b.mcm'}" in flashed.output
    assert "this backup holds" not in flashed.output
    assert pulled.exit_code == 0 and "read 2 macros from" in pulled.output
    with serve(macros={3: "MR5"}) as (server, vc):
        one = cli("pull", server.path, "-o", tmp_path / "one.mcm", *FAST)
        server.call(lambda _c: vc._define("MD7,MR7"))
        restored = cli("flash", server.path, tmp_path / "one.mcm", "--backup", tmp_path / "c.mcm",
                       *FAST)
    assert one.exit_code == 0 and "read 1 macro from" in one.output, one.output
    assert restored.exit_code == 0, restored.output
    assert "this backup holds 1 macro; the controller also holds MC07, which was kept" \
        in " ".join(restored.output.split())
