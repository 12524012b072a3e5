"""`mercmac emulate` as host libraries written for real controllers meet it.

Every check goes byte for byte over a real pseudo-terminal, and the pipelined ones send
their lines in ONE write, as drivers do (a query right after a move).
"""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import pytest

from helpers.cli import cli
from mercmac.compiler.program import Op
from mercmac.emulator.virtual import Faults
from mercmac.upload import protocol
from mercmac.vm import Machine, Options, reports
from helpers.emulator import (FAST, ROOM_S, HeldClock, basil_mercury, drain, eventually, raw_port, read_for,
                              serve, typed, until)

pytestmark = pytest.mark.skipif(not hasattr(os, "openpty"), reason="needs pseudo-terminals")

SELECT = b"\x010"  # 0x01 '0': address selection of address 0 (MS176E §3.1.3)
END = b"\r\n\x03"  # CR LF ETX after every report (MS176E §6.1.3)
OLD_VE = "(c)2003 Physik Instrumente(PI) Karlsruhe, C-862, Ver. 1.20, 2003-05-10"
PROGRAM = "target C-863\n[MC05] MR5000,WS100\n"


def replies(port, n: int, seconds: float = ROOM_S) -> list[bytes]:
    """The next n reports as they came, each with its CR LF ETX (fewer if they do not come)."""
    data, end = b"", time.monotonic() + seconds
    while data.count(b"\x03") < n and time.monotonic() < end:
        data += port.read(port.in_waiting or 1)
    return [part + b"\x03" for part in data.split(b"\x03")[:-1]]


def ask(port, data: bytes, n: int = 1) -> list[bytes]:
    port.write(data)
    return replies(port, n)


def status(port, data: bytes = b"TS\r") -> protocol.Status:
    (answer,) = ask(port, data)
    return protocol.parse_status(answer.decode("latin-1"))


# -- pipelined lines: nothing lost, answers in order ----------------------------------------

@pytest.mark.parametrize("write, expected", [
    (b"TB\rTP\r", [b"B:0", b"P:+0000000000"]),
    (b"SV50000\rTY\r", [b"Y:+0000050000"]),
    (b"MA10000\rTT\r", [b"T:+0000010000"]),
    (b"TT,TY,TL\rTB\r", [b"T:+0000000000", b"Y:+0000045000", b"L:+0000400000", b"B:0"]),
    (b"TP\r'", [b"P:+0000000000", b"P:+0000000000"]),  # ' is TP as one character (§6.3)
])
def test_lines_in_one_write_all_run_and_answer_in_order(write, expected):
    with serve() as (server, vc), raw_port(server) as port:
        assert ask(port, SELECT + write, len(expected)) == [e + END for e in expected]
        assert read_for(port, 0.05) == b""


def test_a_move_then_a_query_in_one_write_runs_the_move():
    with serve() as (server, vc), raw_port(server) as port:
        moving = status(port, SELECT + b"MA10000\rTS\r")
        assert not moving.blocks[0] & 0x04  # block 1 bit 2: not on target, the stage moves
        assert ask(port, b"TT\r") == [b"T:+0000010000" + END]


def test_a_single_character_command_answers_after_the_line_before_it():
    with serve() as (server, vc), raw_port(server) as port:
        first, second = ask(port, SELECT + b"TP\r%", 2)
        assert first.startswith(b"P:") and second.startswith(b"S:")
        answers = ask(port, b"TT,TP\r%", 3)
        assert [a[:2] for a in answers] == [b"T:", b"P:", b"S:"]


def test_a_hundred_lines_in_one_write_get_a_hundred_answers():
    with serve() as (server, vc), raw_port(server) as port:
        answers = ask(port, SELECT + b"TB\r" * 100, 100)
        assert answers == [b"B:0" + END] * 100


