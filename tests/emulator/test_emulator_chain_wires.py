"""`mercmac emulate --rig RIG`: the rig's wires live between emulated controllers.

An output line of one controller drives the wired input of another as it changes (§4.5.1:
"interaxis communication" through I/O lines), so a host sees the coordinated motion. Every
check goes over a real pseudo-terminal.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest
import serial

from helpers.cli import cli
from helpers.emulator import ROOM_S, emulating, eventually, raw_port
from helpers.paths import ROOT
from mercmac.emulator import chain
from mercmac.emulator.ptyserver import PtyServer
from mercmac.emulator.virtual import VirtualController
from mercmac.rig.load import read_rig
from mercmac.upload.protocol import select

pytestmark = pytest.mark.skipif(not hasattr(os, "openpty"), reason="needs pseudo-terminals")

END = b"\r\n\x03"  # CR LF ETX after every report (MS176E §6.1.3)
RASTER = ROOT / "examples" / "rigs" / "raster" / "raster.rig.toml"
# a handshake as the raster example's: X moves, raises out1, waits for Y's out2 on in2
X_LOOP = "MR1000,WS10,CN1,WN2,CF1,WF2,RP"
Y_LOOP = "WN1,MR500,WS10,CN2,WF1,CF2,RP"
RIG = """
wires = ["x.out1 -> y.in1", "y.out2 -> x.in2"]
[controllers.x]
address = 0
model = "C-863"
program = "x.mcm"
[controllers.y]
address = 1
model = "C-863"
program = "y.mcm"
"""


def position(port, address: int) -> int:
    port.reset_input_buffer()
    port.write(select(address) + b"'")  # ' is TP as one character: a macro runs on (§6.3)
    got, end = b"", time.monotonic() + ROOM_S
    while not got.endswith(END) and time.monotonic() < end:
        got += port.read(port.in_waiting or 1)
    assert got.startswith(b"P:") and got.endswith(END), got
    return int(got[2:-3])


def rig_at(tmp_path: Path, text: str = RIG) -> Path:
    for name in ("x", "y"):
        (tmp_path / f"{name}.mcm").write_text("target C-863\n")
    path = tmp_path / "two.rig.toml"
    path.write_text(text)
    return path


def the_rig(path: Path):
    rig_file = read_rig(str(path))
    assert rig_file.rig is not None, [d.message for d in rig_file.report.items]
    return rig_file.rig


def start(port) -> None:
    """Y waits for X's line first; then X starts (each told while selected, §3.2)."""
    port.write(select(1) + f"MD1,{Y_LOOP}\rEM1\r".encode()
               + select(0) + f"MD1,{X_LOOP}\rEM1\r".encode())


