"""Natural guesses get a hint (docs/checks.md): `LED 1` says to write `CN 1`, not
"did you mean DD?". One table (mercmac/compiler/guesses.py), used by the rule that fires."""
from __future__ import annotations

import pytest

from helpers.compiling import compile_text


def diagnostic(body: str, rule: str, raw: bool = False):
    text = f"target C-863\n[MC01] {body}\n" if raw else f"target C-863\nautostart {{\n    {body}\n}}\n"
    found = [d for d in compile_text(text).report.items if d.rule.name == rule]
    assert found, [(d.rule.name, d.message) for d in compile_text(text).report.items]
    return found[0]


@pytest.mark.parametrize("body, says", [
    ("LED 1", "to light LED 1 of the pushbutton box write `CN 1`"),
    ("led 3", "write `CN 3`"),
    ("LED off", "write `CF n`"),
    ("wait 100", "write `WA 100` to wait 100 ms"),
    ("sleep 250", "write `WA 250`"),
    ("delay 20", "write `WA 20`"),
    ("move 5000", "`MR 5000` to move by 5000 counts, `MA 5000` to move to position 5000"),
    ("home", "`GH` moves to position 0"),
    ("print", "`TP` reports the position"),
    ("speed 80000", "write `SV 80000`"),
    ("if 1", "write `when 1 { ... }`"),
    ("jump scan", "`goto NAME`"),
])
def test_an_unknown_command_that_is_a_natural_guess_says_what_to_write(body, says):
    d = diagnostic(body, "unknown-command")
    assert says in d.message and "did you mean" not in d.message


def test_raw_blocks_get_the_command_guesses_but_not_the_constructs():
    assert "write `CN 1`" in diagnostic("LED1", "unknown-command", raw=True).message
    assert "when" not in diagnostic("IF1", "unknown-command", raw=True).message


@pytest.mark.parametrize("body, says", [("XY 1", "did you mean"), ("cal scan", "'call'")])
def test_other_unknown_words_keep_their_spelling_suggestion(body, says):
    assert says in diagnostic(body, "unknown-command").message


# -- syntax errors at the start of a statement (compiler/parse.py `_hint`) -------------------

@pytest.mark.parametrize("body, says", [
    ("if 1 {\n        CN 1\n    }", "write `when 1 { ... }`"),
    ("wait 100ms", "write `WA 100` to wait 100 ms"),
    ("sleep 2s", "write `WA 2000`"),
    ("loop {\n        CN 1\n    }", "`every 20ms { ... }`"),
    ("for 3 {\n        CN 1\n    }", "`repeat 3 { ... }`"),
])
def test_a_syntax_error_at_a_natural_guess_says_what_to_write(body, says):
    d = diagnostic(body, "syntax")
    assert says in d.message and d.span.column == 5  # the word itself


def test_a_guess_word_elsewhere_on_the_line_is_not_blamed():
    """A guard for the hookup: only the statement the error stands in is read."""
    d = diagnostic("LED 1, MR 5 5", "syntax")  # the error is `MR 5 5`, not the LED
    assert "LED" not in d.message
