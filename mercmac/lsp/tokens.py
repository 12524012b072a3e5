"""Semantic tokens: what only the parse knows of a word, for the editor to colour.

The TextMate grammar (editors/vscode/syntaxes) colours the text: keywords, comments,
numbers. These tokens say what a word is, read from the AST's spans and symbols.uses (as
hover and rename read them), never from the text, so that a file with syntax errors gets
the tokens of what parses. Standard types, so that every theme colours them:

    native mnemonic (`MR`, `EM`)       function  + defaultLibrary (the controller's own)
    macro name                         function  (+ declaration at `macro NAME`)
    const name                         variable  + readonly (+ declaration at `const NAME`)
    slot: `[MCnn]`, a pin `@20`,       macro     (+ declaration at `[MCnn]`): a controller
      the number of `EMn`                        macro, MS176E §3.8
    a number (argument, condition,     number
      count, `every` period)
    anything in a raw `[MCnn]` line    + raw: the one modifier of our own (MMCRun's text,
                                       kept as written, docs/language.md "Programs and macros")

A mnemonic the command table does not know gets no token: it stays the grammar's colour,
with its diagnostic. Keywords and comments are left to the grammar.
"""
from __future__ import annotations

from typing import NamedTuple

from lsprotocol import types as t

from mercmac.commands import Mnemonic, lookup
from mercmac.compiler import ast
from mercmac.lsp import symbols
from mercmac.source import Source, Span

TYPES = ("function", "variable", "macro", "number")
MODIFIERS = ("declaration", "readonly", "defaultLibrary", "raw")
LEGEND = t.SemanticTokensLegend(token_types=list(TYPES), token_modifiers=list(MODIFIERS))
_NAMES = {"macro": ("function", ()), "const": ("variable", ("readonly",))}


class Token(NamedTuple):
    span: Span
    type: str
    modifiers: tuple[str, ...] = ()


def tokens(items: tuple, source: Source) -> list[Token]:
    """The tokens of `items` (the AST's, or those of a file with syntax errors as far as
    they parse), in the order of the text."""
    found = [_named(u) for u in symbols.uses(items, source)
             if u.kind != "slot" and symbols.NAME.match(u.name)]
    raw_lines = set()
    for item in items:
        if isinstance(item, ast.RawBlock):
            raw_lines.add(item.span.line)
            found.append(Token(item.span, "macro", ("declaration",)))
            found += _statements(item.commands)
        elif isinstance(item, ast.MacroDef):
            if isinstance(item.pin, ast.Number):
                found.append(Token(item.pin.span, "macro"))
            found += _statements(item.body)
        elif isinstance(item, ast.Autostart):
            found += _statements(item.body)
    found = [tok._replace(modifiers=tok.modifiers + ("raw",)) if tok.span.line in raw_lines
             else tok for tok in found]
    return sorted(found)  # by span: line, then column (a Token is a tuple, its span first)


def _named(use: symbols.Use) -> Token:
    kind, modifiers = _NAMES[use.kind]
    return Token(use.span, kind, modifiers + (("declaration",) if use.defines else ()))


def _statements(body: tuple, found: list | None = None) -> list[Token]:
    """The tokens of a body's statements, nested ones too, added to `found`."""
    found = [] if found is None else found
    for s in body:
        if isinstance(s, ast.Command):
            found += _command(s)
            continue
        if isinstance(s, ast.When):
            found += filter(None, (_number(c.value) for c in s.conditions))
        elif isinstance(s, (ast.Repeat, ast.Every)):
            number = _number(s.count if isinstance(s, ast.Repeat) else s.period)
            found += [number] if number else []
        _statements(getattr(s, "body", ()), found)
    return found


def _command(c: ast.Command) -> list[Token]:
    if lookup(c.word) is None:
        return []
    found = [Token(c.word_span, "function", ("defaultLibrary",))]
    if isinstance(c.value, ast.Number):
        slot = c.word.upper() == Mnemonic.EM
        found.append(Token(c.value.span, "macro" if slot else "number"))
    return found


def _number(value) -> Token | None:
    return Token(value.span, "number") if isinstance(value, ast.Number) else None


def encode(found: list[Token], document) -> list[int]:
    """The LSP's relative encoding of `found` (sorted) at the document's positions: five
    integers a token; one that spans lines, is empty or overlaps the one before is left out."""
    data: list[int] = []
    line = character = 0
    reached = (-1, -1)
    for tok in found:
        s = tok.span
        if (s.end_line or s.line) != s.line:
            continue
        start, stop = document.units(s.line, s.column), document.units(s.line, s.end_column)
        if start[0] != stop[0] or stop[1] <= start[1] or start < reached:
            continue
        data += [start[0] - line, start[1] - (character if start[0] == line else 0),
                 stop[1] - start[1], TYPES.index(tok.type),
                 sum(1 << MODIFIERS.index(m) for m in tok.modifiers)]
        (line, character), reached = start, stop
    return data
