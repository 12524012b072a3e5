"""A broken line hides nothing on the other lines, and syntax errors say why."""
from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mercmac.compiler import compile_source
from mercmac.compiler.ast_builder import build
from mercmac.compiler.checks import check_module
from mercmac.compiler.parse import parse, parse_partial
from mercmac.diagnostics import Report
from mercmac.source import Source
from helpers.budgets import budget
from helpers.paths import EXAMPLE_FILES

ISSUE = """\
macro scan {
  MR 500
}
autostart {
  whne 1 {
    call scan
  }
  MRR 100
  call scna
}
"""


def compiled(text: str):
    return compile_source(Source("t.mcm", text))


def found(text: str) -> list[tuple[str, int]]:
    return sorted((d.rule.name, d.span.line) for d in compiled(text).report.items)


def message(text: str, rule: str) -> str:
    [d] = [d for d in compiled(text).report.items if d.rule.name == rule]
    return d.message


def test_the_issue_example_gets_every_diagnostic_at_once():
    result = compiled(ISSUE)
    by_rule = {d.rule.name: d for d in result.report.items}
    assert found(ISSUE) == [("syntax", 5), ("undefined-name", 9), ("unknown-command", 8)]
    assert "did you mean 'when'" in by_rule["syntax"].message
    assert "did you mean MR" in by_rule["unknown-command"].message
    assert "did you mean 'scan'" in by_rule["undefined-name"].message
    assert result.program is None  # nothing with errors is lowered


def test_a_broken_line_is_not_lowered_and_parse_keeps_its_contract():
    report = Report("t.mcm")
    assert parse(ISSUE, report) is None
    parsed = parse_partial(ISSUE, Report("t.mcm"))
    assert parsed.tree is not None and parsed.broken == {5} and parsed.failed


@pytest.mark.parametrize("line, keyword", [
    ("macor scan {", "macro"), ("  whne 1 {", "when"), ("  reapet 3 {", "repeat"),
    ("  When 1 { TP }", "when"), ("cosnt A = 5", "const"), ("autostrat {", "autostart"),
])
def test_misspelled_keywords_get_did_you_mean(line, keyword):
    text = ("macro a {\n  TP\n}\n" if line[0] != " " else "macro a {\n") + line + "\n  TP\n}\n"
    if line[0] == " ":
        text += "}\n"
    d = [d for d in compiled(text).report.items if d.rule.name == "syntax"][0]
    assert f"did you mean '{keyword}'" in d.message
    assert d.span.column == len(line) - len(line.lstrip()) + 1  # at the word


def test_a_misspelled_call_keyword_in_a_block_is_suggested_too():
    text = "macro scan {\n  TP\n}\nautostart {\n  cal scan\n}\n"
    assert "did you mean 'call'" in message(text, "unknown-command")


def test_a_misspelled_const_gets_did_you_mean():
    text = "const SPEED = 2000\nautostart {\n  SV SPEDE\n}\n"
    assert "did you mean 'SPEED'" in message(text, "undefined-name")


def test_no_far_fetched_suggestion():
    text = "macro scan {\n  TP\n}\nautostart {\n  call home\n}\n"
    assert "did you mean" not in message(text, "undefined-name")


def test_when_or_says_two_when_blocks():
    text = "autostart {\n  when 1 or 2 { TP }\n  MRR 5\n}\n"
    m = message(text, "syntax")
    assert "no 'or'" in m and "when block" in m
    assert found(text) == [("syntax", 2), ("unknown-command", 3)]


@pytest.mark.parametrize("written, shown", [("WA 20ms", "WA 20"), ("WA 2s", "WA 2000"),
                                            ("WS 1min", "WS 60000")])
def test_wa_with_a_unit_says_plain_milliseconds(written, shown):
    m = message(f"autostart {{\n  {written}\n}}\n", "syntax")
    assert "plain milliseconds" in m and f"write {shown}" in m


def test_a_unit_on_a_distance_is_named():
    assert "without a unit" in message("autostart {\n  MR 1mm\n}\n", "syntax")


def test_a_name_on_a_broken_line_is_not_called_undefined():
    # the broken line may be the definition: `macor scan {`
    text = "macor scan {\n  TP\n}\nautostart {\n  call scan\n  call nowhere\n}\n"
    assert found(text) == [("syntax", 1), ("undefined-name", 6)]


