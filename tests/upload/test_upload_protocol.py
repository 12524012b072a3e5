"""The uploader's pure layers: protocol bytes and parsing, and the upload plan."""
from __future__ import annotations

import pytest

from mercmac.compiler.program import Macro, Op, Program
from mercmac.upload import protocol
from mercmac.upload.plan import Action, Fate, make_plan
from mercmac.upload.protocol import ProtocolError, ReportSplitter


@pytest.mark.parametrize("address, code", [(0, b"\x010"), (9, b"\x019"), (10, b"\x01A"),
                                           (12, b"\x01C"), (15, b"\x01F")])
def test_address_selection_codes_follow_the_manual_table(address, code):
    assert protocol.select(address) == code


@pytest.mark.parametrize("address", [-1, 16])
def test_addresses_outside_0_to_15_are_refused(address):
    with pytest.raises(ProtocolError):
        protocol.select(address)


def test_a_command_line_ends_in_one_cr():
    assert protocol.command("MD5,MR5000") == b"MD5,MR5000\r"


@pytest.mark.parametrize("line", ["", "   ", "TP\rTP", "MD1,\x01", "TM\n"])
def test_never_a_bare_cr_nor_control_bytes_inside_a_line(line):
    with pytest.raises(ProtocolError):
        protocol.command(line)


def test_reports_are_cut_at_etx_across_chunks_and_nuls_dropped():
    split = ReportSplitter()
    assert split.feed(b"\x00P:+00000") == []
    assert split.feed(b"05555\r\n\x03MC001 MR5\r") == ["P:+0000005555\r\n"]
    assert split.pending() == "MC001 MR5\r"
    assert split.feed(b"\n\x03") == ["MC001 MR5\r\n"]


def test_a_report_that_never_ends_is_an_error_not_a_memory_leak():
    split = ReportSplitter()
    with pytest.raises(ProtocolError):
        split.feed(b"x" * (protocol.MAX_REPORT + 1))


def test_version_report_of_the_manual():
    v = protocol.parse_version("(c)2009 Physik Instrumente(PI) Karlsruhe, C-863, Ver. 2.30, 2009-21-07\r\n")
    assert (v.model, v.firmware, v.char_gap_limited) == ("C-863", "2.30", False)
    assert protocol.parse_version("PI Karlsruhe, C-663, Ver. 1.06").char_gap_limited


@pytest.mark.parametrize("text", ["P:+0000005555", "", "C-863 without version"])
def test_other_reports_are_not_versions(text):
    assert not protocol.is_version(text)
    with pytest.raises(ProtocolError):
        protocol.parse_version(text)


def test_status_reports_of_both_models():
    c863 = protocol.parse_status("S:04 12 00 03 02 06\r\n")
    assert (c863.layout, c863.macro_running, c863.error) == ("C-863", True, 6)
    c663 = protocol.parse_status("s:03 07 00")
    assert (c663.layout, c663.macro_running, c663.error) == ("C-663", False, 0)
    assert protocol.parse_status("S:13 07 01").macro_running


ONE_ETX = "MC001 MR55555\r\nMC002 MA120000\r\n"


@pytest.mark.parametrize("reports", [
    [ONE_ETX],  # CR LF after each line, one ETX at the end
    ["MC001 MR55555\r\n", "MC002 MA120000\r\n"],  # an ETX after every line
])
def test_both_tm_framings_give_the_same_macros(reports):
    found = {}
    for report in reports:
        found.update(protocol.parse_macros(report))
    assert found == {1: "MR55555", 2: "MA120000"}


@pytest.mark.parametrize("report", ["", "\r\n", "MC005", "MC005\r\n", "MC005 \r\n"])
def test_an_empty_report_or_a_bare_mcnnn_is_an_empty_slot(report):
    assert protocol.is_macro_report(report)
    assert protocol.parse_macros(report) == {}


def test_macro_lines_are_strict_about_shape():
    assert not protocol.is_macro_report("P:+0000000001")
    with pytest.raises(ProtocolError):
        protocol.parse_macro_line("MC040 MR5")
    with pytest.raises(ProtocolError):
        protocol.parse_macros("MC001 MR5\r\nMC001 MR6\r\n")


