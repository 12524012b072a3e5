"""mercmac.mdtext: the one reader and writer of MD text.

Round trips, the canonical form (docs/uploader.md), the wire commands, and the property that the
emulator and `mercmac check` accept and refuse the same lines.
"""
from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from helpers.budgets import budget
from helpers.compiling import compile_text
from mercmac import mdtext
from mercmac.commands import C663, C863, COMMANDS, Arg
from mercmac.emulator.virtual import VirtualController
from mercmac.upload import protocol
from mercmac.upload.plan import Action, Step

SELECT = b"\x010"  # 0x01 '0': address selection of address 0


def rules(text: str, **kw) -> list[str]:
    return [p.rule for p in mdtext.parse_line(text, **kw).problems]


# -- reading ------------------------------------------------------------------------------------

@pytest.mark.parametrize("text,line", [
    ("MR5000,WS100", "MR5000,WS100"),
    ("em + 9, EM+10", "EM9,EM10"),  # MMCRun's signed numbers (MS176E §3.8.6, Example 4)
    ("bf,dp200,DI,dd 200", "BF,DP200,DI,DD200"),
    ("DI,", "DI"),  # a trailing comma: the argument is left out
    ("m r 5", "MR5"),  # "spaces are allowed" (MS176E §5.2): blanks are dropped
    ("MR 50 00", "MR5000"),
    ("fa?", "FA?"),
    ("", ""),
])
def test_lines_read_as_the_controller_reads_them(text, line):
    parsed = mdtext.parse_line(text)
    assert not parsed.errors and mdtext.format_ops(parsed.ops) == line


@pytest.mark.parametrize("text,rule,where", [
    ("MR5000 WS100", "syntax", (7, 12)),  # two commands, no comma: points at the second
    ("TP TT TP", "syntax", (6, 8)),
    ("MR 5.5", "syntax", (4, 5)),
    (",TP", "syntax", (0, 1)),
    ("TP,,TT", "syntax", (3, 4)),
    ("EMxx", "syntax", (2, 4)),  # the manual's placeholder (Example 3): points at the xx
    ("XY5", "unknown-command", (0, 2)),
    ("TP?", "unknown-command", (0, 3)),
    ("EM xx", "bad-argument", (3, 5)),
    ("MR", "bad-argument", (0, 2)),
    ("TP5", "bad-argument", (2, 3)),
    ("TP, CN 9", "argument-range", (7, 8)),
    ("RP32569", "argument-range", (2, 7)),
    ("MR" + "9" * 5000, "argument-range", (2, 5002)),  # int() refuses 4,300 digits
    ("RT", "not-in-macro", (0, 2)),
    ("MD5", "not-in-macro", (0, 3)),
])
def test_what_is_wrong_and_where(text, rule, where):
    [problem] = mdtext.parse_line(text).errors
    assert (problem.rule, (problem.start, problem.end)) == (rule, where)
    assert problem.message


def test_model_slot_and_length_rules():
    assert rules("DP200", model=C663) == ["model-unsupported"]
    assert rules("DP200", model=C863) == rules("DP200") == []
    assert rules("DC200", model=C863) == ["model-unsupported"]
    assert rules("SC0", slot=5) == ["sc-outside-autostart"]
    assert rules("SC0", slot=0) == []
    assert rules(",".join(["TP"] * 17)) == ["too-many-commands"]
    assert rules(",".join(["TP"] * 17), stored=False) == []
    assert rules("RT", stored=False) == []  # direct mode: the macro commands are fine there
    assert rules("WS") == ["default-argument"] and not mdtext.parse_line("WS").errors


def test_check_reports_a_raw_block_as_parse_line_does():
    text = "[MC01] TP, CN 9\n"
    [d] = compile_text(text).report.items
    [p] = mdtext.parse_line("TP, CN 9").problems
    assert (d.rule.name, d.message) == (p.rule, p.message)
    assert d.span.column == len("[MC01] ") + p.start + 1


# -- writing --------------------------------------------------------------------------------------

LINES = st.lists(st.sampled_from(["MR5000", "WS", "WS100", "EM9", "XN1", "CP15", "FA?", "TP",
                                  "MA-1073741823", "RP", "DI", "SV80000"]), min_size=1, max_size=16)


@settings(max_examples=budget(50), deadline=None)
@given(LINES)
def test_parse_format_parse_is_a_round_trip(commands):
    line = ",".join(commands)
    first = mdtext.parse_line(line)
    assert mdtext.format_ops(first.ops) == line
    assert mdtext.parse_line(mdtext.format_ops(first.ops)).ops == first.ops


