"""What stands where in a checked document: names, commands, and what to say about them.

Plain data for the server (mercmac.lsp.server) to turn into LSP messages; positions are
the compiler's 1-based spans, end column exclusive.
"""
from __future__ import annotations

import re
from typing import NamedTuple

from mercmac.commands import COMMANDS, lookup
from mercmac.compiler import ast
from mercmac.compiler.parse import KEYWORDS  # noqa: F401  (completion and rename use them)
from mercmac.compiler.program import Program
from mercmac.source import Source, Span, split_lines

NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_.]*\Z")
_TARGET = re.compile(r"[ \t]*target\b")
_DEFINES = {ast.MacroDef: re.compile(r"macro\s+([A-Za-z_][A-Za-z0-9_.]*)"),
            ast.Const: re.compile(r"const\s+([A-Za-z_][A-Za-z0-9_.]*)")}


class Use(NamedTuple):
    """A name where it stands: its kind ('macro' or 'const'), and whether it defines it."""

    kind: str
    name: str
    span: Span
    defines: bool


def uses(items: tuple, source: Source) -> list[Use]:
    """Every definition and use of a macro or const name, in order."""
    found: list[Use] = []
    for item in items:
        pattern = _DEFINES.get(type(item))
        if pattern:
            line = item.span.line
            m = pattern.match(source.line(line), item.span.column - 1)
            if m:
                kind = "macro" if isinstance(item, ast.MacroDef) else "const"
                found.append(Use(kind, m.group(1), Span(line, m.start(1) + 1, line, m.end(1) + 1),
                                 True))
        if isinstance(item, ast.RawBlock):
            _walk(item.commands, found)
        elif isinstance(item, (ast.MacroDef, ast.Autostart)):
            _walk(item.body, found)
    return found


def _walk(body: tuple, found: list[Use]) -> None:
    for s in body:
        if isinstance(s, (ast.Call, ast.Goto)):
            end = s.span.end_column
            found.append(Use("macro", s.name, Span(s.span.end_line, end - len(s.name),
                                                   s.span.end_line, end), False))
        elif isinstance(s, ast.Command):
            _value(s.value, found)
        elif isinstance(s, ast.When):
            for c in s.conditions:
                _value(c.value, found)
            _walk(s.body, found)
        elif isinstance(s, (ast.Repeat, ast.Every)):
            _value(s.count if isinstance(s, ast.Repeat) else s.period, found)
            _walk(s.body, found)


def _value(value, found: list[Use]) -> None:
    if isinstance(value, ast.Name):
        found.append(Use("const", value.name, value.span, False))


def inside(span: Span, line: int, column: int) -> bool:
    """Whether 1-based (line, column) lies in `span` or touches its end (a cursor after it)."""
    end_line = span.end_line or span.line
    return (span.line, span.column) <= (line, column) <= (end_line, span.end_column)


def use_at(found: list[Use], line: int, column: int) -> Use | None:
    return next((u for u in found if inside(u.span, line, column)), None)


def command_at(items: tuple, line: int, column: int) -> ast.Command | None:
    """The native command whose mnemonic is at (line, column)."""
    for item in items:
        span = item.span
        if not span.line <= line <= max(span.end_line, span.line):
            continue
        body = item.commands if isinstance(item, ast.RawBlock) else getattr(item, "body", ())
        found = _command_in(body, line, column)
        if found:
            return found
    return None


def _command_in(body: tuple, line: int, column: int):
    for s in body:
        if isinstance(s, ast.Command) and inside(s.word_span, line, column):
            return s
        inner = getattr(s, "body", None)
        if inner and s.span.line <= line <= s.span.end_line:
            found = _command_in(inner, line, column)
            if found:
                return found
    return None


def command_help(mnemonic: str) -> str | None:
    """Hover text of a mnemonic: the manual's description, argument, range, default, models."""
    c = lookup(mnemonic)
    if c is None:
        return None
    lines = [f"**{c.mnemonic}**: {c.summary} ({c.kind.value})", "", f"- argument: {c.expects()}"]
    if c.arg.value != "none":
        lines.append(f"- range: {c.range_text()}")
    if c.default is not None:
        lines.append(f"- default when omitted: {c.default}")
    lines.append(f"- models: {', '.join(sorted(c.models))}")
    if not c.storable:
        lines.append("- direct mode only: cannot be stored in a macro")
    lines.append(f"- manual: {c.section}")
    return "\n".join(lines)


def macro_help(name: str, program: Program | None) -> str:
    """Hover text of a macro name: its slots after lowering and their MD lines."""
    lines = [f"**macro {name}**"]
    if program is None:
        return lines[0] + "\n\n(not lowered: the file has syntax errors)"
    mine = slots_of(name, program)
    if not mine:
        return lines[0] + "\n\n(no slot: not defined)"
    lines += ["", f"slot{'s' if len(mine) > 1 else ''}: "
              + ", ".join(f"MC{m.slot:02d}" for m in mine), "", "```", *(m.md for m in mine), "```"]
    return "\n".join(lines)


def slots_of(name: str, program: Program) -> list:
    """The lowered macros of a named macro: its own slot and the ones made from its blocks."""
    return sorted((m for m in program.macros.values()
                   if m.name == name or m.name.startswith(name + ".")), key=lambda m: m.slot)


def const_help(name: str, items: tuple) -> str:
    value = next((i.value for i in items if isinstance(i, ast.Const) and i.name == name), None)
    if value is None:
        return f"**const {name}**\n\n(not defined)"
    shown = value if isinstance(value, int) else "(invalid)"
    return f"**const {name}** = {shown}"


def names(items: tuple) -> tuple[list[str], dict[str, int | None]]:
    """The macro names and the consts (with their values) defined in `items`."""
    macros = [i.name for i in items if isinstance(i, ast.MacroDef)]
    consts = {i.name: (i.value if isinstance(i.value, int) else None)
              for i in items if isinstance(i, ast.Const)}
    return macros, consts


def mnemonics() -> list[tuple[str, str, str]]:
    """(mnemonic, argument hint, summary) of every command of the table."""
    return [(c.mnemonic, c.expects(), c.summary) for c in COMMANDS.values()]


_GUESS = re.compile(r"did you mean '?([A-Za-z_][A-Za-z0-9_.?]*)'?\?")


def suggestion(message: str) -> str | None:
    """The replacement a "did you mean" message proposes."""
    m = _GUESS.search(message)
    return m.group(1) if m else None


def has_target(items: tuple, text: str) -> bool:
    if any(isinstance(i, ast.Target) for i in items):
        return True
    return any(_TARGET.match(line) for line in split_lines(text))


def target_line(text: str) -> int:
    """The 0-based line where a `target` line goes: after the leading comments and blank lines."""
    lines = split_lines(text)
    n = 0
    while n < len(lines) and (not lines[n].strip() or lines[n].lstrip().startswith("//")):
        n += 1
    return n