@pytest.mark.parametrize("a, b", [("EM+9,EM+10", "EM9,EM10"), ("XN2, SV250000, EM20", "XN2,SV250000,EM20"),
                                  ("mr5000,ws100", "MR5000,WS100"), ("MA-050", "MA-50"),
                                  ("BF,DP200,DI,DD200", "BF,DP200,DI,DD200")])
def test_macros_compare_as_the_controller_may_store_them(a, b):
    assert protocol.same_macro(a, b)


@pytest.mark.parametrize("a, b", [("MR5000", "MR500"), ("MA100", "MA-100"), ("SV100000", "SV10000"),
                                  ("EM9", None), ("CP0", "CP")])
def test_real_differences_are_not_normalised_away(a, b):
    assert not protocol.same_macro(a, b)


def test_difference_points_at_the_first_changed_character():
    text = protocol.difference("MR5000,WS100", "MR500,WS100")
    assert "'MR5000,WS100'" in text and "'MR500,WS100'" in text and "character 6" in text
    assert "empty" in protocol.difference("MR5", None)


def test_show_makes_control_bytes_visible():
    assert protocol.show(b"\x01A" + b"VE\r") == "<01>AVE<CR>"


# -- the plan ---------------------------------------------------------------

def _program(lines: dict[int, str]) -> Program:
    macros = {}
    for slot, line in lines.items():
        ops = [Op(t[:2], int(t[2:]) if t[2:] else None) for t in line.split(",")]
        macros[slot] = Macro(slot, f"m{slot}" if slot else "MC00", ops)
    return Program(macros, "C-863", "test.mcm")


def test_empty_controller_gets_every_macro_with_macro_0_last():
    plan = make_plan(_program({0: "EM5", 5: "MR5000", 7: "GH"}), {})
    assert [s.wire for s in plan.steps] == ["MD5,MR5000", "MD7,GH", "MD0,EM5"]
    assert all(fate is Fate.WRITTEN for fate in plan.fates.values())


def test_unchanged_program_plans_nothing():
    plan = make_plan(_program({0: "EM5", 5: "MR5000"}), {0: "EM+5", 5: "mr 5000"})
    assert plan.changes_nothing
    assert set(plan.fates.values()) == {Fate.UNCHANGED}


def test_changing_macro_0_removes_it_first_and_writes_it_last():
    plan = make_plan(_program({0: "EM6", 5: "MR5000"}), {0: "EM5", 5: "MR5000"})
    assert [s.wire for s in plan.steps] == ["RZ", "MD0,EM6"]


def test_an_autostart_is_parked_while_what_it_calls_is_rewritten():
    plan = make_plan(_program({0: "EM5", 5: "MR6000"}), {0: "EM5", 5: "MR5000"})
    assert [s.action for s in plan.steps] == [Action.PARK, Action.WRITE, Action.WRITE]
    assert [s.wire for s in plan.steps] == ["RZ", "MD5,MR6000", "MD0,EM5"]
    assert plan.fates[0] is Fate.RESTORED


def test_a_stored_autostart_not_in_the_file_is_kept_but_parked():
    plan = make_plan(_program({5: "MR6000"}), {0: "EM5,EM+6", 5: "MR5000", 6: "GH"})
    assert [s.wire for s in plan.steps] == ["RZ", "MD5,MR6000", "MD0,EM5,EM+6"]
    assert plan.fates[6] is Fate.KEPT


def test_erase_unused_removes_what_the_file_does_not_define():
    plan = make_plan(_program({5: "MR6000"}), {0: "EM5", 5: "MR6000", 6: "GH"}, erase_unused=True)
    assert [s.wire for s in plan.steps] == ["RZ", "RM6"]
    assert plan.fates == {0: Fate.ERASED, 5: Fate.UNCHANGED, 6: Fate.ERASED}
    assert plan.after == {5: "MR6000"}


def test_reading_back_macro_0_uses_tz_because_tm0_lists_the_others():
    plan = make_plan(_program({0: "EM5", 12: "GH"}), {})
    assert [s.readback for s in plan.steps] == ["TM12", "TZ"]
