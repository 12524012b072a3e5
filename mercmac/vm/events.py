"""What the machine tells its listeners, as plain records; times are microseconds."""
from __future__ import annotations

from dataclasses import dataclass

from mercmac.commands import Mnemonic
from mercmac.ops import TextEnum
from mercmac.source import Span
from mercmac.vm.motion import Ended, Plan


class Motion(TextEnum):
    """What started a profile (MoveStarted.kind)."""

    MOVE = "move"  # MA, MR, GH
    HOME_SEARCH = "home search"  # FE
    STOP = "stop"  # AB1, ST, the joystick released
    ABORT = "abort"  # AB, MN/MF while moving
    JOYSTICK = "joystick"  # JN with input 5 ON


class Via(TextEnum):
    """How a macro was entered (MacroEntered.via)."""

    POWER_ON = "power-on"  # macro 0 at power-on or RT (§3.8.5)
    EM = Mnemonic.EM  # from a macro
    HOST = "host"  # EMn typed in direct mode


class Exit(TextEnum):
    """Why a macro was left (MacroLeft.why): its end, a stop, or a failed condition."""

    END = "end"
    STOPPED = "stopped"  # a character from the host (§3.8.3)
    # XNn: input n was OFF; XFn: input n was ON (§6.4 XN, XF)
    XN1, XN2, XN3, XN4, XN5, XN6 = "XN1", "XN2", "XN3", "XN4", "XN5", "XN6"
    XF1, XF2, XF3, XF4, XF5, XF6 = "XF1", "XF2", "XF3", "XF4", "XF5", "XF6"

    @property
    def failed(self) -> bool:
        """Whether a condition failed (an XN or XF), rather than the macro ending or stopping."""
        return self is not Exit.END and self is not Exit.STOPPED


# The exit of a failed XNn and XFn by input number n (index 0 unused, as inputs count from 1)
FAILED_XN = (None, Exit.XN1, Exit.XN2, Exit.XN3, Exit.XN4, Exit.XN5, Exit.XN6)
FAILED_XF = (None, Exit.XF1, Exit.XF2, Exit.XF3, Exit.XF4, Exit.XF5, Exit.XF6)


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
class JoystickMoved:
    """The joystick held at a new deflection from outside (-1 full negative .. 1 full
    positive; 0 the middle). MS176E §3.6.1: it sets the axis's velocity, so the event says
    the velocity that deflection commands (counts or steps a second, signed; 0 while the
    joystick is off), JN's maximum (0: off, §6.4 JN), the response table it goes through
    (§6.4 JT) and whether input 5 now reads ON."""

    t: int
    deflection: float
    velocity: float
    maximum: int
    table: int
    input_on: bool


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
    """A hazard (mercmac/hazards.py); `accepted` when the user said the program means it: the
    rule allowed for the run (`sim --allow-hazard`, a scenario's `allow_hazards`) or
    expected on its line (`// mercmac: expect[soft-limit-clamp]`). An accepted hazard is
    shown, never counted (docs/simulator.md, "Hazards")."""

    t: int
    rule: str
    message: str
    where: Where | None
    accepted: bool = False


@dataclass(frozen=True, slots=True)
class MoveStarted:
    """A profile started."""

    t: int
    kind: Motion
    target: int
    arrival: float  # us; inf when it never arrives
    segments: tuple  # profile.Segment records, for position plots (VCD)
    where: Where | None
    # the profile running since segments[0].t0 goes on (Axis.keeps), to this target: the
    # command planned it from the same start, as it was planned, or to a target further on
    kept: bool = False
    plan: Plan | None = None  # what a kept profile was planned from


@dataclass(frozen=True, slots=True)
class MoveEnded:
    """The profile ended: on target, or stopped by a hard limit switch."""

    t: int
    how: Ended
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
    via: Via


@dataclass(frozen=True, slots=True)
class MacroLeft:
    t: int
    slot: int
    label: str
    why: Exit
    back_to: str | None  # the label execution returns to, None when the program ends
    back_slot: int | None = None


@dataclass(frozen=True, slots=True)
class ProgramEnded:
    t: int


@dataclass(frozen=True, slots=True)
class FastForwarded:
    """`passes` identical passes of a loop skipped from t to t_to, `period` us each.

    `shape` is what each skipped pass emitted (reports, output changes, inner
    skips: the items of vm/shapes.py) relative to its start; shapes.count and expand read it.
    """

    t: int
    t_to: int
    passes: int
    period: int
    loop: Where
    shape: tuple = ()
    position: int = 0  # a shifted skip (shapes.moved_shape): the first pass's start position
    shift: int = 0  # and how much further each next pass starts; 0: passes identical
    # when the loop came round: the skipped passes end there, k periods on (t, the next
    # command, may be a cycle later, and an arrival fall between); None: at t
    anchor_t: int | None = None
    # each pass, counted: (events other than macro entries and exits, entries and exits), as
    # the JSON `events` holds them (markers aside); None: not counted (a rig's skip)
    events: tuple[int, int] | None = None
    # the passes left the running profile going on (shapes.steady): the stage follows it
    # through them, to the target `position + passes * shift` (Axis.retarget)
    steady: bool = False


@dataclass(frozen=True, slots=True)
class Executed:
    """One instruction executed (only sent when tracing)."""

    t: int
    where: Where
    text: str
