"""Hostile input to the compiler and `check`: nothing lost, nothing hangs, no traceback.

Every failure is a diagnostic with a line and a column; output is safe for a terminal
and bounded; one bad file does not stop the others.
"""
from __future__ import annotations

import json

import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from helpers.budgets import budget
from helpers.cli import cli
from mercmac.cli import main
from mercmac.compiler import compile_source
from mercmac.source import Source, decode


def diagnostics(text: str):
    return compile_source(Source("t.mcm", text)).report.items


def found(text: str) -> list[tuple[str, int, int]]:
    return [(d.rule.name, d.span.line, d.span.column) for d in diagnostics(text)]


# -- numbers the compiler cannot use -----------------------------------------------------

@pytest.mark.parametrize("period", ["1.5ms", "0.0001s"])
def test_fractional_period_is_a_diagnostic(period):
    assert found(f"macro a {{\n  every {period} {{ TP }}\n}}\n") == [("bad-argument", 2, 9)]


def test_period_of_400_nines_days_is_a_diagnostic():
    [d] = diagnostics("autostart { every " + "9" * 400 + "d { TP } }\n")
    assert d.rule.name == "bad-argument" and (d.span.line, d.span.column) == (1, 19)


@pytest.mark.parametrize("text,rule,column", [
    ("[MC01] MR{}\n", "argument-range", 10),
    ("const A = {}\nmacro a {{ MR A }}\n", "argument-range", 11),
    ("macro a @{} {{ TP }}\n", "argument-range", 10),
    ("macro a {{ repeat {} {{ TP }} }}\n", "argument-range", 18),
    ("macro a {{ when -{} {{ TP }} }}\n", "argument-range", 16),
    ("[MC{}] TP\n", "slot-range", 1),
])
def test_number_beyond_python_int_limit_is_a_diagnostic(text, rule, column):
    [d] = diagnostics(text.format("9" * 5000))  # int() refuses more than 4,300 digits
    assert (d.rule.name, d.span.line, d.span.column) == (rule, 1, column)
    assert len(d.message) < 200


def test_long_number_within_reason_still_says_its_value():
    [d] = diagnostics("[MC01] MR 99999999999\n")
    assert d.rule.name == "argument-range" and "99999999999" in d.message


# -- nesting ------------------------------------------------------------------------------

@pytest.mark.parametrize("head", ["when 1", "repeat 2", "every 20ms"])
def test_nesting_250_deep_is_an_error_at_the_33rd_level(head):
    text = "macro a {\n" + f"{head} {{\n" * 250 + "TP\n" + "}\n" * 250 + "}\n"
    deep = [d for d in diagnostics(text) if "nested" in d.message]
    assert [(d.rule.name, d.span.line, d.span.column) for d in deep] == [("slot-range", 34, 1)]


def test_nesting_within_the_limit_is_not_refused():
    text = "macro a {\n" + "when 1 {\n" * 32 + "TP\n" + "}\n" * 32 + "}\n"
    assert not any("nested" in d.message for d in diagnostics(text))


# -- many errors: all reported, in one pass --------------------------------------------------

def test_every_broken_line_is_reported():
    text = "[MC01] MR5000 WS100\n" * 300  # the old re-parsing recovery stopped after 50
    assert found(text) == [("syntax", n, 15) for n in range(1, 301)]


def test_errors_in_blocks_keep_the_braces():
    text = ("macro a {\n  when 3 { MA 5 5 }\n  TP\n}\n"
            "macro b {\n  repeat { TP\n  }\n}\n[MC01] TP TT TP\n")
    assert [(r, line) for r, line, _ in found(text)] == [("syntax", 2), ("syntax", 6), ("syntax", 9)]


def test_source_lines_are_counted_as_the_parser_counts_them():
    source = Source("t.mcm", "[MC01] TP\x0c\r\n[MC02] XX\n")
    assert source.line(2) == "[MC02] XX"  # str.splitlines() would also split at the form feed
    r = CliRunner().invoke(main, ["check", "-"], input="[MC01] TP\x0c\r\n[MC02] XX\n")
    assert "    2 | [MC02] XX" in r.output


# -- output: capped, escaped, windowed --------------------------------------------------------

