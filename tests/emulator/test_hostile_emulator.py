"""The emulator loses nothing, never hangs, never dies."""
from __future__ import annotations

import json
import os
import re
import subprocess
import sys

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mercmac.commands import COMMANDS, Arg
from mercmac.upload import protocol
from mercmac.emulator.virtual import MAX_LINE, StateError, VirtualController
from helpers.budgets import budget
from helpers.emulator import raw_port, read_for, serve

SELECT = b"\x010"  # 0x01 '0': address selection of address 0
STORED = {0: "EM3", 3: "MR5,WS100", 12: "XN1,CN2"}
OUT_OF_RANGE = ["XN99", "CN0", "CF0", "FE9", "WN99", "WF7", "TA99", "TC99", "EM0", "EM32",
                "RP40000", "MA9999999999", "TM99", "RM-1", "TP5", "MR"]
ROOT = os.geteuid() == 0 if hasattr(os, "geteuid") else False
needs_pty = pytest.mark.skipif(not hasattr(os, "openpty"), reason="needs pseudo-terminals")


class Session:
    """A VirtualController fed directly, on a clock that moves 1 ms per exchange."""

    def __init__(self, macros=STORED, **kw):
        self.vc = VirtualController(macros=dict(macros), **kw)
        self.now = 0.0
        self.send(SELECT)

    def send(self, data: bytes) -> bytes:
        self.vc.receive(data, self.now)
        for _ in range(20):  # bytes after a line wait until its commands ran (up to 17 cycles)
            self.now += 0.002  # a command takes a cycle: its report comes on the next tick
            self.vc.tick(self.now)
            if not self.vc.waiting:
                break
        return self.vc.take()

    def ask(self, line: str) -> str:
        return self.send(line.encode() + b"\r").decode("latin-1")

    def error(self) -> int:
        return protocol.parse_status(self.ask("TS")).error

    def alive(self) -> bool:
        return "Physik Instrumente" in self.ask("VE")


# -- item 11: out-of-range arguments --------------------------------------------------------

@pytest.mark.parametrize("line", OUT_OF_RANGE)
def test_an_out_of_range_argument_is_error_06_and_the_controller_goes_on(line):
    s = Session()
    s.send(b"RT\r" + SELECT)  # power-on, as after RT: deselected until addressed again
    s.ask(line)
    assert s.error() == 0x06
    assert s.alive()
    assert s.vc.macros == STORED


@pytest.mark.parametrize("body", ["XN99", "CN0", "FE9", "WN99", "EM0", "TP,CN5", "RP40000"])
def test_an_md_line_with_an_out_of_range_argument_is_refused(body):
    s = Session()
    s.ask(f"MD7,{body}")
    assert s.error() == 0x05  # MS176E §6.4 TS: 05 macro wrong command
    assert 7 not in s.vc.macros
    s.ask("EM7")
    assert s.alive() and s.vc.macros == STORED


def test_a_bug_in_command_handling_is_error_06_not_a_dead_controller(monkeypatch):
    s = Session()

    def broken(ops):
        raise RuntimeError("a bug")

    monkeypatch.setattr(s.vc.machine, "execute_line", broken)
    s.ask("TP")
    monkeypatch.undo()
    assert s.error() == 0x06 and s.alive() and s.vc.macros == STORED


def test_a_bug_while_a_macro_runs_stops_the_macro_not_the_controller(monkeypatch):
    s = Session()
    monkeypatch.setattr(s.vc.machine, "step", lambda: (_ for _ in ()).throw(KeyError("bug")))
    s.ask("EM3")
    monkeypatch.undo()
    assert not s.vc.running and s.error() == 0x06 and s.alive()


# -- item 8: the command buffer -------------------------------------------------------------

def test_a_line_without_cr_does_not_grow_the_buffer():
    s = Session(macros={})
    for _ in range(64):
        s.send(b"MR5" + b"0" * 16_384)  # a megabyte without CR
    assert len(s.vc._line) <= MAX_LINE
    s.send(b"\r")  # the overflowing line is dropped, not executed
    assert s.error() == 0x02  # MS176E §6.4 TS: 02 RS-232 overflow
    assert s.ask("TT") == "T:+0000000000\r\n\x03"
    assert s.alive()


