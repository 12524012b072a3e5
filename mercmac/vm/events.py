"""What the machine tells its observer, as plain records; times are microseconds."""
from __future__ import annotations

from dataclasses import dataclass

from mercmac.source import Span


@dataclass(frozen=True, slots=True)
class Where:
    """The instruction an event came from: macro label, slot, index and source span."""

    label: str
    slot: int
    ip: int
    span: Span | None

    @property
    def line(self) -> int | None:
        return self.span.line if self.span else None


@dataclass(frozen=True, slots=True)
class InputChanged:
    t: int
    input: int
    on: bool


@dataclass(frozen=True, slots=True)
class OutputsChanged:
    t: int
    pattern: int


@dataclass(frozen=True, slots=True)
class Reported:
    t: int
    text: str
    where: Where | None


@dataclass(frozen=True, slots=True)
class HazardFound:
    t: int
    rule: str
    message: str
    where: Where | None


@dataclass(frozen=True, slots=True)
class MoveStarted:
    """A profile started: kind is move, home search, stop, abort or joystick."""

    t: int
    kind: str
    target: int
    arrival: float  # us; inf when it never arrives
    segments: tuple  # profile.Segment records, for position plots (VCD)
    where: Where | None


@dataclass(frozen=True, slots=True)
class MoveEnded:
    """The profile ended: 'arrived' on target, or stopped by a hard 'limit'."""

    t: int
    how: str
    position: int


@dataclass(frozen=True, slots=True)
class HomeDefined:
    t: int
    position: int
    where: Where | None


@dataclass(frozen=True, slots=True)
class MacroEntered:
    t: int
    slot: int
    label: str
    via: str  # 'power-on', 'EM', 'host'


@dataclass(frozen=True, slots=True)
class MacroLeft:
    t: int
    slot: int
    label: str
    why: str  # 'end', 'XN1' (a failed condition), 'stopped'
    back_to: str | None  # the label execution returns to, None when the program ends
    back_slot: int | None = None


@dataclass(frozen=True, slots=True)
class ProgramEnded:
    t: int


@dataclass(frozen=True, slots=True)
class FastForwarded:
    """`passes` identical passes of a loop skipped from t to t_to, `period` us each.

    `shape` is what each skipped pass emitted (reports, output changes, inner
    skips) relative to its start; fastforward.count and expand read it.
    """

    t: int
    t_to: int
    passes: int
    period: int
    loop: Where
    shape: tuple = ()
    position: int = 0  # a shifted skip (fastforward.moved_shape): the first pass's start position
    shift: int = 0  # and how much further each next pass starts; 0: passes identical


@dataclass(frozen=True, slots=True)
class Executed:
    """One instruction executed (only sent when tracing)."""

    t: int
    where: Where
    text: str
