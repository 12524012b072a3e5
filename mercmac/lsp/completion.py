"""Completion: the words that may stand at the cursor, read from the text before it.

The grammar (mercmac/grammar.lark) says what may come where:
  - nothing in a comment, nor where a new name or a number is typed (`const X = `, `macro `);
  - in a raw `[MCnn]` line, mnemonics after the header or a comma (it holds native
    commands and plain numbers only, MS176E §3.8.6);
  - the models after `target`, durations after `every`, macro names after `call`/`goto`,
    consts after a mnemonic that takes a number, after `repeat` and in a `when` condition;
  - where a statement starts (a line's start, after `,`, `{` or `}`): at the top level
    the items' keywords, in a block the statements' keywords and the mnemonics.
"""
from __future__ import annotations

import re
from typing import NamedTuple

from mercmac.commands import Arg, lookup
from mercmac.source import split_lines

# The word being typed: the client matches it against the labels itself.
_TYPED = re.compile(r"[A-Za-z0-9_.?+-]*\Z")
_RAW = re.compile(r"[ \t]*\[")
_RAW_NEXT = re.compile(r"(\]|,)[ \t]*\Z")
_STATEMENT_END = re.compile(r"[,{}]")  # what ends a statement (grammar.lark `block`)
TOP_LEVEL = ("target", "const", "macro", "autostart")
IN_BLOCK = ("call", "goto", "when", "repeat", "every")
DURATIONS = (20, 50, 100, 250, 500, 1000)  # ms: polling periods people choose


class Offer(NamedTuple):
    """What may stand at the cursor: kinds of word ('keywords', 'mnemonics', 'models',
    'durations', 'macros', 'consts'), and which keywords."""

    kinds: tuple[str, ...]
    keywords: tuple[str, ...] = ()


NOTHING = Offer(())
_AFTER = {"target": Offer(("models",)), "every": Offer(("durations", "consts")),
          "call": Offer(("macros",)), "goto": Offer(("macros",)), "repeat": Offer(("consts",)),
          "when": Offer(("keywords", "consts"), ("not",)),
          "and": Offer(("keywords", "consts"), ("not",)), "not": Offer(("consts",))}


def offer(before: str, depth: int) -> Offer:
    """What may follow `before` (the cursor's line up to it) at brace depth `depth`."""
    if "//" in before:  # a comment runs to the end of its line (and no string holds `//`)
        return NOTHING
    head = before[:len(before) - len(_TYPED.search(before).group())]
    if _RAW.match(before):
        return Offer(("mnemonics",)) if _RAW_NEXT.search(head) else NOTHING
    words = _STATEMENT_END.split(head)[-1].split()
    if not words:
        return Offer(("keywords", "mnemonics"), IN_BLOCK) if depth > 0 else \
            Offer(("keywords",), TOP_LEVEL)
    if not head[-1:].isspace():  # `@`, `=`, ...: a number or a name of one's own comes
        return NOTHING
    if words[0] == "when":  # conditions: `when not 1 and 2`
        return _AFTER.get(words[-1], NOTHING) if len(words) > 1 else _AFTER["when"]
    if len(words) > 1:
        return NOTHING
    command = lookup(words[0]) if depth > 0 else None
    if command is not None:
        return Offer(("consts",)) if command.arg is not Arg.NONE else NOTHING
    return _AFTER.get(words[0], NOTHING)


def depth_at(text: str) -> int:
    """How many blocks are open at the end of `text` (braces outside comments)."""
    depth = 0
    for line in split_lines(text):
        code = line.split("//", 1)[0]
        depth += code.count("{") - code.count("}")
    return max(depth, 0)