def test_a_line_that_waits_is_still_interrupted_by_the_next_character():
    # MS176E §6.1.1: any character stops a running compound command; WS waits for the move
    with serve() as (server, vc), raw_port(server) as port:
        assert ask(port, SELECT + b"MR100000,WS0,TB\rTY\r") == [b"Y:+0000045000" + END]
        assert read_for(port, 0.1) == b""  # TB never ran


# -- a stray ETX after the CR ----------------------------------------------------------------

def test_an_etx_after_each_cr_is_ignored():
    with serve(macros={3: "WA300,CN1"}) as (server, vc), raw_port(server) as port:
        assert ask(port, SELECT + b"TP\r\x03TT\r\x03", 2) == [b"P:+0000000000" + END,
                                                              b"T:+0000000000" + END]
        assert status(port, b"TS\r\x03").error == 0
        port.write(b"EM3\r\x03")  # the ETX must not stop the macro it just started
        assert until(server.served)  # both read
        assert eventually(server, lambda _c: vc.machine.macro == 3)


# -- TS: "macro running" and the error code -------------------------------------------------

def test_ts_typed_alone_is_not_a_running_macro_on_the_c863():
    with serve() as (server, vc), raw_port(server) as port:
        assert status(port, SELECT + b"TS\r").blocks[1] == 0x02  # busy only, §6.4 TS block 2


def test_ts_typed_alone_is_ready_and_on_target_on_the_c663():
    with serve(model="C-663") as (server, vc), raw_port(server) as port:
        # block 1: ready, on target, brake on (BN, §3.4.2); block 2: both limit lines high
        assert ask(port, SELECT + b"TS\r") == [b"S:43 05 00" + END]


@pytest.mark.parametrize("model, flags", [("C-863", 1), ("C-663", 0)])
def test_a_stored_macro_that_runs_is_reported(model, flags):
    with serve(model=model, macros={0: "SC0,WA5000"}) as (server, vc), raw_port(server) as port:
        running = status(port, b"%")  # SC0 selected it; % does not stop the macro (§6.3)
        assert running.macro_running and running.blocks[flags] & 0x10
        assert server.call(lambda _c: vc.machine.macro) == 0


@pytest.mark.parametrize("model", ["C-863", "C-663"])
@pytest.mark.parametrize("read", [b"TS\r", b"%"])
def test_reading_the_error_code_clears_it(model, read):
    with serve(model=model) as (server, vc), raw_port(server) as port:
        port.write(SELECT + b"XYZ\r")  # not a command: 06 (§6.4 TS)
        assert status(port, read).error == 0x06
        assert status(port, read).error == 0x00
        port.write(b"MA\r")  # a missing argument: 06 again, after it was cleared
        assert status(port, read).error == 0x06


# -- C-663 limit lines ---------------------------------------------------------------------

def test_c663_limit_bits_are_line_levels_high_when_active_low_switches_are_not_hit():
    with serve(model="C-663") as (server, vc), raw_port(server) as port:
        assert status(port, SELECT + b"TS\r").blocks[1] & 0x05 == 0x05  # LL, nothing hit
        assert status(port, b"LH\rTS\r").blocks[1] & 0x05 == 0x00  # LH, nothing hit


@pytest.mark.parametrize("model, block, negative, positive", [
    ("C-663", 1, 0x01, 0x04),  # block 2 bit 0 negative, bit 2 positive
    ("C-863", 4, 0x08, 0x04),  # block 5 bit 3 negative, bit 2 positive
])
def test_a_hit_limit_switch_drives_its_line_to_its_active_level(model, block, negative, positive):
    m = Machine(model=model, options=Options(hard_limits=(-100, 100)))
    m.execute_line([Op("MA", 1000)])
    m.run_until(5000)
    levels = protocol.parse_status(reports.status(m)).blocks[block] & (negative | positive)
    active_high = model == "C-863"  # LH on the C-863, LL on the C-663 (§3.4)
    assert levels == (positive if active_high else negative)  # only the positive switch is hit