def test_a_bare_cr_after_an_overflow_repeats_nothing():
    s = Session(macros={})
    s.ask("MR5")
    s.send(b"MR7" + b"0" * (2 * MAX_LINE) + b"\r")
    s.send(b"\r")
    assert s.ask("TT") == "T:+0000000005\r\n\x03"


def test_the_longest_legal_md_line_fits_the_buffer():
    longest = max((c for c in COMMANDS.values() if c.storable and c.arg is Arg.REQUIRED),
                  key=lambda c: len(f"{c.mnemonic}{c.lo}"))
    token = f"{longest.mnemonic}{longest.lo}"
    line = "MD31," + ",".join([token] * 16)
    s = Session()
    s.ask(line)
    assert s.error() == 0 and s.vc.macros[31] == ",".join([token] * 16)
    assert len(line) <= MAX_LINE


# -- the property: random input never kills it, never loses a macro -------------------------

_COMMAND_LINES = st.sampled_from(
    ["TP", "TS", "VE", "TM", "TZ", "TM3", "MR100", "MA-5", "WA5", "CN1", "CF2", "CP15", "AB",
     "AB1", "GH", "DH5", "FE1", "TA", "TC", "XN1", "XF2,TP", "EM3", "EM12", "RP2", "JN2000",
     "JF", "MF", "MN", "ST", "SV100", "JH10", "JC", "TI", "tp", "m r 5", "DI,", "RT"]
    + OUT_OF_RANGE)
_FORBIDDEN = ("MD", "RM", "RZ")  # the only commands that may change what is stored


def _chunks():
    garbage = st.binary(min_size=0, max_size=40)
    numbers = st.builds(lambda m, n: f"{m}{n}", st.sampled_from(sorted(COMMANDS)),
                        st.integers(-10**12, 10**12))
    text = st.one_of(_COMMAND_LINES, numbers).map(lambda t: t.encode() + b"\r")
    long_line = st.integers(MAX_LINE - 2, 4 * MAX_LINE).map(lambda n: b"5" * n)
    return st.one_of(text, garbage, long_line, st.sampled_from([b"\r", b"%", b"!", b"\x01", b"\\"]))


@settings(max_examples=budget(60), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(_chunks(), min_size=1, max_size=25))
def test_random_input_never_kills_it_and_keeps_the_macros(chunks):
    s = Session()
    for chunk in chunks:
        s.send(chunk)
    s.send(b"\r\x010")  # end whatever line was left open, select it again
    # what the controller makes of the bytes: upper case, blanks, NUL and LF dropped
    sent = re.sub(r"[\s\x00]+", "", b"".join(chunks).decode("latin-1").upper())
    if not any(word in sent for word in _FORBIDDEN):
        assert s.vc.macros == STORED
    assert s.alive()


# -- over a real pty ---------------------------------------------------------------------------

@needs_pty
def test_over_a_pty_bad_arguments_and_endless_lines_leave_it_serving():
    with serve(macros=dict(STORED)) as (server, vc), raw_port(server) as port:
        # RT deselects (MS176E §3.1), so the host selects the controller again after it
        port.write(SELECT + b"RT\r" + SELECT + b"XN99\rCN0\rMD7,XN99\rEM7\r")
        port.write(b"MR5" + b"0" * 100_000)
        port.write(b"\rTS\r")
        assert protocol.parse_status(read_for(port, 0.5).decode()).error == 0x02
        port.write(b"VE\r")
        assert b"Physik Instrumente" in read_for(port, 0.3)
        assert server.call(lambda _c: (vc.macros, len(vc._line))) == (STORED, 0)


@needs_pty
def test_the_serve_loop_survives_an_exception():
    with serve(macros=dict(STORED)) as (server, vc), raw_port(server) as port:
        calls = []
        real = vc.tick

        def flaky(now):
            calls.append(now)
            if len(calls) == 3:
                raise RuntimeError("a bug in tick")
            real(now)

        server.call(lambda _c: setattr(vc, "tick", flaky))
        port.write(SELECT + b"VE\r")
        assert b"Physik Instrumente" in read_for(port, 0.3)
        assert len(calls) > 3


