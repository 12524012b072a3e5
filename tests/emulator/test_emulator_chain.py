"""`mercmac emulate --addresses`: a daisy chain of virtual controllers on ONE pty.

MS176E §3.2: every controller hears every byte; only the selected one answers; a deselected
one ignores everything but address selection codes (`\\x01` + one hex digit, §3.1.1, §3.1.3)
while its macros keep running. Every check goes over a real pseudo-terminal.
"""
from __future__ import annotations

import json
import os
import time
from contextlib import contextmanager

import pytest
import serial

from helpers.cli import cli
from helpers.emulator import ROOM_S, basil_mercury, drain, emulating, eventually, raw_port, read_for
from mercmac.emulator import chain
from mercmac.emulator.ptyserver import PtyServer
from mercmac.emulator.virtual import StateError, VirtualController
from mercmac.upload.protocol import select

pytestmark = pytest.mark.skipif(not hasattr(os, "openpty"), reason="needs pseudo-terminals")

END = b"\r\n\x03"  # CR LF ETX after every report (MS176E §6.1.3)


@contextmanager
def served(*controllers: VirtualController, log=None):
    with PtyServer(chain.Chain(controllers), log) as server:
        yield server, server.chain


def answers(port, data: bytes, n: int = 1, seconds: float = ROOM_S) -> list[bytes]:
    port.write(data)
    got, end = b"", time.monotonic() + seconds
    while got.count(b"\x03") < n and time.monotonic() < end:
        got += port.read(port.in_waiting or 1)
    return [part + b"\x03" for part in got.split(b"\x03")[:-1]]


def test_each_address_answers_only_when_selected():
    with served(VirtualController(address=0), VirtualController(address=1),
                VirtualController(address=11)) as (server, _), raw_port(server) as port:
        port.write(b"TB\r")
        assert read_for(port, 0.3) == b""  # after power-on nobody is selected (§3.1)
        assert answers(port, select(1) + b"TB\r") == [b"B:1" + END]
        assert answers(port, select(0) + b"TB\r") == [b"B:0" + END]
        assert answers(port, select(11) + b"TB\r") == [b"B:11" + END]  # 'B': address 11
        port.write(select(5) + b"TB\r")
        assert read_for(port, 0.3) == b""  # no controller at 5: silence


def test_a_deselected_controller_ignores_commands_and_its_macro_keeps_running():
    x, y = VirtualController(address=0), VirtualController(address=1, macros={
        1: "MR3000,WS20,MR-3000,WS20,RP"})  # back and forth for ever
    with served(x, y) as (server, _), raw_port(server) as port:
        port.write(select(1) + b"EM1\r" + select(0) + b"MA777\r")  # MA: x, and y runs on
        assert eventually(server, lambda c: c.by_address(0).machine.target == 777)
        seen = set()
        end = time.monotonic() + ROOM_S
        while len(seen) < 5 and time.monotonic() < end:  # y moves while x is selected
            seen.add(server.call(lambda c: c.by_address(1).machine.position()))
            time.sleep(0.02)
        assert len(seen) >= 5 and server.call(lambda c: c.by_address(1).machine.macro) == 1
        assert server.call(lambda c: c.by_address(1).machine.target) != 777  # MA777 was x's
        assert answers(port, b"TT\r") == [b"T:+0000000777" + END]
        assert answers(port, select(1) + b"%")[0].startswith(b"S:")  # % leaves it running
        assert server.call(lambda c: c.by_address(1).machine.macro) == 1


def test_a_report_a_deselected_macro_makes_is_not_sent():
    x, y = VirtualController(address=0), VirtualController(address=1, macros={
        1: "WA300,TP,RP"})  # reports its position every 300 ms, selected or not
    with served(x, y) as (server, _), raw_port(server) as port:
        port.write(select(1) + b"EM1\r" + select(0))  # deselected before its first TP
        assert read_for(port, 0.7) == b""  # §3.2: reports of a deselected one are not issued
        assert server.call(lambda c: c.by_address(1).machine.macro) == 1
        port.write(select(1))
        assert answers(port, b"", 2) == [b"P:+0000000000" + END] * 2


def test_the_log_says_which_controller_was_selected_and_who_answered(tmp_path):
    log_path = tmp_path / "emu.log"
    with open(log_path, "w", buffering=1) as log, \
            served(VirtualController(address=0), VirtualController(address=1), log=log) \
            as (server, _), raw_port(server) as port:
        assert answers(port, select(1) + b"TB\r") == [b"B:1" + END]
        assert answers(port, select(0) + b"TB\r") == [b"B:0" + END]
    text = log_path.read_text()
    assert "chain of C-863 at 0, C-863 at 1" in text
    assert "[selected: 1]" in text and "[from 1]" in text
    assert "[selected: 0]" in text and "[from 0]" in text


