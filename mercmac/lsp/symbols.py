"""What stands where in a checked document: names, slots, commands, keywords, and what to
say about them.

Plain data for the server (mercmac.lsp.server) to turn into LSP messages; positions are
the compiler's 1-based spans, end column exclusive. A slot is one thing however it is
written: `[MCnn]`, `EMn` in a raw line or a block, and the macro whose name the compiler
gave that slot (`macro scan @11`, or allocated), so that definition and references
follow `EM11` to `[MC11]` and `call scan` alike.
"""
from __future__ import annotations

import re
from typing import NamedTuple

from mercmac.commands import COMMANDS, Mnemonic
from mercmac.compiler import ast
from mercmac.compiler.checks import name_span
from mercmac.compiler.parse import KEYWORDS  # noqa: F401  (completion and rename use them)
from mercmac.compiler.program import Program, wait_pieces
from mercmac.lsp import lowered
from mercmac.mdtext import slot_name
from mercmac.ops import Origin
from mercmac.render.commands import KEYWORD_HELP  # noqa: F401  (hover and completion)
from mercmac.source import Source, Span
from mercmac.timespec import format_span

NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_.]*\Z")
_DEFINES = {ast.MacroDef: re.compile(r"macro\s+([A-Za-z_][A-Za-z0-9_.]*)"),
            ast.Const: re.compile(r"const\s+([A-Za-z_][A-Za-z0-9_.]*)")}


class Use(NamedTuple):
    """A name or slot where it stands: its kind ('macro', 'const', or 'slot' for `[MCnn]`
    and `EMn`), its name ('MCnn' for a slot), whether it defines it, and the slot it
    stands for when that is known (a macro's after lowering or its pin)."""

    kind: str
    name: str
    span: Span
    defines: bool
    slot: int | None = None


def uses(items: tuple, source: Source, program: Program | None = None) -> list[Use]:
    """Every definition and use of a macro or const name and of a slot, in order."""
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
            found.append(_slot(item.slot, item.span, True))
            _walk(item.commands, found)
        elif isinstance(item, (ast.MacroDef, ast.Autostart)):
            _walk(item.body, found)
    slots = _named_slots(items, program)
    return [u._replace(slot=slots.get(u.name)) if u.kind == "macro" else u for u in found]


def _slot(number: int, span: Span, defines: bool) -> Use:
    return Use("slot", slot_name(number), span, defines, number)


def _named_slots(items: tuple, program: Program | None) -> dict[str, int]:
    """name -> slot of each named macro: where the compiler put it, else its pin."""
    if program is not None:
        return {m.name: m.slot for m in program.macros.values() if m.origin is Origin.MACRO}
    return {i.name: i.pin.value for i in items
            if isinstance(i, ast.MacroDef) and isinstance(i.pin, ast.Number)}


def same(found: list[Use], use: Use) -> list[Use]:
    """The uses that stand for what `use` stands for: one slot, or one name."""
    if use.slot is not None:
        return [u for u in found if u.slot == use.slot]
    return [u for u in found if (u.kind, u.name) == (use.kind, use.name)]


def _walk(body: tuple, found: list[Use]) -> None:
    for s in body:
        if isinstance(s, (ast.Call, ast.Goto)):
            found.append(Use("macro", s.name, name_span(s), False))
        elif isinstance(s, ast.Command):
            if s.word.upper() == Mnemonic.EM and isinstance(s.value, ast.Number):
                found.append(_slot(s.value.value, s.span, False))
            _value(s.value, found)
        elif isinstance(s, ast.When):
            for c in s.conditions:
                _value(c.value, found)
            _walk(s.body, found)
        elif isinstance(s, (ast.Repeat, ast.Every)):
            _value(s.count if isinstance(s, ast.Repeat) else s.period, found)
            _walk(s.body, found)


def _value(value, found: list[Use]) -> None:
    if isinstance(value, ast.Name):  # `-FAR`: the name without its sign, as rename rewrites it
        found.append(Use("const", value.name, value.name_span, False))


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
    """Hover text of a mnemonic: the text `mercmac explain MR` shows (mercmac.render.commands)."""
    from mercmac.render.commands import command_help as text

    return text(mnemonic)