@pytest.mark.parametrize("stored,meant", [
    ("mr 5000, ws100", "MR5000,WS100"),  # docs/uploader.md: upper case, spaces dropped
    ("EM+9,EM+10", "EM9,EM10"),  # what MMCRun wrote means what mercmac sends
    ("WA007", "WA7"),
    ("DI,", "DI"),
])
def test_stored_lines_compare_by_meaning(stored, meant):
    assert mdtext.canonical(stored) == stored.upper().replace(" ", "")
    assert protocol.same_macro(stored, meant)
    assert not protocol.same_macro(stored, meant + ",TP")
    assert protocol.same_macro(None, "") and not protocol.same_macro(None, meant)


def test_wire_commands():
    assert mdtext.md(5, "MR5000,WS100") == "MD5,MR5000,WS100"
    assert mdtext.md(5, mdtext.parse_line("mr 5000").ops) == "MD5,MR5000"
    assert (mdtext.tm(), mdtext.tm(12), mdtext.tz(), mdtext.rz(), mdtext.rt(), mdtext.ve()) == (
        "TM", "TM12", "TZ", "RZ", "RT", "VE")
    assert [mdtext.tell(s) for s in (0, 7)] == ["TZ", "TM7"]  # TM0 would list all but 0
    assert [mdtext.remove(s) for s in (0, 7)] == ["RZ", "RM7"]
    with pytest.raises(ValueError):
        mdtext.rm(0)  # a bare RM or RM0 would erase every macro but 0 (MS176E §6.4 RM)
    assert mdtext.split_md("md 5 , tp") == (5, "TP") and mdtext.split_md("MDx,TP")[0] is None


def test_dry_run_and_flash_build_the_same_lines():
    step = Step(Action.WRITE, 5, "MC05", "MR5000,WS100")
    assert step.wire == mdtext.md(5, "MR5000,WS100")
    assert Step(Action.ERASE, 0, "MC00").wire == mdtext.remove(0)
    assert step.readback == mdtext.tell(5)


# -- the emulator and `check` accept and refuse the same lines -------------------------------------

def _case(draw, text: str) -> str:
    return "".join(c.lower() if draw(st.booleans()) else c for c in text)


def _spaced(draw, text: str) -> str:
    return "".join(c + (" " if draw(st.integers(0, 5)) == 0 else "") for c in text)


@st.composite
def commands(draw) -> str:
    kind = draw(st.sampled_from(["known", "known", "known", "unknown", "junk"]))
    if kind == "unknown":
        text = draw(st.sampled_from(["XX", "QQ5", "EMxx", "TP?", "MRX", "Z"]))
    elif kind == "junk":
        text = draw(st.sampled_from(["MR5.5", "MR5000 WS100", "5", "", "MR-", "EM x", "TP TT"]))
    else:
        spec = COMMANDS[draw(st.sampled_from(sorted(COMMANDS)))]
        arg = ""
        if spec.arg is not Arg.NONE and draw(st.integers(0, 5)) or draw(st.integers(0, 20)) == 0:
            lo = -10 ** 9 if spec.lo is None else spec.lo
            hi = 10 ** 9 if spec.hi is None else spec.hi
            n = draw(st.sampled_from([lo, hi, lo - 1, hi + 1, 0]) | st.integers(lo, hi))
            arg = draw(st.sampled_from(["", "+"])) + str(n) if n >= 0 else str(n)
        text = spec.mnemonic + arg
    return _spaced(draw, _case(draw, text))


@st.composite
def lines(draw) -> tuple[str, int, str]:
    parts = draw(st.lists(commands(), min_size=1, max_size=17))
    line = ",".join(parts) + ("," if draw(st.integers(0, 5)) == 0 else "")
    return line, draw(st.sampled_from([0, 5])), draw(st.sampled_from([C663, C863]))


@settings(max_examples=budget(300), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(lines())
def test_the_emulator_and_check_accept_and_refuse_the_same_lines(case):
    line, slot, model = case
    if not line.strip(" ,"):
        return  # nothing to store: MD needs a command
    vc = VirtualController(model=model, macros={})
    vc.receive(SELECT + f"MD{slot},{line}\r".encode(), 0.0)
    vc.take()
    vc.receive(b"TS\r", 0.01)
    vc.tick(0.02)
    error = protocol.parse_status(vc.take().decode("latin-1")).error
    result = compile_text(f"target {model}\n[MC{slot:02d}] {line}\n")
    accepted = not result.report.has_errors
    assert (error == 0) == accepted, (line, error, [d.message for d in result.report.items])
    if accepted:
        assert vc.macros[slot] == result.program.macros[slot].line
    else:
        assert slot not in vc.macros
