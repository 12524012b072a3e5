"""Re-checking on every keystroke: the same checker, with each top-level block parsed once.

Parsing is most of a compile (about 90% of one for a program of 32 slots), and an edit
touches one block. So the text is cut into chunks at lines that start a top-level item
(`macro`, `autostart`, `const`, `target`, `[MCnn]`) outside any braces; each chunk is
parsed and built on its own, once per distinct text, and the items are moved to their
lines. The checks, lowering and flow checks then run on the whole module, as
`compile_source` runs them. A chunk with a syntax error sends the whole text to
`compile_source`, so broken files get exactly its diagnostics. Lines end at LF, CRLF or
CR (mercmac.source.LINE_END), as the compiler and the editor count them.
"""
from __future__ import annotations

import re
from typing import NamedTuple

from mercmac.compiler import Compilation, compile_source
from mercmac.compiler import ast
from mercmac.diagnostics import Report
from mercmac.source import LINE_END, Source, Span, split_lines

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
    first, depth = 0, 0
    starts = [0, *(m.end() for m in LINE_END.finditer(text))]  # where each line starts
    for number, line in enumerate(split_lines(text)):
        if number and depth <= 0 and _ITEM.match(line):
            out.append((first, text[starts[first]:starts[number]]))
            first = number
        code = line.split("//", 1)[0]
        depth += code.count("{") - code.count("}")
    out.append((first, text[starts[first]:]))
    return out


def shifted(node, lines: int):
    """`node` (a span, an AST node or a tuple of them) with every span moved down by `lines`."""
    kind = type(node)
    if kind is Span:
        return Span(node[0] + lines, node[1], node[2] + lines if node[2] else 0, node[3])
    moved = [shifted(x, lines) if isinstance(x, tuple) else x for x in node]
    return tuple(moved) if kind is tuple else kind._make(moved)


class Rechecker:
    """Checks successive versions of one document, reusing the blocks that did not change."""

    def __init__(self, name: str, target: str | None = None):
        self.name, self.target = name, target
        self._parsed: dict[str, tuple | None] = {}  # chunk text -> its items at line 1
        self._placed: dict[tuple[int, str], tuple] = {}  # (offset, text) -> items in place
        self._last: Checked | None = None  # the last check that parsed

    def check(self, text: str) -> Checked:
        """Diagnostics and program of `text`, equal to `compile_source(Source(name, text))`."""
        from mercmac.compiler.parse import paused_gc

        with paused_gc():  # the AST makes no cycles; collecting rescans it all (half the time)
            return self._check(text)

    def _check(self, text: str) -> Checked:
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
            self._last = None
            return Checked(compile_source(source, self.target), None, tuple(items))
        module = ast.Module(tuple(items))
        last = self._last
        if last is not None and last.module == module:  # typed in a comment: same findings
            return last._replace(compilation=last.compilation._replace(source=source))
        self._last = Checked(self._compile(source, module), module, module.items)
        return self._last

    def _compile(self, source: Source, module: ast.Module) -> Compilation:
        """`compile_source` from the AST on (mercmac/compiler/__init__.py)."""
        from mercmac.compiler.checks import check_module
        from mercmac.compiler.lower import lower
        from mercmac.compiler.program_checks import check_program

        report = Report(source.name)
        env = check_module(module, report, self.target.upper() if self.target else None)
        program = lower(module, env, report, source.name)
        check_program(program, report)
        return Compilation(source, report, program)


def _parse(chunk: str) -> tuple | None:
    """The items of one chunk, spans counted from its first line; None on a syntax error."""
    from mercmac.compiler.ast_builder import parse_module

    report = Report("")
    parsed = parse_module(chunk, report)
    if parsed.failed or report.items:
        return None
    return parsed.tree.items