# -- item 2: the --state file ----------------------------------------------------------------

def emulate(*args: str, timeout: float = 10) -> subprocess.CompletedProcess:
    """`mercmac emulate` as a process; a refusal ends it, a start would be killed by the timeout."""
    return subprocess.run([sys.executable, "-m", "mercmac", "emulate", *args],
                          capture_output=True, text=True, timeout=timeout)


GOOD = {"model": "C-863", "macros": {"3": "MR5,WS100", "0": "EM3"}}


@pytest.mark.parametrize("content, why", [
    ('{"model": "C-863", "macros": {"3": "MR5,WS', "not valid JSON"),
    ("", "not valid JSON"),
    (json.dumps({**GOOD, "extra": 1}), "unknown key 'extra'"),
    (json.dumps({"model": "C-863", "macros": ["MR5"]}), "macros"),
    (json.dumps({"model": "C-863", "macros": {"40": "TP"}}), "'40'"),
    (json.dumps({"model": "C-863", "macros": {"3": "XN99"}}), "macro 3"),
    (json.dumps({"model": "C-863", "macros": {"3": ",".join(["TP"] * 17)}}), "macro 3"),
    (json.dumps({"model": "C-863", "macros": {"3": 5}}), "macro 3"),
    (json.dumps({"model": "C-663", "macros": {}}), "C-663"),
    ('{"macros": {"3": "TP", "3": "GH"}}', "'3' appears twice"),
])
def test_a_state_file_it_cannot_read_is_refused_and_left_alone(tmp_path, content, why):
    state = tmp_path / "flash.json"
    state.write_text(content)
    result = emulate("--state", str(state))
    assert result.returncode == 2, result.stdout + result.stderr
    assert str(state) in result.stderr and why in result.stderr
    assert "Traceback" not in result.stderr
    assert state.read_text() == content


def test_a_state_file_in_a_missing_folder_is_refused_up_front(tmp_path):
    state = tmp_path / "nowhere" / "flash.json"
    result = emulate("--state", str(state))
    assert result.returncode == 2 and str(state) in result.stderr
    assert "does not exist" in result.stderr and ".mercmac-" not in result.stderr
    assert not state.parent.exists()


@pytest.mark.skipif(ROOT, reason="root may write anywhere")
def test_a_state_file_in_an_unwritable_folder_is_refused_up_front(tmp_path):
    folder = tmp_path / "ro"
    folder.mkdir()
    state = folder / "flash.json"
    state.write_text(json.dumps(GOOD))
    folder.chmod(0o500)
    try:
        result = emulate("--state", str(state))
    finally:
        folder.chmod(0o700)
    assert result.returncode == 2 and str(state) in result.stderr
    assert state.read_text() == json.dumps(GOOD)


def test_a_state_file_that_is_a_folder_is_refused(tmp_path):
    with pytest.raises(StateError, match="folder"):
        VirtualController(state=tmp_path)


def test_lower_case_entries_are_read_as_the_controller_would(tmp_path):
    state = tmp_path / "flash.json"
    state.write_text(json.dumps({"model": "C-863", "macros": {"3": "mr 5, ws100", "0": "em3"}}))
    vc = VirtualController(state=state)
    assert vc.macros == {0: "EM3", 3: "MR5,WS100"}


def test_a_state_that_cannot_be_saved_keeps_the_old_macros_and_says_so(tmp_path, caplog):
    state = tmp_path / "flash.json"
    state.write_text(json.dumps(GOOD))
    s = Session(state=state)
    state.unlink()
    state.mkdir()  # now a folder: the next save must fail
    s.ask("MD5,TP")
    assert s.error() == 0x03  # MS176E §6.4 TS: 03 macro storage full
    assert 5 not in s.vc.macros and s.alive()
    assert str(state) in caplog.text
