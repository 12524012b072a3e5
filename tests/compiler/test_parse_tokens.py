"""`parse.tokens`, the tree-less reading `mercmac fmt` rewrites (once a 1 MB line took 38 s
to format): the same tokens as grammar.lark's own parser gives, and a refusal exactly where
that parser refuses."""
from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from helpers.budgets import budget
from helpers.paths import EXAMPLE_FILES
from mercmac.compiler import parser_tables as lark
from mercmac.compiler.parse import NotParsed, tokens
from mercmac.source import to_lf

EXAMPLE_TEXTS = [p.read_text(encoding="utf-8") for p in EXAMPLE_FILES]
NOISE = st.sampled_from(
    list("[]{},@=-+?0123456789 \t\n\r\f.MCEWXNFRPSVTabcdefmnorstw/_")
    + ["when ", "and ", "not ", "macro ", "repeat ", "every ", "ms", "call ", "goto ", "const ",
       "target ", "C-863", "autostart", "//", "[MC05]", "\r\n", "\x00", "\u2122"])


def lark_tokens(text: str) -> list[tuple[str, str]] | None:
    """(terminal, text) of the tokens and comments lark's parser reads; None if it refuses."""
    comments: list = []
    parser = lark.Lark_StandAlone(lexer_callbacks={"COMMENT": comments.append})
    found: list = []
    try:
        interactive = parser.parse_interactive(to_lf(text) + "\n")
        for token in interactive.iter_parse():
            found.append(token)
        interactive.feed_eof(found[-1] if found else None)
    except lark.LarkError:
        return None
    return [(t.type, str(t)) for t in sorted(found + comments, key=lambda t: t.start_pos)]


def our_tokens(text: str) -> list[tuple[str, str]] | None:
    try:
        return tokens(text)
    except NotParsed:
        return None


@st.composite
def mangled(draw) -> str:
    text = draw(st.sampled_from(EXAMPLE_TEXTS))
    for _ in range(draw(st.integers(1, 3))):
        at = draw(st.integers(0, len(text)))
        cut = draw(st.integers(0, 5))
        text = text[:at] + "".join(draw(st.lists(NOISE, max_size=4))) + text[at + cut:]
    return text


@pytest.mark.parametrize("text", EXAMPLE_TEXTS)
def test_the_examples_read_as_lark_reads_them(text):
    assert our_tokens(text) == lark_tokens(text) is not None


@settings(max_examples=budget(300), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mangled())
def test_mangled_files_read_as_lark_reads_them_or_are_refused_alike(text):
    assert our_tokens(text) == lark_tokens(text)


@pytest.mark.parametrize("text, where", [
    ("macro a { MR 5 @ }\n", (1, 16)),
    ("macro a {\n", (2, 1)),  # the file ends inside the block
    ("target C-863\n   \x01\n", (2, 4)),
    ("when 1 { }\n", (1, 1)),
])
def test_a_refusal_says_where(text, where):
    with pytest.raises(NotParsed) as e:
        tokens(text)
    assert (e.value.line, e.value.column) == where


def test_keywords_are_keywords_and_names_are_names():
    assert tokens("macro and_more { call and_more }") == [
        ("MACRO", "macro"), ("NAME", "and_more"), ("LBRACE", "{"), ("CALL", "call"),
        ("NAME", "and_more"), ("RBRACE", "}"), ("_NL", "\n")]
