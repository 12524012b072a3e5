"""Signature help: while a native command's argument is typed (`MR |`, `SV 80|`), the
command from the one command table (mercmac.commands): what it does and its facts as the
hover says them (mercmac.render.commands), and of its argument the range, the unit
distances count in and the value after power-on, for the model the file targets (both
models when none; MS176E §3.4).

The command is read from the cursor's line up to the cursor, as completion reads it
(mercmac.lsp.completion): the argument being typed is often a line that does not parse
yet, so the AST has no command there.
"""
from __future__ import annotations

import re
from typing import NamedTuple

from mercmac.commands import C663, C863, MODELS, Arg, Command, lookup, unit
from mercmac.compiler import ast
from mercmac.render.commands import command_help

# The statement the cursor is in: after a line's start, `,`, `{`, `}` or a raw header's `]`
# (grammar.lark `block`, `raw_block`); a mnemonic, then blanks or the argument so far.
_STATEMENT_END = re.compile(r"[,{}\]]")
_TYPING = re.compile(r"[ \t]*([A-Za-z]+\??)(?:[ \t]*[+-]?[ \t]*[A-Za-z0-9_.]*)\Z")
# Arguments that count distances, by the table's name of the argument, and what they are
# per: MS176E §6.4 MA, MR, SV, SA (the C-663 counts microsteps, §3.4.2).
_MEASURES = (("velocity", "/s"), ("acceleration", "/s²"), ("position", ""), ("distance", ""),
             ("increment", ""), ("window", ""), ("following error", ""))


class Signature(NamedTuple):
    """What the editor shows: the label (`MR n`, `WS [n]`), the argument's label within it,
    and the Markdown of the command and of its argument."""

    label: str
    parameter: str
    documentation: str
    argument: str


def command_typed(before: str) -> Command | None:
    """The command whose argument the cursor is in (one that takes an argument); `before`
    is the cursor's line up to it."""
    if "//" in before:  # a comment runs to the end of its line
        return None
    typed = _TYPING.match(_STATEMENT_END.split(before)[-1])
    if typed is None or typed.end(1) == typed.end():  # `MR|` may still become `MRX`
        return None
    command = lookup(typed.group(1))
    return None if command is None or command.arg is Arg.NONE else command


def model_of(target: str | None, items: tuple) -> str | None:
    """The model the file is checked for: the settings' or rig's, else its `target` line."""
    written = next((i.model for i in items if isinstance(i, ast.Target)), None)
    model = (target or written or "").upper()
    return model if model in MODELS else None


def signature(c: Command, model: str | None) -> Signature:
    """The signature of `c` on `model` (None: both models); its text is the hover's
    (mercmac.render.commands.command_help)."""
    parameter = "[n]" if c.arg is Arg.OPTIONAL else "n"
    return Signature(f"{c.mnemonic} {parameter}", parameter,
                     command_help(c.mnemonic) or c.summary, _argument(c, model))


def _argument(c: Command, model: str | None) -> str:
    """The argument's Markdown: what it is, its range and unit, its value after power-on."""
    lines = [f"**n**: {c.argument()}", "", f"- range: {c.range_text()}{_unit(c, model)}"]
    models = [m for m in ((model,) if model else MODELS) if m in c.models]
    lines += [f"- after power-on on the {m}: {v:,}" for m, v in c.power_on if m in models]
    if model and model not in c.models:
        lines.append(f"- not a command of the {model} (MS176E §6.2)")
    return "\n".join(lines)


def _unit(c: Command, model: str | None) -> str:
    per = next((p for word, p in _MEASURES if word in c.arg_name), None)
    if per is None:
        return ""
    if model:
        return f" {unit(model)}{per} ({model})"
    return f" {unit(C863)}{per} ({C863}) or {unit(C663)}{per} ({C663})"
