"""The virtual controller over a real pseudo-terminal (its helpers: tests/helpers/emulator.py)."""
from __future__ import annotations

import os

import pytest

from mercmac.upload import protocol
from mercmac.emulator.virtual import Faults
from helpers.emulator import HeldClock, eventually, raw_port, read_for, serve, typed

pytestmark = pytest.mark.skipif(not hasattr(os, "openpty"), reason="needs pseudo-terminals")


def test_deselected_at_power_on_until_the_address_code_comes():
    with serve(macros={3: "MR5"}) as (server, vc), raw_port(server) as port:
        port.write(b"VE\r")
        assert read_for(port) == b""
        port.write(b"\x010" + b"TM3\r")  # 0x01 '0': address selection
        assert read_for(port) == b"MC003 MR5\r\n\x03"


@pytest.mark.parametrize("address", range(10, 16))
def test_addresses_a_to_f(address):
    with serve(address=address) as (server, vc), raw_port(server) as port:
        port.write(b"\x01" + bytes([ord("A") + address - 10]) + b"TB\r")
        assert read_for(port) == f"B:{address}\r\n\x03".encode()
        port.write(b"\x010TB\r")  # another address deselects it (MS176E §3.1)
        assert read_for(port) == b""


def test_a_bare_cr_repeats_the_previous_line():
    with serve(macros={1: "GH"}) as (server, vc), raw_port(server) as port:
        port.write(b"\x010TM1\r")
        port.write(b"\r")
        assert read_for(port) == b"MC001 GH\r\n\x03" * 2


def test_md_is_silent_and_overwrites():
    with serve(macros={4: "GH"}) as (server, vc), raw_port(server) as port:
        port.write(b"\x010md4, mr 5000,ws100\r")
        assert read_for(port) == b""
        assert vc.macros[4] == "MR5000,WS100"


def test_firmware_1_drops_a_line_typed_slower_than_20ms_per_character():
    clock = HeldClock()  # 30 ms between the bytes on the emulator's clock, whatever the load
    with serve(clock, firmware="1.06", macros={2: "GH"}) as (server, vc), raw_port(server) as port:
        port.write(b"\x010")
        typed(server, port, b"TM2\r", clock, 0.03)
        assert read_for(port) == b""
        port.write(b"TM2\r")  # in one write, as the uploader sends lines
        assert read_for(port) == b"MC002 GH\r\n\x03"


def test_firmware_2_accepts_slow_typing():
    clock = HeldClock()
    with serve(clock, firmware="2.30", macros={2: "GH"}) as (server, vc), raw_port(server) as port:
        port.write(b"\x010")
        typed(server, port, b"TM2\r", clock, 0.03)
        assert read_for(port) == b"MC002 GH\r\n\x03"


@pytest.mark.parametrize("framing, expected", [
    ("etx-per-line", b"MC001 GH\r\n\x03MC002 TP\r\n\x03"),
    ("one-etx", b"MC001 GH\r\nMC002 TP\r\n\x03"),
])
def test_both_listing_framings(framing, expected):
    with serve(macros={0: "EM1", 1: "GH", 2: "TP"}, faults=Faults(tm_framing=framing)) as (server, vc), \
            raw_port(server) as port:
        port.write(b"\x010TM\r")
        assert read_for(port) == expected


@pytest.mark.parametrize("empty, expected", [("empty", b"\r\n\x03"), ("bare", b"MC007\r\n\x03")])
def test_both_empty_slot_answers(empty, expected):
    with serve(faults=Faults(empty_slot=empty)) as (server, vc), raw_port(server) as port:
        port.write(b"\x010TM7\r")
        assert read_for(port) == expected


def test_status_by_its_single_character_and_error_codes():
    with serve() as (server, vc), raw_port(server) as port:
        port.write(b"\x010XYZ\r")  # not a command: error 06 (MS176E §6.4 TS)
        port.write(b"%")
        status = protocol.parse_status(read_for(port).decode())
        assert (status.layout, status.error, status.macro_running) == ("C-863", 6, False)


def test_a_running_macro_reports_and_any_character_stops_it_but_percent_does_not():
    # SC0 in the autostart macro selects the controller at power-on (MS176E §3.1.2)
    with serve(macros={0: "SC0,TP,WA20,RP"}) as (server, vc), raw_port(server) as port:
        chatter = read_for(port, 0.2)
        assert chatter.count(b"P:+0000000000\r\n\x03") >= 3
        port.write(b"%")
        assert b"S:" in read_for(port, 0.1) and vc.running
        port.write(b"x")  # MS176E §3.8.3: "just send a character, e.g. x"
        assert eventually(server, lambda _c: not vc.running)
        read_for(port, 0)  # the reports it made before it stopped
        assert read_for(port, 0.1) == b""


def test_c663_status_has_three_blocks():
    with serve(model="C-663") as (server, vc), raw_port(server) as port:
        port.write(b"\x010%")
        assert protocol.parse_status(read_for(port).decode()).layout == "C-663"


def test_storage_survives_restarts_with_a_state_file(tmp_path):
    state = tmp_path / "flash.json"
    with serve(state=state) as (server, vc), raw_port(server) as port:
        port.write(b"\x010MD6,MR100\r")
        read_for(port)
    with serve(state=state) as (server, vc), raw_port(server) as port:
        port.write(b"\x010TM6\r")
        assert read_for(port) == b"MC006 MR100\r\n\x03"


def test_rm_and_rz_erase():
    with serve(macros={0: "EM1", 1: "GH", 2: "TP"}) as (server, vc), raw_port(server) as port:
        port.write(b"\x010RM2\r")
        port.write(b"RZ\r")
        read_for(port)
        assert vc.macros == {1: "GH"}
