"""The syntax tree of a .mcm file: immutable records with spans (docs/language.md).

NamedTuples rather than dataclasses: they are several times cheaper to
define, and `mercmac check` runs on every save.
"""
from __future__ import annotations

from typing import NamedTuple, Union

from mercmac.mdtext import MAX_DIGITS
from mercmac.source import Span


class Number(NamedTuple):
    value: int
    span: Span


class Name(NamedTuple):
    name: str
    span: Span  # with the sign, if it has one
    sign: str = ""  # a command's argument may be `-FAR` (the const negated) or `+FAR`

    @property
    def name_span(self) -> Span:
        """Where the name itself stands: after its sign and blanks, at the end of the value."""
        if not self.sign:
            return self.span
        s = self.span
        return Span(s.end_line, s.end_column - len(self.name), s.end_line, s.end_column)


class Invalid(NamedTuple):
    """A number that cannot be used (too many digits, not whole milliseconds): the rule,
    its message variant and the values to report where it is used."""

    rule: str
    variant: str
    values: tuple  # ((field, value), ...): hashable, as the AST is
    span: Span
    value = None  # as a pin or a count it is no slot and no number


# A literal of more than mdtext.MAX_DIGITS digits becomes an Invalid (a slot number: TOO_BIG).
TOO_BIG = 10 ** MAX_DIGITS

Value = Union[Number, Name, Invalid]


class Command(NamedTuple):
    """A native command as written: `word` is the mnemonic text in its own case."""

    word: str
    value: Value | None
    span: Span
    word_span: Span


class Call(NamedTuple):
    name: str
    span: Span


class Goto(NamedTuple):
    name: str
    span: Span


class Condition(NamedTuple):
    value: Value
    negated: bool
    span: Span


class When(NamedTuple):
    conditions: tuple[Condition, ...]
    body: tuple["Stmt", ...]
    span: Span


class Repeat(NamedTuple):
    count: Value
    body: tuple["Stmt", ...]
    span: Span


class Every(NamedTuple):
    period: Value  # milliseconds
    body: tuple["Stmt", ...]
    span: Span


Stmt = Union[Command, Call, Goto, When, Repeat, Every]


class RawBlock(NamedTuple):
    """`[MCnn] CMD,CMD,...` exactly as MMCRun writes it (MS176E §3.8.6)."""

    slot: int
    commands: tuple[Command, ...]
    span: Span


class MacroDef(NamedTuple):
    name: str
    pin: Number | None
    body: tuple[Stmt, ...]
    span: Span


class Autostart(NamedTuple):
    body: tuple[Stmt, ...]
    span: Span


class Target(NamedTuple):
    model: str
    span: Span


class Const(NamedTuple):
    name: str
    value: int | Invalid
    span: Span


Item = Union[RawBlock, MacroDef, Autostart, Target, Const]


class Module(NamedTuple):
    items: tuple[Item, ...]
