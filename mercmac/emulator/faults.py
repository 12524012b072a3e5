"""Misbehaviour on demand: how the virtual controller may fail the way real links do.

The uploader's fault tests and `mercmac emulate --tm-framing/--empty-slot` choose them;
virtual.py acts on them. The answers the protocol leaves open (docs/uploader.md) are closed
sets (`Framing`, `EmptySlot`) whose text is what the command line takes.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from mercmac.ops import TextEnum


class Framing(TextEnum):
    """How a TM listing of several macros ends its lines (real controllers differ:
    docs/uploader.md)."""

    ETX_PER_LINE = "etx-per-line"  # each line a report of its own, CR LF ETX
    ONE_ETX = "one-etx"  # one report: the lines joined by CR LF, one ETX at the end


class EmptySlot(TextEnum):
    """What TMn of an empty slot answers (docs/uploader.md)."""

    EMPTY = "empty"  # an empty report
    BARE = "bare"  # the header alone, 'MCnnn'


@dataclass(slots=True)
class Faults:
    """Misbehaviour on demand, for the uploader's fault tests."""

    drop_char: dict[int, int] = field(default_factory=dict)  # n-th MD line (1-based) -> index lost
    always_drop_slot: int | None = None  # every MD line for this slot loses a character
    vanish_after_md: int | None = None  # the port disappears after this many MD lines
    tm_framing: Framing = Framing.ETX_PER_LINE
    empty_slot: EmptySlot = EmptySlot.EMPTY
    silent: bool = False  # nothing answers at all
    garble: bool = False  # replies arrive mangled, as at a wrong baud rate
    char_gap: bool | None = None  # enforce the 20 ms gap; None = as the firmware version says
    md_delay: float = 0.0  # seconds a flash write keeps the controller from reading on
    # like real hardware: bytes reach the firmware at `baud`, firmware 1.xx's 20 ms gap holds
    # whatever VE says, and characters are lost while a move runs (virtual.MOVE_POLL_S)
    pace: bool = False
    baud: int = 9600
    version: str | None = None  # VE answers this instead (older firmware, the C-862)

    def __post_init__(self):
        # given by their text too (`--tm-framing one-etx`); an unknown name fails here
        self.tm_framing = Framing(self.tm_framing)
        self.empty_slot = EmptySlot(self.empty_slot)