def test_the_body_of_a_broken_block_is_still_checked():
    text = "autostart {\n  repeat three x {\n    MRR 1\n  }\n  XYZ\n}\n"
    assert found(text) == [("syntax", 2), ("unknown-command", 3), ("unknown-command", 5)]


def test_a_file_that_ends_inside_a_block_is_checked():
    text = "macro a {\n  TP\n}\nautostart {\n  MRR 1\n  when 1 {\n    call b\n"
    assert found(text) == [("syntax", 7), ("undefined-name", 7), ("unknown-command", 5)]
    assert compiled(text).program is None


def test_a_broken_raw_block_is_left_out_and_the_others_checked():
    text = "[MC01] MR5000 WS100\n[MC02] MRR5\n[MC01] TP\n"
    assert found(text) == [("syntax", 1), ("unknown-command", 2)]


def test_nothing_on_the_broken_line_but_its_syntax_error():
    assert found("autostart {\n  MR 5 5\n}\n") == [("syntax", 2)]


def test_the_output_order_is_deterministic():
    text = ISSUE + "autostart {\n  MRX 2\n}\n"
    first = [(d.rule.name, d.span, d.message) for d in compiled(text).report.sorted()]
    assert first == [(d.rule.name, d.span, d.message) for d in compiled(text).report.sorted()]


# -- property: one broken line hides nothing elsewhere ----------------------------------------

# Diagnostics that depend on other lines by nature: which definition comes first, which
# statement is last, which loop a goto is in, which target the file names.
_CONTEXTUAL = {"duplicate-name", "duplicate-slot", "goto-not-last", "goto-ends-loop",
               "model-unsupported", "undefined-name"}


def _ast_level(text: str) -> set[tuple[str, int, int]]:
    """The checks of the syntax tree on a clean file (lowering's checks wait for a clean one)."""
    report = Report("t.mcm")
    tree = parse(text, report)
    assert tree is not None
    check_module(build(tree), report, None)
    return {(d.rule.name, d.span.line, d.span.column) for d in report.items}


_TEXTS = {p.name: p.read_text(encoding="utf-8") for p in EXAMPLE_FILES}


@settings(max_examples=budget(150), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(name=st.sampled_from(sorted(_TEXTS)), data=st.data())
def test_garbling_one_line_hides_nothing_on_the_others(name, data):
    text = _TEXTS[name]
    lines = text.split("\n")
    index = data.draw(st.integers(0, len(lines) - 1))
    line = lines[index]
    at = data.draw(st.integers(0, len(line)))
    junk = data.draw(st.sampled_from(["%%", "?", " or ", "1.5", " ms", "{ }", "]["]))
    lines[index] = line[:at] + junk + line[at:]
    garbled = "\n".join(lines)
    result = compiled(garbled)  # never raises
    after = {(d.rule.name, d.span.line, d.span.column) for d in result.report.items}
    parsed = parse_partial(garbled, Report("t.mcm"))
    broken = parsed.broken
    if parsed.failed:
        assert result.program is None
    if not broken:
        return  # the junk was harmless (in a comment, say)
    if broken != {index + 1} or line.count("{") != lines[index].count("{") or \
            line.count("}") != lines[index].count("}"):
        return  # the junk broke another line too, or changed the blocks: no comparison
    clean = _ast_level(text)
    words = set(line.replace("{", " ").replace(",", " ").split())
    for rule, number, column in clean:
        if number == index + 1 or rule in _CONTEXTUAL and not (
                rule == "undefined-name" and not words & {"macro", "const"}):
            continue
        assert (rule, number, column) in after, (rule, number, garbled)


@settings(max_examples=budget(100), deadline=None)
@given(name=st.sampled_from(sorted(_TEXTS)), data=st.data())
def test_deleting_one_line_never_raises_nor_hides_local_diagnostics(name, data):
    text = _TEXTS[name]
    lines = text.split("\n")
    index = data.draw(st.integers(0, len(lines) - 1))
    gone = lines.pop(index)
    result = compiled("\n".join(lines))
    if parse_partial("\n".join(lines), Report("t.mcm")).failed:
        assert result.program is None
    if gone.count("{") or gone.count("}") or gone.lstrip().startswith(("target", "const", "macro")):
        return  # the blocks or the definitions changed: other diagnostics may well change
    after = {(d.rule.name, d.span.line, d.span.column) for d in result.report.items}
    for rule, number, column in _ast_level(text):
        if number == index + 1 or rule in _CONTEXTUAL:
            continue
        shifted = number - (number > index + 1)
        assert (rule, shifted, column) in after, (rule, number)
