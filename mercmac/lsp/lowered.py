"""What the controller will hold, shown where the user types: the slot each macro and
each hoisted block takes (inlay hints), the file's slot budget, and the MD lines of each
macro as `mercmac build` writes them (code lenses).

Plain data for the server's views (mercmac.lsp.views); positions are the compiler's 1-based
lines and columns. Everything is read off the lowered program, so a file with syntax
errors (no program) shows none of it.
"""
from __future__ import annotations

from typing import NamedTuple

from mercmac.compiler import ast
from mercmac.compiler.program import MAX_COMMANDS, SLOTS, Macro, Program
from mercmac.mdtext import slot_name
from mercmac.ops import USER_ORIGINS, Origin

# The client command a "build" lens runs with {"macro": name, "lines": [MD lines]}:
# the VS Code extension copies the lines (docs/editors.md, ## VS Code).
COPY_BUILD = "mercmac.copyBuild"
# The client command the "simulate" lens on `autostart` runs with {"uri": the document's}:
# the VS Code extension opens `sim FILE --web` beside the editor (docs/editors.md, ## VS Code).
SIMULATE = "mercmac.simulate"


class Hint(NamedTuple):
    """A label at (line, column), 1-based, and what hovering it tells (Markdown)."""

    line: int
    column: int
    label: str
    tooltip: str


class Lens(NamedTuple):
    """A block's header line, the lens title, and what its command copies."""

    line: int
    title: str
    macro: str
    lines: tuple[str, ...]


def hints(items: tuple, program: Program | None, text_line) -> list[Hint]:
    """The slot budget on line 1, then per line the slots lowering gave what starts there:
    a macro's header its own slot(s), a `when`, `repeat`, `every` or the rest after one its
    hidden slot, an inlined `call` the hidden slots of the macro it copies.
    `text_line(n)` is the n-th line of the document's text."""
    if program is None:
        return []
    by_line: dict[int, list[Macro]] = {}
    for macro, line in _placed(items, program):
        by_line.setdefault(line, []).append(macro)
    out = [_budget(program, text_line(1))]
    for line in sorted(by_line):
        macros = sorted(by_line[line], key=_build_order)
        out.append(Hint(line, _line_end(text_line(line)),
                        ", ".join(slot_name(m.slot) for m in macros),
                        "\n".join(f"- {m.written}: `{m.md}` ({_count(m)})" for m in macros)))
    return out


def _budget(program: Program, first: str) -> Hint:
    """'9 of 32 slots' at the end of the first line (MS176E §3.8: macros 0 to 31)."""
    used = sorted(program.macros.values(), key=_build_order)
    free = _runs([s for s in SLOTS if s not in program.macros])
    tooltip = "\n".join([f"- {m.written}" for m in used] + [f"- free: {free or 'none'}"])
    # at the very end of the line: a first line is often a comment, and a label before it
    # would stand at column 1
    return Hint(1, len(first.rstrip()) + 1, f"{len(used)} of {len(SLOTS)} slots", tooltip)


def _runs(slots: list[int]) -> str:
    """'MC09-MC12, MC20' for slots 9 to 12 and 20."""
    runs: list[list[int]] = []
    for slot in slots:
        if runs and runs[-1][-1] == slot - 1:
            runs[-1].append(slot)
        else:
            runs.append([slot])
    return ", ".join(slot_name(r[0]) if len(r) == 1 else f"{slot_name(r[0])}-{slot_name(r[-1])}"
                     for r in runs)


def _placed(items: tuple, program: Program):
    """(macro, line its hint goes on) for each lowered macro but the raw blocks, which name
    their slot already."""
    blocks = {_key(i): i for i in items if isinstance(i, (ast.MacroDef, ast.Autostart))}
    for macro in program.macros.values():
        if macro.origin is Origin.RAW or macro.span is None:
            continue
        owner = blocks.get(macro.name.partition(".")[0])
        if macro.origin in USER_ORIGINS or (macro.origin is Origin.PART  # of the macro
                                            and "." not in macro.name.rpartition(".")[0]):
            if owner is not None:
                yield macro, owner.span.line
        elif owner is None or _within(macro.span.line, owner):
            yield macro, macro.span.line
        else:  # a block of a macro the owner's `call` copied in (inlined)
            yield from ((macro, line) for line in _calls_of(owner, macro.span.line, blocks))


