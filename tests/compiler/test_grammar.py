"""The stand-alone parser is generated from grammar.lark and parses like lark itself."""
from __future__ import annotations

import os
import subprocess
import sys

import pytest

from helpers.paths import EXAMPLE_FILES
from mercmac.compiler import parser_tables, regen
from mercmac.compiler.parse import parser


def test_parser_tables_are_generated_from_the_current_grammar():
    assert parser_tables.GRAMMAR_SHA256 == regen.grammar_digest(), (
        "grammar.lark changed: run `python -m mercmac.compiler.regen`")


@pytest.mark.parametrize("path", EXAMPLE_FILES, ids=lambda p: p.name)
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


def test_regen_writes_the_same_file_in_every_process():
    """Two runs (two hash seeds) give byte-identical tables: no noisy diffs for contributors."""
    pytest.importorskip("lark")
    code = "import sys; from mercmac.compiler.regen import generate; sys.stdout.write(generate())"
    runs = {subprocess.run([sys.executable, "-c", code], capture_output=True, encoding="utf-8",
                           env={**os.environ, "PYTHONHASHSEED": seed},
                           check=True).stdout for seed in ("1", "2")}
    assert len(runs) == 1
    assert runs.pop() == regen.TABLES.read_text(encoding="utf-8")
