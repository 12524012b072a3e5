"""Re-checking on every keystroke: the same checker, with each top-level block parsed once.

Parsing is most of a compile (about 90% of one for a program of 32 slots), and an edit
touches one block. So the text is cut into chunks at lines that start a top-level item
(`macro`, `autostart`, `const`, `target`, `[MCnn]`) outside any braces; each chunk is
parsed and built on its own, once per distinct text, and the items are moved to their
lines. The checks, lowering and flow checks then run on the whole module, as
`compile_source` runs them. A chunk with a syntax error sends the whole text to
`compile_source`, so broken files get exactly its diagnostics.
"""
from __future__ import annotations

import re
from typing import NamedTuple

from mercmac.compiler import Compilation, compile_source
from mercmac.compiler import ast
from mercmac.diagnostics import Report
from mercmac.source import Source, Span

# A line that may start a top-level item (grammar.lark `_item`).
_ITEM = re.compile(r"[ \t]*(macro\b|autostart\b|const\b|target\b|\[)")


class Checked(NamedTuple):
    """One check of one text: what `compile_source` gives, and the AST (None when a block
    does not parse; `items` then holds the items of the blocks that do)."""

    compilation: Compilation
    module: ast.Module | None
    items: tuple


def chunks(text: str) -> list[tuple[int, str]]:
    """(first line - 1, text) of each top-level chunk, in order; they join to `text`."""
    out: list[tuple[int, str]] = []
    start, depth = 0, 0
    lines = text.split("\n")
    for number, line in enumerate(lines):
        if number and depth <= 0 and _ITEM.match(line):
            out.append((start, "\n".join(lines[start:number]) + "\n"))
            start = number
        code = line.split("//", 1)[0]
        depth += code.count("{") - code.count("}")
    out.append((start, "\n".join(lines[start:])))
    return out


def shifted(node, lines: int):
    """`node` with every span moved down by `lines`."""
    if isinstance(node, Span):
        return Span(node.line + lines, node.column, node.end_line + lines, node.end_column)
    if isinstance(node, tuple):
        moved = [shifted(x, lines) if isinstance(x, tuple) else x for x in node]
        return type(node)(*moved) if hasattr(node, "_fields") else tuple(moved)
    return node


class Rechecker:
    """Checks successive versions of one document, reusing the blocks that did not change."""

    def __init__(self, name: str, target: str | None = None):
        self.name, self.target = name, target
        self._parsed: dict[str, tuple | None] = {}  # chunk text -> its items at line 1
        self._placed: dict[tuple[int, str], tuple] = {}  # (offset, text) -> items in place

    def check(self, text: str) -> Checked:
        """Diagnostics and program of `text`, equal to `compile_source(Source(name, text))`."""
        parsed, placed, items, whole = {}, {}, [], True
        for offset, chunk in chunks(text):
            local = self._parsed[chunk] if chunk in self._parsed else _parse(chunk)
            parsed[chunk] = local
            if local is None:
                whole = False
                continue
            key = (offset, chunk)
            here = self._placed.get(key)
            if here is None:
                here = shifted(local, offset) if offset else local
            placed[key] = here
            items += here
        self._parsed, self._placed = parsed, placed  # keep only what this version uses
        source = Source(self.name, text)
        if not whole or "\x00" in text:
            return Checked(compile_source(source, self.target), None, tuple(items))
        module = ast.Module(tuple(items))
        return Checked(self._compile(source, module), module, module.items)

    def _compile(self, source: Source, module: ast.Module) -> Compilation:
        """`compile_source` from the AST on (mercmac/compiler/__init__.py)."""
        from mercmac.compiler.checks import check_module
        from mercmac.compiler.lower import lower
        from mercmac.compiler.parse import paused_gc
        from mercmac.compiler.program_checks import check_program

        report = Report(source.name)
        with paused_gc():
            env = check_module(module, report, self.target.upper() if self.target else None)
        program = lower(module, env, report, source.name)
        check_program(program, report)
        return Compilation(source, report, program)


def _parse(chunk: str) -> tuple | None:
    """The items of one chunk, spans counted from its first line; None on a syntax error."""
    from mercmac.compiler.ast_builder import build
    from mercmac.compiler.parse import parse

    report = Report("")
    tree = parse(chunk, report)
    if tree is None or report.items:
        return None
    return build(tree).items
