"""The syntax tree of a .mcm file: frozen dataclasses with spans (SPEC §1)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Union

from mercmac.source import Span


@dataclass(frozen=True, slots=True)
class Number:
    value: int
    span: Span


@dataclass(frozen=True, slots=True)
class Name:
    name: str
    span: Span


Value = Union[Number, Name]


@dataclass(frozen=True, slots=True)
class Command:
    """A native command as written: `word` is the mnemonic text in its own case."""

    word: str
    value: Value | None
    span: Span
    word_span: Span


@dataclass(frozen=True, slots=True)
class Call:
    name: str
    span: Span


@dataclass(frozen=True, slots=True)
class Goto:
    name: str
    span: Span


@dataclass(frozen=True, slots=True)
class Condition:
    value: Value
    negated: bool
    span: Span


@dataclass(frozen=True, slots=True)
class When:
    conditions: tuple[Condition, ...]
    body: tuple["Stmt", ...]
    span: Span


@dataclass(frozen=True, slots=True)
class Repeat:
    count: Value
    body: tuple["Stmt", ...]
    span: Span


@dataclass(frozen=True, slots=True)
class Every:
    period: Value  # milliseconds
    body: tuple["Stmt", ...]
    span: Span


Stmt = Union[Command, Call, Goto, When, Repeat, Every]


@dataclass(frozen=True, slots=True)
class RawBlock:
    """`[MCnn] CMD,CMD,...` exactly as MMCRun writes it (MS176E §3.8.6)."""

    slot: int
    commands: tuple[Command, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class MacroDef:
    name: str
    pin: Number | None
    body: tuple[Stmt, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class Autostart:
    body: tuple[Stmt, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class Target:
    model: str
    span: Span


@dataclass(frozen=True, slots=True)
class Const:
    name: str
    value: int
    span: Span


Item = Union[RawBlock, MacroDef, Autostart, Target, Const]


@dataclass(frozen=True, slots=True)
class Module:
    items: tuple[Item, ...]