def test_text_output_is_capped_per_file_with_a_count(tmp_path):
    f = tmp_path / "many.mcm"
    f.write_text("[MC01] MR5000 WS100\n" * 250)
    r = cli("check", str(f))
    assert r.exit_code == 1
    assert r.output.count("error[MM001 syntax]") == 200
    assert "50 more diagnostics not shown" in r.output and "--max-diagnostics 0" in r.output
    assert r.output.rstrip().endswith("250 errors, 0 warnings, 0 infos in 1 file.")
    assert cli("check", "--max-diagnostics", "0", str(f)).output.count("error[MM001") == 250


def test_json_output_is_capped_with_truncated_counts(tmp_path):
    f = tmp_path / "many.mcm"
    f.write_text("[MC01] MR5000 WS100\n" * 30)
    data = json.loads(cli("check", "--format", "json", "--max-diagnostics", "10", str(f)).output)
    assert len(data["diagnostics"]) == 10 and data["truncated"] == {str(f): 20}
    assert "truncated" not in json.loads(cli("check", "--format", "json", str(f)).output)


def test_a_long_line_is_shown_as_a_window_around_the_caret(tmp_path):
    f = tmp_path / "long.mcm"
    f.write_text("[MC01] " + "TP," * 5000 + "XX1\n")
    r = cli("check", str(f))
    lines = r.output.splitlines()
    i = next(i for i, line in enumerate(lines) if "unknown-command" in line)
    shown, caret = lines[i + 1], lines[i + 2]
    assert len(shown) < 130 and shown.startswith("    1 | ...") and shown.rstrip().endswith("XX1")
    assert shown[caret.index("^"):caret.index("^") + 2] == "XX"


def test_control_characters_never_reach_the_terminal(tmp_path):
    f = tmp_path / "esc.mcm"
    f.write_text("[MC01] TP\x1b]0;pwned\x07\x1b[2J\n[MC02] \x1b[2JXX\n[MC03] TP\u202e\n")
    r = cli("check", str(f))
    assert r.exit_code == 1
    assert not any(c in r.output for c in "\x1b\x07\u202e")
    assert "\\x1b[2J" in r.output
    lines = r.output.splitlines()
    i = next(i for i, line in enumerate(lines) if line.startswith(f"{f}:2:"))
    assert lines[i + 1].index("\\x1b") == lines[i + 2].index("^")  # caret under the escape


# -- names and encodings ----------------------------------------------------------------------

def test_non_ascii_name_says_names_are_ascii_and_points_at_it():
    [d] = diagnostics("const \u00c4PFEL = 5\n")
    assert d.rule.name == "syntax" and (d.span.line, d.span.column) == (1, 7)
    assert "ASCII" in d.message and "ST" not in d.message


@pytest.mark.parametrize("codec", ["utf-16", "utf-16-be", "utf-32", "utf-32-be"])
def test_unicode_files_with_a_bom_are_read(tmp_path, codec):
    f = tmp_path / "u.mcm"
    data = "// Mercury\u2122 Macro File\r\n[MC01] TP\r\n".encode(codec)
    if codec.endswith("-be"):
        data = "\ufeff".encode(codec) + data
    f.write_bytes(data)
    r = cli("check", str(f))
    assert r.exit_code == 0 and "No problems found" in r.output


def test_utf16_without_bom_is_read():
    assert decode("[MC01] TP \u2122\n".encode("utf-16-le")) == "[MC01] TP \u2122\n"


def test_binary_file_says_so(tmp_path):
    f = tmp_path / "b.mcm"
    f.write_bytes(bytes(range(256)) * 4)
    r = cli("check", str(f))
    assert r.exit_code == 1 and "binary file" in r.output and r.output.count("[MM") == 1


# -- one bad file does not stop the others ----------------------------------------------------

def test_a_compiler_crash_is_an_error_on_that_file_and_the_others_go_on(tmp_path, monkeypatch):
    import mercmac.compiler

    real = mercmac.compiler.compile_source

    def flaky(source, target=None):
        if source.name.endswith("bad.mcm"):
            raise RecursionError("maximum recursion depth exceeded")
        return real(source, target)

    monkeypatch.setattr(mercmac.compiler, "compile_source", flaky)
    bad, good = tmp_path / "bad.mcm", tmp_path / "good.mcm"
    bad.write_text("[MC01] TP\n")
    good.write_text("[MC01] TQ\n")
    r = cli("check", str(bad), str(good))
    assert r.exit_code == 1
    assert f"{bad}:1:1: error" in r.output and "internal error" in r.output
    assert "RecursionError" in r.output and "unknown-command" in r.output


