"""How .mcm code is written: each token's spelling, the blanks between tokens, indentation,
and the column of trailing comments (docs/cli.md). One canonical layout for two writers:
`mercmac fmt` lays out the tokens of a user's file with it, keeping the user's line breaks
(mercmac.fmt), and the AST printer lays out a tree, choosing them (mercmac.fmt.printer).
"""
from __future__ import annotations

import re
from typing import Iterable, NamedTuple

INDENT = "    "  # per open brace
# The examples' house style: three spaces between the longest code of a run of
# commented lines and the column of its comments.
COMMENT_GAP = "   "
# Longer code is not aligned with its neighbours: padding 10,000 short lines to the column
# of one 1 MB line would write 10 GB (a hostile file once did).
ALIGN_WIDTH = 100

_BLANKS = re.compile(r"[ \t\f\v]+")
# Tokens written with their blanks dropped; MNEMONIC and MODEL also upper case.
_SQUEEZE = {"INT", "SIGNED_NAME", "DURATION", "MNEMONIC", "MODEL"}
_UPPER = {"MNEMONIC", "MODEL"}
_NO_SPACE_BEFORE = {"COMMA"}
_NO_SPACE_AFTER = {"AT"}


class Line(NamedTuple):
    """One line of the layout: how many braces are open before it, its code, its comment."""

    depth: int
    code: str
    comment: str


def space(previous: str | None, kind: str) -> str:
    """The blank between a token of kind PREVIOUS (None: none before it) and one of KIND:
    `MR 5000`, `when 1 and not 2`, `a, b`, `@20`."""
    if previous is None or kind in _NO_SPACE_BEFORE or previous in _NO_SPACE_AFTER:
        return ""
    return " "


def spell(kind: str, value: str) -> str:
    """A token as the canonical layout writes it."""
    if kind in _SQUEEZE and (" " in value or "\t" in value):
        value = _BLANKS.sub("", value)
    if kind in _UPPER:
        value = value.upper()
    if kind == "DURATION":
        value = value.lower()  # units read in any case (mercmac.timespec)
    return value


def code(tokens: Iterable[tuple[str, str]], previous: str | None = None) -> str:
    """Tokens (kind, text) written on one line, after a token of kind PREVIOUS (None: first)."""
    out = []
    for kind, value in tokens:
        out.append(space(previous, kind) + spell(kind, value))
        previous = kind
    return "".join(out)


def render(lines: list[Line | None]) -> str:
    """The text of LINES (None: a blank line), indented, trailing comments aligned, no blank
    line at the end."""
    while lines and lines[-1] is None:
        lines.pop()
    codes = ["" if line is None else INDENT * max(line.depth, 0) + line.code for line in lines]
    columns = _comment_columns(lines, codes)
    out = [code.ljust(column) + (line.comment if line else "")
           for line, code, column in zip(lines, codes, columns)]
    return "".join(line + "\n" for line in out)


def _comment_columns(lines: list[Line | None], codes: list[str]) -> list[int]:
    """Where each line's comment starts: for a run of consecutive lines that each end in a
    comment, COMMENT_GAP after the run's longest code; 0 (right after the code) elsewhere.
    A line longer than ALIGN_WIDTH is a run of its own."""
    columns = [0] * len(lines)
    run: list[int] = []
    for i, line in enumerate(lines):
        if line is not None and line.code and line.comment:  # code, then a comment
            if len(codes[i]) <= ALIGN_WIDTH:
                run.append(i)
                continue
            _align(columns, codes, [i])
        if run:
            _align(columns, codes, run)
            run = []
    _align(columns, codes, run)
    return columns


def _align(columns: list[int], codes: list[str], run: list[int]) -> None:
    if run:
        column = max(len(codes[i]) for i in run) + len(COMMENT_GAP)
        for i in run:
            columns[i] = column