def test_two_self_selected_controllers_are_a_collision_in_the_log(tmp_path):
    # §3.1.2: SC in macro 0 "can not be used with networked controllers": both would talk
    log_path = tmp_path / "emu.log"
    with open(log_path, "w", buffering=1) as log, \
            served(VirtualController(address=0, macros={0: "SC0"}),
                   VirtualController(address=1, macros={0: "SC1"}), log=log) \
            as (server, _), raw_port(server) as port:
        assert len(answers(port, b"TB\r", 2)) == 2
    assert "several controllers answered at once" in log_path.read_text()


def test_rt_deselects_the_controller_as_power_on_does():
    # §3.1: "After power-on or reset, a Mercury controller is not addressed (deselected)";
    # §6.4 RT restarts it "as if from a power-off condition"
    with served(VirtualController(address=0), VirtualController(address=1)) as (server, _), \
            raw_port(server) as port:
        port.write(select(1) + b"RT\rTB\r")
        assert read_for(port, 0.3) == b""  # the TB after the RT finds nobody selected
        assert server.call(lambda c: [vc.selected for vc in c.controllers]) == [False, False]
        port.write(b"\r")
        assert read_for(port, 0.3) == b""  # nor does a bare CR repeat the RT or the TB
        assert answers(port, select(1) + b"TB\r") == [b"B:1" + END]  # selected again


@pytest.mark.parametrize("macro_0, heard", [
    ("WA5,TP", []),  # macro 0 runs after the RT, its report suppressed (§5.1)
    ("SC3,TP", [b"P:+0000000000" + END]),  # §3.1.2: SC in macro 0 selects it at power-on
])
def test_rt_on_a_single_controller_deselects_it_unless_macro_0_selects_it(macro_0, heard):
    with served(VirtualController(address=3, macros={0: macro_0})) as (server, _), \
            raw_port(server) as port:
        port.write(select(3) + b"AB\r")  # AB: its macro 0 stops, but selection stays
        assert eventually(server, lambda c: not c.by_address(3).running)
        read_for(port, 0.3)  # what macro 0 said at power-on, if it was selected
        port.write(b"RT\r")
        assert eventually(server, lambda c: c.by_address(3).lines[-1] == "RT")
        assert read_for(port, 0.5) == b"".join(heard)
        assert server.call(lambda c: c.by_address(3).selected) == bool(heard)


def test_a_chain_needs_distinct_addresses():
    with pytest.raises(ValueError, match="distinct"):
        chain.Chain([VirtualController(address=1), VirtualController(address=1)])


# -- the command line ------------------------------------------------------------------------

@pytest.mark.parametrize("value, why", [
    ("0,x", "comma-separated"), ("0,16", "not 0-15"), ("1,1", "twice"), ("", "comma")])
def test_bad_addresses_are_refused(value, why):
    result = cli("emulate", "--addresses", value, catch=True)
    assert result.exit_code == 2 and why in result.output


def test_address_and_addresses_together_are_refused():
    result = cli("emulate", "--addresses", "0,1", "--address", "3", catch=True)
    assert result.exit_code == 2 and "--addresses and --address" in result.output


def test_emulate_addresses_keeps_one_state_file_per_controller(tmp_path):
    state = tmp_path / "flash"
    with emulating("--addresses", "0,2", "--state", str(state), "--target", "C-663") \
            as (first, path):
        assert "virtual chain" in first
        assert "C-663 at address 0" in first and "C-663 at address 2" in first
        port = serial.serial_for_url(path, baudrate=9600, timeout=0.3)
        try:
            port.write(select(2) + b"MD5,MR100\r" + select(0) + b"MD7,TP\r")
            assert answers(port, b"TZ\r")  # a reply: both MD lines are read by now
        finally:
            port.close()
    assert json.loads((state / "2.json").read_text())["macros"] == {"5": "MR100"}
    assert json.loads((state / "0.json").read_text())["macros"] == {"7": "TP"}


def test_a_state_file_for_a_chain_is_refused(tmp_path):
    (tmp_path / "one.json").write_text("{}")
    with pytest.raises(StateError, match="folder"):
        chain.at_addresses([0, 1], "C-863", state=tmp_path / "one.json")


@pytest.mark.slow
@pytest.mark.parametrize("write_termination", ["", "\x03"])  # "\x03": basil's default, an ETX
def test_basil_daq_addresses_two_boards_on_one_port(write_termination):
    with served(VirtualController(address=0), VirtualController(address=1)) as (server, c), \
            basil_mercury(server, write_termination) as dut:
        mercury = dut["Mercury"]
        assert {0, 1} <= set(mercury._board_numbers)
        drain(dut["Serial"]._port)  # the second TBs' answers, if basil has not read them
        assert mercury.get_board_number(0) == "B:0\r\n\x03"
        assert mercury.get_board_number(1) == "B:1\r\n\x03"
        mercury.motor_on(0)
        mercury.motor_on(1)
        mercury.set_position(400, board_number=0)
        mercury.set_position(-900, board_number=1)
        assert eventually(server, lambda c: (c.by_address(0).machine.position(),  # both move
                                             c.by_address(1).machine.position()) == (400, -900))
        assert mercury.get_position(0) == 400
        assert mercury.get_position(1) == -900