def test_an_output_of_one_controller_moves_the_other(tmp_path):
    with PtyServer(chain.for_rig(the_rig(rig_at(tmp_path)))) as server, raw_port(server) as port:
        start(port)
        assert eventually(server, lambda c: c.by_address(1).machine.position() >= 1000)
        x, y = position(port, 0), position(port, 1)
        assert x >= 1000 and y >= 500
        assert abs(x // 1000 - y // 500) <= 1  # lock-step: one row per line, never ahead
        assert server.call(lambda c: c.by_address(1).machine.macro) == 1


def test_without_the_wires_the_other_one_never_moves(tmp_path):
    path = rig_at(tmp_path, RIG.replace('wires = ["x.out1 -> y.in1", "y.out2 -> x.in2"]', ""))
    with PtyServer(chain.for_rig(the_rig(path))) as server, raw_port(server) as port:
        start(port)
        assert eventually(server, lambda c: c.by_address(0).machine.outputs_pattern() == 1)
        time.sleep(0.1)
        assert position(port, 1) == 0 and position(port, 0) == 1000  # X waits for ever on in2


def test_a_wired_input_follows_its_output_in_the_same_step():
    # a pulse shorter than the server's tick (2 ms) still reaches the other controller
    x, y = VirtualController(address=0), VirtualController(address=1)
    c = chain.Chain([x, y], [chain.Wiring(x, 1, y, 3)])
    c.receive(select(1) + b"MD2,WN3,MR777\rEM2\r", 0.0)
    c.tick(0.02)  # y waits on input 3 by now
    c.receive(select(0) + b"CN1,CF1\r", 0.02)  # on for one cycle (1 ms) only
    c.tick(0.05)
    assert y.machine.target == 777 and y.machine.input(3) is False


# -- the command line ------------------------------------------------------------------------



def build(path: Path) -> list[str]:
    done = subprocess.run([sys.executable, "-m", "mercmac", "build", str(path)],
                          capture_output=True, text=True, timeout=30, check=True)
    return done.stdout.split()


@pytest.mark.slow
def test_the_raster_rig_flashed_and_started_scans_on_both_axes(tmp_path):
    log = tmp_path / "emu.log"
    with emulating("--rig", str(RASTER), "--state", str(tmp_path / "flash"),
                   "--log", str(log)) as (first, path):
        assert "C-663 at address 0 (x)" in first and "C-663 at address 1 (y)" in first
        port = serial.serial_for_url(path, baudrate=9600, timeout=0.3)
        try:
            for address, name in ((0, "x"), (1, "y")):
                lines = build(RASTER.parent / f"{name}.mcm")
                port.write(select(address) + "".join(f"{line}\r" for line in lines).encode())
            # y is reset and runs its autostart (waits for a line, §6.4 RT); x, whose box is
            # not plugged in, is told what its autostart sets and starts its scan, macro 3
            port.write(select(1) + b"RT\r" + select(0) + b"SV20000,SA200000\rEM3\r")
            end, rows = time.monotonic() + ROOM_S, 0
            while rows < 1000 and time.monotonic() < end:
                time.sleep(0.2)
                rows = position(port, 1)  # Y stepped a row per line of X
            assert rows >= 1000 and position(port, 0) in range(0, 20001)
        finally:
            port.close()
    text = log.read_text()
    assert "[selected: 1 (y)]" in text and "[from 0 (x)]" in text
    assert json.loads((tmp_path / "flash" / "y.json").read_text())["macros"]["1"].startswith("WN1")


@pytest.mark.parametrize("old, new, why", [
    ("address = 1", "adress = 1", "two.rig.toml:8:1: error[MR001 rig-file]"),
    ("address = 1", "address = 0", "two.rig.toml:8:1: error[MR005 address-repeated]"),
    ("address = 1", "address = 16", "two.rig.toml:8:1: error[MR004 address-range]"),
])
def test_a_rig_that_cannot_be_a_chain_is_refused_with_its_place(tmp_path, old, new, why):
    path = rig_at(tmp_path, RIG.replace(old, new))
    proc = subprocess.run([sys.executable, "-m", "mercmac", "emulate", "--rig", str(path)],
                          capture_output=True, text=True, timeout=20)
    # exit 1, as `sim FILE` with errors and `check` (docs/rigs.md: refused as `check` refuses it)
    assert proc.returncode == 1 and why in proc.stderr and "Traceback" not in proc.stderr
    assert "nothing is served" in proc.stderr


def test_a_rig_whose_program_does_not_exist_is_refused_as_check_refuses_it(tmp_path):
    """The emulated controllers start empty, but a rig `check` refuses is not served
    (docs/rigs.md): one rig, one answer."""
    path = rig_at(tmp_path)
    (tmp_path / "x.mcm").unlink()
    result = cli("emulate", "--rig", path, catch=True)
    assert result.exit_code == 2 and "error[MR002 rig-program]" in result.stderr
    assert "nothing is served" in result.stderr and not result.stdout


def test_an_input_two_outputs_drive_is_on_while_either_is():
    # `check` refuses such a rig (MR008 input-driven-twice); served anyway, the input never toggles in between
    x, y = VirtualController(address=0), VirtualController(address=1)
    c = chain.Chain([x, y], [chain.Wiring(x, 1, y, 2), chain.Wiring(x, 2, y, 2)])
    c.receive(select(0) + b"CN1\r", 0.0)
    c.tick(0.01)
    assert y.machine.input(2) is True
    c.receive(b"CN2,CF1\r", 0.02)
    c.tick(0.03)
    assert y.machine.input(2) is True
    c.receive(b"CF2\r", 0.04)
    c.tick(0.05)
    assert y.machine.input(2) is False


def test_rig_and_target_together_are_refused(tmp_path):
    result = cli("emulate", "--rig", rig_at(tmp_path), "--target", "C-663", catch=True)
    assert result.exit_code == 2 and "--target and --rig" in result.output


def test_a_rig_state_file_is_named_in_its_folder_never_a_path(tmp_path):
    """Defence in depth: a Rig built in the library with a path for a
    controller's name keeps no state outside the --state folder."""
    from dataclasses import replace as changed

    from mercmac.emulator.chain import for_rig
    from mercmac.outfile import OutputError
    from mercmac.rig.load import read_rig
    from helpers.rigs import RASTER

    rig = read_rig(str(RASTER)).rig
    hostile = changed(rig, controllers=(changed(rig.controllers[0], name="../../escaped"),
                                        rig.controllers[1]))
    with pytest.raises(OutputError, match="no plain file name"):
        for_rig(hostile, state=tmp_path / "state")
    assert not list(tmp_path.rglob("*escaped*"))
