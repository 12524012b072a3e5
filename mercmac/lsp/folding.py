"""Folding ranges: the blocks of a file (`macro`, `autostart`, `when`, `repeat`, `every`)
that span lines, from the AST's spans, and each run of two or more `//` comment lines.

Lines are 0-based here, as the LSP counts them. A block folds from its opening line to
the line before its closing brace when that brace starts its line (the brace stays in
sight, as an editor's own folding leaves it), else to its last line. A raw `[MCnn]`
block is one line (docs/language.md, "Programs and macros"): it never folds.
"""
from __future__ import annotations

from typing import NamedTuple

from mercmac.compiler import ast
from mercmac.source import split_lines

_BLOCKS = (ast.MacroDef, ast.Autostart, ast.When, ast.Repeat, ast.Every)


class Fold(NamedTuple):
    start: int  # 0-based lines
    end: int
    comment: bool = False


def folds(items: tuple, text: str) -> list[Fold]:
    """The folds of `items` and of the comments of `text`, by first line."""
    lines = split_lines(text)
    found = [f for f in _blocks(items, lines) if 0 <= f.start < f.end < len(lines)]
    return sorted(found + comment_runs(lines))


def _blocks(body: tuple, lines: list[str]):
    for node in body:
        if isinstance(node, _BLOCKS):
            span = node.span
            last = min(span.end_line or span.line, len(lines))
            closes = last > span.line and lines[last - 1].lstrip().startswith("}")
            yield Fold(span.line - 1, last - 2 if closes else last - 1)
            yield from _blocks(node.body, lines)


def comment_runs(lines: list[str]) -> list[Fold]:
    """Each run of two or more lines that hold nothing but a `//` comment."""
    found, first = [], None
    for number, text in enumerate([*lines, ""]):
        if text.lstrip().startswith("//"):
            first = number if first is None else first
            continue
        if first is not None and number - 1 > first:
            found.append(Fold(first, number - 1, comment=True))
        first = None
    return found
