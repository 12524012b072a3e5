"""The Pygments lexer for .mcm (mercmac.highlight): every example, unknown words, the entry point."""
from __future__ import annotations

import re

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pygments.lexers import get_lexer_by_name, get_lexer_for_filename
from pygments.token import Comment, Error, Keyword, Name, Number, Operator

from helpers.budgets import budget
from helpers.cli import cli
from helpers.paths import EXAMPLE3, EXAMPLE_FILES
from mercmac.commands import COMMANDS
from mercmac.compiler import compile_file
from mercmac.highlight import McmLexer

FILES = EXAMPLE_FILES
# The rules a word the lexer cannot read stands behind.
UNREADABLE = {"syntax", "unknown-command"}


def tokens(text: str) -> list[tuple[object, str]]:
    return [(kind, value) for _, kind, value in McmLexer().get_tokens_unprocessed(text)]


def of(kind, text: str) -> list[str]:
    return [v.strip() for k, v in tokens(text) if k in kind]


def is_clean(path) -> bool:
    return not any(d.rule.name in UNREADABLE for d in compile_file(path).report.items)


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.name)
def test_examples_round_trip(path):
    text = path.read_text(encoding="utf-8")
    assert "".join(v for _, v in tokens(text)) == text
    assert "".join(v for _, v in McmLexer().get_tokens(text)) == text


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.name)
def test_errors_only_where_check_finds_an_unreadable_word(path):
    errors = of(Error, path.read_text(encoding="utf-8"))
    assert (errors == []) == is_clean(path), errors


@settings(max_examples=budget(200), deadline=None)
@given(st.text(alphabet=st.sampled_from(list("[]MCmc05+- \t\r\n,/{}@=?_.xXEWSabdeglnortwé")), max_size=60))
def test_any_text_round_trips(text):
    assert "".join(v for _, v in tokens(text)) == text


def test_crlf_lines_round_trip():
    text = "[MC1] MR5 // a\r\nmacro m {\r\n  SV 5\r\n}\r\n"
    assert "".join(v for _, v in tokens(text)) == text and of(Error, text) == []


def test_some_examples_are_clean_and_one_is_not():
    assert sum(map(is_clean, FILES)) >= 6 and not all(map(is_clean, FILES))


def test_raw_blocks_are_read_as_the_controller_reads_them():
    text = "[MC18] XN4,cf1,MA-50000,EM + 9,m r 5,DI,EMxx   // expect: syntax\n"
    assert of(Name.Label, text) == ["[MC18]"]
    assert of(Name.Builtin, text) == ["XN", "cf", "MA", "EM", "m r", "DI"]
    assert of(Number, text) == ["4", "1", "-50000", "+ 9", "5"]
    assert of(Error, text) == ["EMxx"]
    assert of(Comment, text) == ["// expect: syntax"]


def test_high_level_constructs():
    text = ("target C-863\nconst FAR = 9999999\nmacro jog @20 {\n  every 20ms {\n"
            "    when 1 and not BUTTON { MR FAR, WF 1, FA?, AB1 }\n  }\n"
            "  repeat STEPS { call pulse }\n  goto idle\n}\nautostart { call jog }\n")
    assert of(Keyword.Declaration, text) == ["target", "const", "macro", "autostart"]
    assert of(Keyword.Constant, text) == ["C-863"]
    assert [v for k, v in tokens(text) if k is Keyword] == ["every", "when", "repeat", "call",
                                                           "goto", "call"]
    assert of(Operator.Word, text) == ["and", "not"]
    assert of(Name.Function, text) == ["jog", "pulse", "idle", "jog"]
    assert of(Name.Constant, text) == ["FAR", "BUTTON", "FAR", "STEPS"]
    assert of(Name.Builtin, text) == ["MR", "WF", "FA?", "AB"]
    assert of(Number, text) == ["9999999", "20", "20ms", "1", "1", "1"]
    assert of(Error, text) == []


@pytest.mark.parametrize("word", ["XYZ", "EMxx", "mrr", "FB?"])
def test_an_unknown_mnemonic_is_an_error(word):
    assert of(Error, f"macro m {{ {word} 5, MR 1 }}\n") == [word]
    assert of(Error, f"[MC3] MR1,{word}5\n") == [word]


def test_every_mnemonic_of_the_table_is_known_in_any_case():
    line = ", ".join([*COMMANDS, *(m.lower() for m in COMMANDS)])
    assert of(Error, f"macro m {{ {line} }}\n") == []
    assert of(Error, f"[MC1] {line}\n") == []


def test_pygments_finds_the_lexer_through_its_entry_point():
    assert isinstance(get_lexer_for_filename("a.mcm"), McmLexer)
    assert isinstance(get_lexer_by_name("mcm"), McmLexer)


# -- mercmac's own diagnostics on a terminal ------------------------------------------------

_ANSI = re.compile(r"\x1b\[[0-9;]*m")
EX3 = EXAMPLE3


def test_check_highlights_the_source_line_on_a_colour_terminal():
    plain = cli("check", EX3, env={"NO_COLOR": "1", "FORCE_COLOR": None}).output
    coloured = cli("check", EX3, env={"NO_COLOR": None, "FORCE_COLOR": "1"}).output
    assert _ANSI.sub("", coloured) == plain
    line = next(l for l in coloured.splitlines() if "EMxx" in l and "|" in l)
    assert re.search(r"\x1b\[[0-9;]*m\[MC18\]", line)  # the slot has a colour of its own
    assert re.search(r"\x1b\[[0-9;]*mEMxx", line)  # and so has the unknown word


def test_a_long_line_is_highlighted_in_its_window():
    from mercmac.render.report import _excerpt, _highlighted

    text = "[MC1] " + ",".join(["MR 5000"] * 40) + ",XYZ\t5," + ",".join(["WS 1"] * 30)
    start = text.index("XYZ")
    shown, _, _ = _excerpt(text, start, 3)
    pieces = _highlighted(text, start)
    assert "".join(p for p, _ in pieces) == shown
    assert ("XYZ", "bold red underline") in pieces