def test_hostile_files_do_not_stop_check(tmp_path):
    files = {"a.mcm": "macro a {\n" + "repeat 2 {\n" * 250 + "}\n" * 251,
             "b.mcm": "[MC01] MR" + "9" * 5000 + "\n", "c.mcm": "autostart { every 1.5ms { TP } }\n",
             "d.mcm": "[MC01] TQ\n"}
    for name, text in files.items():
        (tmp_path / name).write_text(text)
    r = cli("check", *(str(tmp_path / n) for n in files))
    assert r.exit_code == 1 and "internal error" not in r.output
    for name in files:
        assert f"{tmp_path / name}:" in r.output


# -- fuzz ---------------------------------------------------------------------------------------

PIECES = st.sampled_from([
    "[MC01] ", "[MC", "]", "macro a ", "macro b @", "autostart ", "{", "}", "{\n", "}\n", "when 1 ",
    "when not ", " and ", "repeat 3 ", "every 20ms ", "every 1.5s ", "call a", "goto b",
    "const A = ", "target C-863\n", "MR", "MR 5", "EM+9", "DI,", "TP", "XX", ",", "\n", " ",
    "9" * 30, "9" * 5000, "0.0001s", "\x1b[2J", "\x00", "\u00c4", "\ufeff", "\r", "\t", "//", "@",
    "=", "-", "+", "A", "_", "EMxx", "MR " + "9" * 5000, "every 1.5ms {", "every " + "9" * 400 + "d {",
    "const B = " + "9" * 5000 + "\n",
])


@st.composite
def mangled(draw):
    parts = draw(st.lists(PIECES, max_size=40))
    if draw(st.booleans()):
        depth = draw(st.sampled_from([0, 3, 33, 300]) | st.integers(0, 300))
        head = draw(st.sampled_from(["when 1 {", "repeat 2 {", "every 5ms {", "{"]))
        parts = ["macro z {"] + [head] * depth + parts + ["}"] * draw(st.integers(0, depth + 1))
    return "\n".join(parts) if draw(st.booleans()) else "".join(parts)


NUMBERS = st.sampled_from(["5", "0", "-3", "9" * 30, "9" * 5000, "+ 7", "A"])
PERIODS = st.sampled_from(["20ms", "1.5ms", "0.0001s", "9" * 400 + "d", "A", "70000ms"])
STATEMENTS = st.recursive(
    st.sampled_from(["TP", "XX", "SC", "JN 5000", "call a", "goto a"]) | NUMBERS.map("MR {}".format),
    lambda body: st.tuples(
        st.sampled_from(["when {} ", "when not {} and 2 ", "repeat {} ", "every {} "]),
        NUMBERS, PERIODS, st.lists(body, max_size=4),
    ).map(lambda t: t[0].format(t[2] if "every" in t[0] else t[1]) + "{ " + ", ".join(t[3]) + " }"),
    max_leaves=12)


@st.composite
def programs(draw):
    """Programs that parse, so that every stage after the parser sees the hostile values."""
    body = ",\n".join(draw(st.lists(STATEMENTS, min_size=1, max_size=6)))
    depth = draw(st.sampled_from([0, 1, 32, 33, 300]))
    body = "when 1 { " * depth + body + " }" * depth
    pin = draw(st.sampled_from(["", "@3 ", "@" + "9" * 5000 + " "]))
    return (f"const A = {draw(NUMBERS)}\n[MC{draw(NUMBERS).strip('+ A') or 1}] MR{draw(NUMBERS)}\n"
            f"macro a {pin}{{\n{body}\n}}\n")


@settings(max_examples=budget(100), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(programs())
def test_hostile_programs_never_raise(text):
    for d in diagnostics(text):
        assert d.span.line >= 1 and d.span.column >= 1


@settings(max_examples=budget(150), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mangled())
def test_mangled_text_never_raises(text):
    for d in diagnostics(text):
        assert d.span.line >= 1 and d.span.column >= 1


@settings(max_examples=budget(60), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.binary(max_size=400), st.sampled_from(["text", "json"]))
def test_check_on_random_bytes_never_raises(data, fmt):
    r = CliRunner().invoke(main, ["check", "--format", fmt, "-"], input=data)
    assert r.exception is None or isinstance(r.exception, SystemExit), r.exception
    assert r.exit_code in (0, 1)
    if fmt == "text":
        assert "\x1b" not in r.output and "Traceback" not in r.output
