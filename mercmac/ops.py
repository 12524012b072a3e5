"""The words of a lowered program: a base command (`Op`), why an EM is there (`Role`) and
where a macro came from (`Origin`).

A foundation module: mercmac.mdtext reads MD text into Ops, the compiler lowers a program
to them (mercmac.compiler.program), the VM, the emulator and the uploader run and send
them. It imports nothing of mercmac but the source positions, so none of those import
each other to name an Op (mdtext and compiler.program imported each other).
"""
from __future__ import annotations

from enum import Enum
from typing import NamedTuple

from mercmac.source import Span


class TextEnum(str, Enum):
    """A closed set of names that reads, compares, prints and dumps to JSON as its text."""

    def __str__(self) -> str:
        return self.value

    def __format__(self, spec: str) -> str:
        return format(self.value, spec)

    # equal to its text, so it hashes as its text (the C slot: no Python frame per hash)
    __hash__ = str.__hash__


class Role(TextEnum):
    """Why an EM is there."""

    NONE = ""  # not an EM
    RAW = "raw"  # written natively
    CALL = "call"
    GOTO = "goto"
    HOIST = "hoist"  # a `when`, `repeat` or `every` body moved into a macro of its own
    CONTINUE = "continue"  # the tail EM to a macro that continues a split block or the rest


class Origin(TextEnum):
    """Where a macro came from: written by the user, made by the compiler, or read back."""

    RAW = "raw"  # a `[MCnn]` block
    MACRO = "macro"
    AUTOSTART = "autostart"
    WHEN = "when"  # a hoisted `when` body
    REPEAT = "repeat"
    EVERY = "every"
    REST = "rest"  # the code after a hoisted block that calls out
    PART = "part"  # a piece of a block longer than 16 commands
    STORED = "stored"  # read from a controller (the emulator's flash memory)


USER_ORIGINS = (Origin.RAW, Origin.MACRO, Origin.AUTOSTART)  # what the user wrote


class Op(NamedTuple):
    """One base command of a lowered macro.

    `mnemonic` is the key of `mercmac.commands.COMMANDS` (upper case, 'FA?'
    for queries); `arg` is None when omitted. For EM, `role` says why it is there.
    """

    mnemonic: str
    arg: int | None = None
    span: Span | None = None
    role: Role = Role.NONE

    @property
    def text(self) -> str:
        return self.mnemonic if self.arg is None else f"{self.mnemonic}{self.arg}"
