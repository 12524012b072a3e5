"""The AST printer: one writer of .mcm source from a tree, in `mercmac fmt`'s layout.

`mercmac.fmt.printer` prints a tree of `mercmac.compiler.ast`; the decompiler builds such
trees and prints them there instead of writing text of its own. What the printer writes
parses back to the same tree and is already formatted: fmt and the printer share one layout
(mercmac.fmt.layout).
"""
from __future__ import annotations

import ast as python_ast
from pathlib import Path

import pytest

import mercmac
from mercmac.compiler import ast
from mercmac.compiler.ast_builder import parse_module
from mercmac.diagnostics import Report
from mercmac.fmt import format_text, printer

ROOT = Path(mercmac.__file__).parent.parent
EXAMPLES = sorted((ROOT / "examples" / "macros").glob("*.mcm"))
_SPANS = ("span", "word_span")


def _tree(text: str) -> ast.Module:
    module = parse_module(text, Report("example.mcm")).tree
    assert module is not None
    return module


def _shape(node):
    """A node without its spans, mnemonics upper case (fmt writes them so)."""
    if isinstance(node, ast.Command):
        node = node._replace(word=node.word.upper())
    if isinstance(node, tuple) and hasattr(node, "_fields"):
        return type(node)(*(None if field in _SPANS else _shape(value)
                            for field, value in zip(node._fields, node)))
    if isinstance(node, tuple):
        return tuple(map(_shape, node))
    return node


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_a_printed_tree_parses_back_to_the_same_tree(path):
    module = _tree(path.read_text(encoding="utf-8"))
    printed = printer.module(module.items)
    assert _shape(_tree(printed)) == _shape(module)


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_a_printed_tree_is_in_fmts_layout(path):
    printed = printer.module(_tree(path.read_text(encoding="utf-8")).items)
    assert format_text(printed) == printed


def test_comments_beside_the_tree_stand_in_fmts_columns():
    scan = ast.MacroDef("scan", None, (ast.Command("MR", ast.Number(5000, None), None, None),
                                       ast.Call("home", None)), None)
    items = [printer.Comment("// two macros"), printer.Commented(scan, "// MC05"),
             printer.RawText(9, "EMXX")]
    printed = printer.module(items)
    assert printed == ("// two macros\n\nmacro scan {   // MC05\n    MR 5000, call home\n}\n\n"
                       "[MC09] EMXX\n")
    assert format_text(printed) == printed


def test_the_decompiler_writes_no_layout_of_its_own():
    """Braces, indentation and `, ` between statements are the printer's: decompile/source.py
    builds nodes (its strings are comments and reasons, not code)."""
    tree = python_ast.parse((ROOT / "mercmac" / "decompile" / "source.py").read_text(encoding="utf-8"))
    docstrings = {id(node.body[0].value) for node in python_ast.walk(tree)
                  if isinstance(node, (python_ast.Module, python_ast.ClassDef, python_ast.FunctionDef))
                  and node.body and isinstance(node.body[0], python_ast.Expr)}
    layout = [(node.lineno, node.value) for node in python_ast.walk(tree)
              if isinstance(node, python_ast.Constant) and isinstance(node.value, str)
              and id(node) not in docstrings
              and any(mark in node.value for mark in ("{", "}", "    ", ", "))]
    assert layout == []