def macro_help(name: str, program: Program | None, errors: bool = False) -> str:
    """Hover text of a macro name: its slots after lowering, their MD lines (as `build`
    writes them, or as lowered so far when the file has `errors`), its callers."""
    lines = [f"**macro {name}**"]
    if program is None:
        return lines[0] + _UNLOWERED
    mine = lowered.of_macro(name, program)
    if not mine:
        return lines[0] + "\n\n(no slot: not defined)"
    lines += ["", f"slot{'s' if len(mine) > 1 else ''}: "
              + ", ".join(slot_name(m.slot) for m in mine), "", "```", *(m.md for m in mine), "```",
              "", lowered.count_lines(mine), "", _called_by(mine[0].slot, program)]
    if errors:
        lines += ["", "(as lowered so far: `mercmac build` writes nothing while the file "
                      "has errors)"]
    return "\n".join(lines)


_UNLOWERED = "\n\n(not lowered: the file has syntax errors)"


def slot_help(slot: int, program: Program | None) -> str:
    """Hover text of a slot (`[MCnn]`, `EMn`): what it holds after lowering, who calls it."""
    head = f"**{slot_name(slot)}**"
    if program is None:
        return head + _UNLOWERED
    macro = program.macros.get(slot)
    if macro is None:
        return head + f"\n\n(empty: no block defines it, so EM{slot} does nothing; MS176E §6.4 EM)"
    return "\n".join([f"**{macro.written}**: {_ORIGINS[macro.origin]}", "", "```", macro.md,
                      "```", "", _called_by(slot, program)])


_ORIGINS = {Origin.RAW: "a raw block", Origin.MACRO: "a named macro",
            Origin.AUTOSTART: "the autostart block", Origin.WHEN: "a `when` body, hoisted",
            Origin.REPEAT: "a `repeat` body, hoisted", Origin.EVERY: "an `every` loop, hoisted",
            Origin.REST: "what follows a hoisted block", Origin.PART: "a part of a long block",
            Origin.STORED: "read from a controller"}


def _called_by(slot: int, program: Program) -> str:
    """'called by: jog (MC01), MC09' from the EMs of the lowered program."""
    if slot == 0:
        return "runs at power-on and reset: macro 0 is the autostart macro (MS176E §3.8.5)"
    callers = [m.written for m in program.ordered()  # a hoisted block by its line
               if any(op.mnemonic == Mnemonic.EM and op.arg == slot for op in m.ops)]
    return "called by: " + (", ".join(callers) if callers else
                            "no macro (only a host's EM runs it)")




def duration_help(written: str, ms: int) -> str:
    """Hover text of an `every` period: its WA commands and how often the loop polls."""
    waits = ",".join(f"{Mnemonic.WA}{n}" for n in wait_pieces(ms))
    if ms == 0:
        rate = "does not wait: a busy loop"
    elif ms <= 1000:
        rate = "polls once a second" if ms == 1000 else f"polls {1000 / ms:.3g} times a second"
    else:
        rate = f"polls once every {format_span(ms * 1000, digits=None)}"
    return (f"**{written}** = {ms:,} ms = `{waits}`; every {written} {rate} (plus one "
            "controller cycle for each command it runs, 1 ms by default)")


def period_at(items: tuple, line: int, column: int) -> ast.Number | None:
    """The period of the `every` whose duration is at (line, column)."""
    for item in items:
        for s in _statements(getattr(item, "body", ())):
            if isinstance(s, ast.Every) and isinstance(s.period, ast.Number) \
                    and inside(s.period.span, line, column):
                return s.period
    return None


def _statements(body: tuple):
    """Every statement of a body, nested ones too."""
    for s in body:
        yield s
        yield from _statements(getattr(s, "body", ()))


_WORD = re.compile(r"[A-Za-z_][A-Za-z0-9_.]*")


def keyword_at(text: str, column: int) -> tuple[str, int] | None:
    """The keyword of a line's `text` at 1-based `column`, and its first column; None
    in a comment or a raw line."""
    if text.lstrip().startswith("["):
        return None
    comment = text.find("//")
    for m in _WORD.finditer(text):
        if m.start() < column <= m.end() + 1 and (comment < 0 or m.start() < comment):
            return (m.group(), m.start() + 1) if m.group() in KEYWORD_HELP else None
    return None


def partial_items(text: str) -> tuple:
    """The items of a text with syntax errors as far as they parse, as compile_source
    reads them: a block with a broken line keeps the rest of its body."""
    from mercmac.compiler.ast_builder import parse_module
    from mercmac.compiler.parse import BROKEN
    from mercmac.diagnostics import Report

    parsed = parse_module(text, Report(""))
    if parsed.tree is None:
        return ()
    return tuple(i for i in parsed.tree.items if getattr(i, "name", None) != BROKEN)


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
    """(mnemonic, argument hint, summary) of every command a macro may hold (MS176E §3.8)."""
    return [(c.mnemonic, c.expects(), c.summary) for c in COMMANDS.values() if c.storable]