# -- a VE without a model mercmac knows ------------------------------------------------------

def test_an_unknown_model_goes_on_as_the_files_target(tmp_path, program_file):
    with serve(faults=Faults(version=OLD_VE)) as (server, vc):
        result = cli("flash", server.path, program_file, "--backup", tmp_path / "b.mcm",
                     *FAST)
    assert result.exit_code == 0, result.output
    assert "C-862" in result.output and "going on as the C-863" in result.output
    assert vc.macros == {5: "MR5000,WS100"}


def test_an_unknown_model_goes_on_as_the_target_option(tmp_path):
    prog = tmp_path / "plain.mcm"
    prog.write_text("[MC05] MR5000,WS100\n")
    with serve(faults=Faults(version=OLD_VE)) as (server, vc):
        result = cli("flash", server.path, prog, "--target", "C-663", "--backup",
                     tmp_path / "b.mcm", *FAST)
    assert result.exit_code == 0, result.output
    assert "going on as the C-663" in result.output and vc.macros == {5: "MR5000,WS100"}


def test_an_unknown_model_without_any_target_is_refused_saying_what_ve_answered(tmp_path):
    prog = tmp_path / "plain.mcm"
    prog.write_text("[MC05] MR5000,WS100\n")
    with serve(faults=Faults(version=OLD_VE)) as (server, vc):
        result = cli("flash", server.path, prog, "--backup", tmp_path / "b.mcm",
                     *FAST)
        assert result.exit_code == 1, result.output
        assert "C-862, Ver. 1.20" in result.output and "--target" in result.output
        assert "nothing was written" in result.output and vc.md_count == 0


def test_pull_reads_a_controller_of_an_unknown_model(tmp_path):
    with serve(faults=Faults(version=OLD_VE), macros={5: "GH"}) as (server, vc):
        result = cli("pull", server.path, *FAST)
    assert result.exit_code == 0, result.output
    assert "[MC05] GH" in result.output and "\ntarget " not in result.output


@pytest.mark.parametrize("text, model, firmware", [
    (OLD_VE, None, "1.20"),
    ("(c)2004 Physik Instrumente(PI) Karlsruhe, Ver. 1.06", None, "1.06"),
    ("(c)2009 Physik Instrumente(PI) Karlsruhe, C-663, Ver. 2.30", "C-663", "2.30"),
])
def test_version_reports_with_and_without_a_known_model(text, model, firmware):
    v = protocol.parse_version(text)
    assert (v.model, v.firmware) == (model, firmware)


# -- pacing like real hardware --------------------------------------------------------------

def test_paced_bytes_arrive_at_the_baud_rate():
    with serve(faults=Faults(pace=True, baud=1200)) as (server, vc), raw_port(server) as port:
        start = time.monotonic()
        assert ask(port, SELECT + b"TB\r") == [b"B:0" + END]
        assert time.monotonic() - start >= 5 * 10 / 1200 * 0.9  # 5 bytes of 10 bits each


def test_paced_link_drops_a_line_typed_slower_than_20ms_whatever_the_firmware():
    clock = HeldClock()  # the gaps on the emulator's clock, whatever the load
    with serve(clock, faults=Faults(pace=True), firmware="2.30") as (server, vc), \
            raw_port(server) as port:
        port.write(SELECT)
        typed(server, port, b"TB\r", clock, 0.03)
        clock.release()  # real time from here: an answer, if any, would be paced out
        assert read_for(port) == b""
        assert status(port).error == 0x01  # §6.4 TS: 01 RS-232 timeout


