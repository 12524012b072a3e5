"""`// mercmac: ignore[...]` comments: a comment that cannot be read
turns nothing off and is reported (invalid-suppression); codes and names in any case."""
from __future__ import annotations

import json

import pytest

from helpers.cli import cli

# nested-call (a warning) on line 2, and nothing else: the comment goes on line 2.
NESTED = "[MC00] EM1\n[MC01] EM2,MR5 {comment}\n[MC02] EM3\n[MC03] MR1\n"


def _check(tmp_path, comment: str, *options) -> tuple[int, list[tuple[str, int]]]:
    """Exit code and (rule, line) of each diagnostic of `check --format json`."""
    (tmp_path / "a.mcm").write_text(NESTED.format(comment=comment), encoding="utf-8")
    result = cli("check", "--format", "json", *options, tmp_path / "a.mcm")
    found = json.loads(result.output)["diagnostics"]
    return result.exit_code, [(d["rule"], d["line"]) for d in found]


@pytest.mark.parametrize("comment", [
    "// MERCMAC: IGNORE[mm011]",
    "// Mercmac: Ignore[NESTED-CALL]",
    "// MERCMAC: IGNORE",
])
def test_directive_codes_and_names_in_any_case(tmp_path, comment):
    assert _check(tmp_path, comment) == (0, [])


@pytest.mark.parametrize("comment", [
    "// mercmac: ignore[MM011",            # the bracket is never closed
    "// mercmac: ignore[nested-call",
    "// mercmac: ignore[",
    "// why // mercmac: ignore[MM011 // mercmac: ignore[MM012]",  # closed by another's ]
])
def test_an_unclosed_bracket_turns_nothing_off_and_is_a_warning(tmp_path, comment):
    code, found = _check(tmp_path, comment)
    assert ("nested-call", 2) in found and ("invalid-suppression", 2) in found
    assert code == 0  # warnings


def test_an_unclosed_bracket_fails_with_warnings_as_errors(tmp_path):
    assert _check(tmp_path, "// mercmac: ignore[MM011", "--warnings-as-errors")[0] == 1


@pytest.mark.parametrize("comment, silenced", [
    ("// mercmac: ignore[nested-cal]", False),          # a typo: said, not passed over
    ("// mercmac: ignore[MM999, nested-call]", True),   # the known one still applies
    ("// mercmac: ignore[]", False),
    ("// mercmac: ignore[ , ]", False),
])
def test_a_rule_that_does_not_exist_is_reported(tmp_path, comment, silenced):
    code, found = _check(tmp_path, comment)
    assert ("invalid-suppression", 2) in found
    assert (("nested-call", 2) not in found) is silenced


def test_invalid_suppression_is_a_rule_like_the_others(tmp_path):
    assert _check(tmp_path, "// mercmac: ignore[MM011", "--ignore", "invalid-suppression") \
        == (0, [("nested-call", 2)])
    assert _check(tmp_path, "// mercmac: ignore[MM011", "--select", "MM034") \
        == (0, [("invalid-suppression", 2)])
    # the comment of a line may turn it off, as any rule (a second, valid directive)
    assert _check(tmp_path, "// mercmac: ignore[nested-cal] // mercmac: ignore") == (0, [])


def test_explain_lists_and_explains_invalid_suppression():
    listed = cli("explain")
    assert listed.exit_code == 0 and "invalid-suppression" in listed.output
    story = cli("explain", "MM034")
    assert story.exit_code == 0 and "invalid-suppression" in story.output
    assert "ruff" in story.output  # says why it is a rule (RUF102)


def test_the_warning_points_at_the_directive(tmp_path):
    (tmp_path / "a.mcm").write_text("[MC00] TP   // mercmac: ignore[MM011\n", encoding="utf-8")
    result = cli("check", "--format", "json", tmp_path / "a.mcm")
    [d] = json.loads(result.output)["diagnostics"]
    assert (d["rule"], d["line"], d["column"]) == ("invalid-suppression", 1, 16)


def test_a_line_of_many_comment_starts_is_read(tmp_path):
    """The shape that made the old pattern quadratic (its time is in
    benchmarks/check_large.py): the directive at the end still counts, once."""
    comment = "// " * 2000 + "mercmac: ignore[MM011"
    code, found = _check(tmp_path, comment)
    assert found.count(("invalid-suppression", 2)) == 1 and ("nested-call", 2) in found
    assert _check(tmp_path, "// " * 2000 + "mercmac: ignore[MM011]") == (0, [])
