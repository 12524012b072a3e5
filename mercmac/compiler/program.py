"""The lowered program: slots of base commands, exactly what goes to the controller.

The simulator assembles these, the uploader writes their `MD` lines; both
show macro names, not numbers, through `Macro.name` and the spans of `Op`.
"""
from __future__ import annotations

from typing import Mapping

from mercmac import mdtext
from mercmac.ops import Op, Origin
from mercmac.source import Span

MAX_COMMANDS = mdtext.MAX_COMMANDS  # MS176E §3.8: "Each macro can contain up to 16 base commands"
SLOTS = range(32)  # MS176E §3.8.4: macros 0 to 31, 0 = autostart
MAX_RP = 32_568  # MS176E §6.4 RP: n <= 32568
MAX_WA = 65_535  # MS176E §6.4 WA: n <= 65535 ms
MAX_WAITS = MAX_COMMANDS  # a period lowers to at most this many WAs (one macro of waits)


def rp_counts(times: int) -> tuple[int, ...] | None:
    """The RP arguments that run a line `times` times (>= 1), or None.

    One `RP n` runs the line n+1 times; `RP a,RP b` runs it (a+1)(b+1) times:
    RP b jumps back to the start, and RP a, whose counter was forgotten when
    it fell through, starts again (docs/simulator.md; the manual's `RP,RP`, §3.8.6).
    """
    if times - 1 <= MAX_RP:
        return (times - 1,)
    for a in range(2, MAX_RP + 2):
        if times % a == 0 and times // a - 1 <= MAX_RP:
            return (a - 1, times // a - 1)
    return None


def wait_pieces(ms: int) -> list[int]:
    """A wait of `ms` as WA arguments of at most 65535 each, as even as can be."""
    n = max(1, -(-ms // MAX_WA))
    return [ms // n + (1 if i < ms % n else 0) for i in range(n)]


class Macro:
    """One slot's contents, with the name and source span it came from."""

    __slots__ = ("slot", "name", "ops", "span", "origin")

    def __init__(self, slot: int, name: str, ops: list[Op] | None = None,
                 span: Span | None = None, origin: Origin | str = Origin.RAW):
        self.slot, self.name, self.span = slot, name, span
        self.ops: list[Op] = [] if ops is None else ops
        self.origin = Origin(origin)

    def __repr__(self) -> str:
        return f"Macro({self.slot}, {self.name!r}, {self.line!r}, origin={self.origin.value!r})"

    def __eq__(self, other) -> bool:
        return isinstance(other, Macro) and all(
            getattr(self, a) == getattr(other, a) for a in self.__slots__)

    @property
    def line(self) -> str:
        """The command line as stored: 'MR5000,WS100'."""
        return mdtext.format_ops(self.ops)

    @property
    def md(self) -> str:
        """The definition sent to the controller: 'MD5,MR5000,WS100' (MS176E §3.8.1)."""
        return mdtext.md(self.slot, self.ops)  # a bare `MDn` for an empty raw `[MCnn]` only

    @property
    def label(self) -> str:
        """'main (MC05)' for named macros, 'MC05' for raw ones."""
        tag = mdtext.slot_name(self.slot)
        return tag if self.name == tag else f"{self.name} ({tag})"

    @property
    def written(self) -> str:
        """How a diagnostic names it: the label, but a macro the compiler made by the block
        the user wrote, 'the `repeat` at line 30 (MC03)' (see `as_written`)."""
        if "." not in self.name:
            return self.label
        return f"{as_written(self.name)} ({mdtext.slot_name(self.slot)})"


_BLOCKS = ("when", "repeat", "every")


def as_written(name: str) -> str:
    """A macro's name in the user's terms. Compiler-made names (lower.py `helper`,
    `part_name`) are the owner's name and a step, 'jog.when@29.repeat@30', 'jog.rest@31',
    'jog.part2': no user wrote them, so a block is named by its kind and line, a rest by
    the user's macro and the line it starts at, a part by what it is a part of."""
    owner, _, step = name.rpartition(".")
    if not owner:
        return name  # a user's macro, 'autostart' or 'MC05': names have no '.'
    kind, _, where = step.partition("@")
    line, _, column = where.partition(":")
    at = f"line {line}, column {column}" if column else f"line {line}"
    if kind in _BLOCKS:
        return f"the `{kind}` at {at}"
    if kind == "rest":
        return f"the rest of {name.partition('.')[0]} from {at}"
    return f"part {step.removeprefix('part')} of {as_written(owner)}"


class Program:
    """All macros of one compiled file, by slot."""

    __slots__ = ("macros", "target", "file", "inlined", "expected")

    def __init__(self, macros: dict[int, Macro], target: str | None = None, file: str = "",
                 inlined: frozenset = frozenset(),
                 expected: Mapping[int, frozenset[str]] | None = None):
        self.macros, self.target, self.file = macros, target, file
        self.inlined = inlined  # named macros whose body also runs in place of a call
        # hazard rules a line's `// mercmac: expect[...]` accepts, by line (mercmac.suppress)
        self.expected: Mapping[int, frozenset[str]] = expected or {}

    def __repr__(self) -> str:
        return f"Program({self.macros!r}, target={self.target!r}, file={self.file!r})"

    def __eq__(self, other) -> bool:
        return isinstance(other, Program) and (self.macros, self.target, self.file) == (
            other.macros, other.target, other.file)

    def ordered(self) -> list[Macro]:
        """Slot order with macro 0 last: the safe upload order
        (docs/uploader.md, "A flash, step by step")."""
        return sorted(self.macros.values(), key=lambda m: (m.slot == 0, m.slot))

    def md_lines(self) -> list[str]:
        return [m.md for m in self.ordered()]

    def names(self) -> dict[int, str]:
        return {slot: m.name for slot, m in self.macros.items()}
