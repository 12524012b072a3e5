"""The stand-alone parser is generated from grammar.lark and parses like lark itself."""
from __future__ import annotations

import pytest

from conftest import EXAMPLES
from mercmac.compiler import parser_tables, regen
from mercmac.compiler.parse import parser


def test_parser_tables_are_generated_from_the_current_grammar():
    assert parser_tables.GRAMMAR_SHA256 == regen.grammar_digest(), (
        "grammar.lark changed: run `python -m mercmac.compiler.regen`")


@pytest.mark.parametrize("path", sorted(EXAMPLES.glob("*.mcm")), ids=lambda p: p.name)
def test_standalone_parser_matches_lark(path):
    lark = pytest.importorskip("lark")
    text = path.read_text(encoding="utf-8") + "\n"
    reference = lark.Lark(regen.GRAMMAR.read_text(encoding="utf-8"), **regen.OPTIONS)
    assert _shape(parser().parse(text)) == _shape(reference.parse(text))


def _shape(node):
    """A tree as nested tuples of rule names, token types, values and positions."""
    if hasattr(node, "children"):
        return (str(node.data), tuple(_shape(c) for c in node.children))
    return (node.type, str(node), node.line, node.column)


def test_grammar_is_lalr_with_positions():
    assert regen.OPTIONS["parser"] == "lalr" and regen.OPTIONS["propagate_positions"]