def test_paced_link_loses_characters_typed_at_full_speed_during_a_move():
    clock = HeldClock()
    with serve(clock, faults=Faults(pace=True)) as (server, vc), raw_port(server) as port:
        typed(server, port, SELECT + b"MR200000\r", clock, 0)  # about 4.5 s at SV 45000
        clock.advance(0.05)
        typed(server, port, b"TT\r", clock, 0)  # at full speed: at one instant
        clock.advance(0.05)  # time for an answer to be paced out, if there were one
        assert read_for(port) == b""  # 'T' taken, the next one lost: "T" + CR, error 06
        assert server.call(lambda _c: vc.lost) >= 1
        typed(server, port, b"'", clock, 0.05)
        assert replies(port, 1)[0].startswith(b"P:")  # one character alone gets through
        typed(server, port, b"TT\r", clock, 0.005)  # slower than the receiver, faster than 20 ms
        clock.advance(0.05)
        assert replies(port, 1) == [b"T:+0000200000" + END]


# -- mercmac emulate --log FILE --pace ------------------------------------------------------

def command_line(*args: str) -> list[str]:
    return [sys.executable, "-m", "mercmac", *args]


def test_emulate_logs_every_byte_both_ways_with_times(tmp_path):
    import serial

    log = tmp_path / "wire.log"
    proc = subprocess.Popen(command_line("emulate", "--log", str(log), "--pace", "--baud", "19200"),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        banner = proc.stdout.readline()
        assert "paced at 19200 baud" in banner and str(log) in banner
        port = serial.serial_for_url(proc.stdout.readline().strip(), baudrate=19200, timeout=0.5)
        with port:
            assert ask(port, SELECT + b"TB\r") == [b"B:0" + END]
    finally:
        proc.send_signal(signal.SIGINT)
        assert proc.wait(timeout=5) == 130  # Ctrl-C, as `scan` and `sim --interactive`
    lines = log.read_text().splitlines()
    assert lines[0].startswith("# ")
    bytes_lines = [line for line in lines if not line.startswith("#")]
    sent = next(line for line in bytes_lines if " -> " in line)
    back = next(line for line in bytes_lines if " <- " in line)
    assert sent.split()[2:] == ["01", "30", "54", "42", "0d", "<01>0TB<CR>"]
    assert back.split()[2:] == ["42", "3a", "30", "0d", "0a", "03", "B:0<CR><LF><ETX>"]
    assert 0 <= float(sent.split()[0]) <= float(back.split()[0])


@pytest.mark.parametrize("kind", ["device", "fifo", "folder"])
def test_emulate_refuses_a_log_that_is_not_a_regular_file(tmp_path, kind):
    if kind == "device":
        path = "/dev/null"
    elif kind == "fifo":
        path = tmp_path / "pipe"
        os.mkfifo(path)
    else:
        path = tmp_path
    proc = subprocess.run(command_line("emulate", "--log", str(path)), capture_output=True,
                          text=True, timeout=20)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    assert "Traceback" not in proc.stderr and "/dev/pts" not in proc.stdout


# -- a real host library: basil-daq's Mercury driver over its pyserial transport ------------

@pytest.mark.slow
@pytest.mark.parametrize("write_termination", ["", "\x03"])  # "\x03": basil's default, an ETX
def test_basil_daq_mercury_driver(write_termination):
    with serve() as (server, vc):
        with basil_mercury(server, write_termination) as dut:
            mercury = dut["Mercury"]
            assert 0 in mercury._board_numbers
            drain(dut["Serial"]._port)  # the second TB's answer, if basil has not read it
            assert mercury.get_board_number(0) == "B:0\r\n\x03"
            assert mercury.get_position(0) == 0
            mercury.motor_on(0)
            mercury.set_position(5000, board_number=0)  # MN and MA5000 right before the TS
            state = protocol.parse_status(mercury.get_channel(0))
            assert not state.blocks[0] & 0x04 and state.error == 0  # moving, nothing refused
            mercury.set_position(3000, board_number=0, wait=True)  # polls TP until it stays
            assert mercury.get_position(0) == 3000
            mercury.abort(0)
        assert eventually(server, lambda _c: {"MN", "MA5000", "TS", "MA3000", "AB"} <= set(vc.lines))