def _build_order(macro: Macro) -> tuple[bool, int]:
    """By slot, macro 0 last: the order `build` writes them (Program.ordered)."""
    return macro.slot == 0, macro.slot


def _key(item) -> str:
    return item.name if isinstance(item, ast.MacroDef) else "autostart"


def _within(line: int, item) -> bool:
    return item.span.line <= line <= max(item.span.end_line or item.span.line, item.span.line)


def _calls_of(owner, line: int, blocks: dict) -> list[int]:
    """The lines of the owner's calls of the macro written around `line`."""
    source = next((name for name, item in blocks.items() if _within(line, item)), None)
    return [s.span.line for s in _statements(owner.body)
            if isinstance(s, ast.Call) and s.name == source]


def _statements(body: tuple):
    for s in body:
        yield s
        yield from _statements(getattr(s, "body", ()))


def _line_end(text: str) -> int:
    """The column after the line's last character that is not a comment or a blank."""
    cut = text.find("//")
    return len((text if cut < 0 else text[:cut]).rstrip()) + 1


def _count(macro: Macro) -> str:
    return f"{len(macro.ops)} of {MAX_COMMANDS} commands"


def lenses(items: tuple, program: Program | None, errors: int = 0) -> list[Lens]:
    """A "build" lens on each macro, the autostart block and each raw block: its MD lines;
    with `errors` in the file, `build` writes none, so the lens says so and copies nothing."""
    if program is None:
        return []
    out = []
    for item in items:
        if isinstance(item, ast.RawBlock):
            mine = [program.macros[item.slot]] if item.slot in program.macros else []
            name = slot_name(item.slot)
        elif isinstance(item, (ast.MacroDef, ast.Autostart)):
            name = _key(item)
            mine = of_macro(name, program)
        else:
            continue
        if mine and errors:
            out.append(Lens(item.span.line, f"build: {_slots(mine)}, not built while the file "
                                             f"has {errors} error{'s' * (errors > 1)}", name, ()))
        elif mine:
            out.append(Lens(item.span.line, _title(mine), name, tuple(m.md for m in mine)))
    return out


def simulate(items: tuple, errors: int = 0) -> Lens | None:
    """The "simulate" lens on the autostart block, which the box runs at power-on; with
    `errors` in the file `sim` refuses it, so the lens says so."""
    start = next((item for item in items if isinstance(item, ast.Autostart)), None)
    if start is None:
        return None
    if errors:
        return Lens(start.span.line, f"simulate: not while the file has {errors} "
                                     f"error{'s' * (errors > 1)}", "autostart", ())
    return Lens(start.span.line, "▶ simulate: the box and the stage", "autostart", ())


def _title(mine: list[Macro]) -> str:
    if len(mine) == 1:
        return f"build: {slot_name(mine[0].slot)}, {_count(mine[0])} (copy the MD line)"
    return (f"build: {_slots(mine)} "
            f"(copy {len(mine)} MD lines)")


def _slots(mine: list[Macro]) -> str:
    return ", ".join(slot_name(m.slot) for m in mine)


def of_macro(name: str, program: Program) -> list[Macro]:
    """The lowered macros of a named macro (or `autostart`): its own slot(s) and the ones
    made from its blocks, by slot."""
    return sorted((m for m in program.macros.values()
                   if m.name == name or m.name.startswith(name + ".")), key=_build_order)


def count_lines(mine: list[Macro]) -> str:
    """'MC01: 5 of 16 commands' per slot, for a hover under the MD lines."""
    return "; ".join(f"{slot_name(m.slot)}: {_count(m)}" for m in mine)
