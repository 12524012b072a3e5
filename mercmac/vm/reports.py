"""Report strings exactly as the firmware sends them, without CR LF ETX (MS176E §6.1.3, §6.4).

The one place that formats reports: the simulator and the virtual controller
of `mercmac emulate` both call `report()`. A report reads a `Snapshot`, the machine's
state at one instant taken once per report, never the machine's parts: what a report
can show is the snapshot's fields.
"""
from __future__ import annotations

from itertools import compress
from typing import Mapping, NamedTuple, Protocol

from mercmac.commands import C663, COMMANDS, Command, Mnemonic
from mercmac.mdtext import tm_line
from mercmac.vm.motion import Side

# §6.4 CS and VE examples; the model name in VE is how a host tells C-663 from C-863.
CHECKSUM = "C:0230-15"
VERSION = "(c)2009 Physik Instrumente(PI) Karlsruhe, {model}, Ver. {firmware}, 2009-21-07"
TABLE_DONE = "Table done"  # §6.4 JT: sent when the table is generated
_WEIGHTS = tuple(1 << i for i in range(8))  # bits 0-7 of a TS byte


class Snapshot(NamedTuple):
    """The machine at one instant, as its reports show it. Machine.snapshot builds it by
    position, once per report: a new field goes there in the same place
    (tests/vm/test_vm_snapshot_taking.py holds each field to the machine's word)."""

    model: str
    address: int  # TB: the DIP switches
    firmware: str  # VE
    position: float  # the profile's position, counts (perfect tracking: TP, TD)
    velocity: float  # counts/s
    target: int
    moving: bool  # or stuck trying to (SV0, SA0)
    sv: int
    sa: int
    iteration: int  # TI
    settings: Mapping[str, int]  # stored by the setting commands, JH/JL/JN and ZM/ZP/ZI too
    inputs: tuple[bool, ...]  # lines 1-6 by number; index 0 unused
    buttons: int  # inputs 1-4 as bits 0-3 (TC0, TS)
    macros: Mapping[int, str]  # the stored command lines by slot, as TM lists them
    macro_running: bool  # a stored macro runs; a line the host typed is direct mode (§5.7)
    error: int  # the TS error code
    # the rest of the TS bits (§6.4 TS)
    referenced: bool
    servo: bool
    negative: bool  # the last move's direction
    homing: bool
    joystick: bool  # JN is on
    brake: bool
    limits_on: bool
    limits_high: bool
    reference_high: bool  # the reference line (§6.4 FE2)
    limit: Side | None  # the hard limit switch pressed, if one is


class Snapshotting(Protocol):
    """What reports ask of a machine: its state now (vm.machine.Machine)."""

    def snapshot(self) -> Snapshot: ...


def number(identifier: str, value: float) -> str:
    """'P:+0000005555': sign and ten digits (§6.4 TP, TT, TI, TL, GL examples)."""
    return f"{identifier}{round(value):+011d}"


def report(mnemonic: str, arg: int | None, m: Snapshotting) -> str:
    """The report of one report command (kind REPORT in the command table), now."""
    return _report(mnemonic, arg, m.snapshot())


def _report(mnemonic: str, arg: int | None, s: Snapshot) -> str:
    command = COMMANDS[mnemonic]
    ident = command.report or ""
    if mnemonic.endswith("?"):
        return _query(command, ident, s)
    if command.reads:  # G*: the D* setting (§6.2)
        return number(ident, s.settings.get(command.reads, 0))
    match mnemonic:
        case Mnemonic.TP:
            return number(ident, s.position)
        case Mnemonic.TT:
            return number(ident, s.target)
        case Mnemonic.TI:
            return number(ident, s.iteration)
        case Mnemonic.TL:
            return number(ident, s.sa)
        case Mnemonic.TY:
            return number(ident, s.sv)
        case Mnemonic.TV:
            return number(ident, s.velocity)
        case Mnemonic.TD:  # the dynamic target: the profile's position (perfect tracking)
            return number(ident, s.position)
        case Mnemonic.TE:  # §6.4 TE: target minus actual position
            return number(ident, s.target - round(s.position))
        case Mnemonic.TF | Mnemonic.TR:  # the model tracks perfectly and has no force sensor
            return number(ident, 0)
        case Mnemonic.TC:
            return _channel(arg or 0, s)
        case Mnemonic.TA:
            return _analog(arg or 0, s)
        case Mnemonic.TS:
            return _status(s)
        case Mnemonic.TB:
            return f"B:{s.address}"
        case Mnemonic.CS:
            return CHECKSUM
        case Mnemonic.VE:
            return VERSION.format(model=s.model, firmware=s.firmware)
        case Mnemonic.TM:
            return macros(s.macros, [arg] if arg else [slot for slot in s.macros if slot != 0])
        case Mnemonic.TZ:
            return macros(s.macros, [0])
    raise ValueError(f"no report format for {mnemonic}")


def _query(command: Command, ident: str, s: Snapshot) -> str:
    """'JH:+250000', 'ZM:2': the value set by the command the query belongs to."""
    value = s.settings.get(command.mnemonic[:-1], 0)
    return f"{ident}{value}" if command.unsigned else f"{ident}{value:+d}"


def _channel(n: int, s: Snapshot) -> str:
    """TCn: 'H01:1'; TC0: all four inputs as one hex digit, 'H00:5' (§6.4 TC)."""
    if n == 0:
        return f"H00:{s.buttons:X}"
    return f"H0{n}:{int(s.inputs[n])}"


def _analog(n: int, s: Snapshot) -> str:
    """TAn: 8-bit readings; a digital line reads 255 when ON. The joystick (5) rests at
    mid-scale, 128, and reads 255 at full tilt (docs/simulator.md: ON above mid-scale)."""
    def value(k: int) -> int:
        if k == 5:
            return 255 if s.inputs[5] else 128
        return 255 if s.inputs[k] else 0
    if n == 0:  # §6.4 TA: "A:185" followed by the other channels, one per line
        return "A:" + "\r\n".join(str(value(k)) for k in range(1, 5))
    return f"A{n}:{value(n)}"


def status(m: Snapshotting) -> str:
    """TS: six bytes on the C-863, three on the C-663 (§6.4 TS tables), now."""
    return _status(m.snapshot())


def _status(s: Snapshot) -> str:
    blocks = _status_663(s) if s.model == C663 else _status_863(s)
    return "S:" + bytes(blocks).hex(" ").upper()  # each block is one byte, in hex


def _bits(*flags: bool) -> int:
    """The flags as bits 0, 1, ... of a byte (C loops: TS builds six of them per report)."""
    return sum(compress(_WEIGHTS, flags))


def _limit_lines(s: Snapshot) -> tuple[bool, bool]:
    """(negative, positive): the levels of the two limit switch lines, not whether a switch
    is hit. §6.4 TS calls these bits "limit signal (input)" and shows them so: the C-663's
    idle example `s:03 07 00` has both limit bits set, which only levels can be (no stage
    sits on both switches), since PI's stepper stages switch active-low (§4.4.1 NOTE) -
    as EPICS' drvPIC663 reads them. The C-863 example `S:04 02 00 03 02 00` (LH, §3.4.1)
    has both clear. The stage is taken to match LH/LL, as motion needs (§4.4.1), so a
    line is high when its switch is hit under LH and when it is not hit under LL."""
    high = s.limits_high
    return (s.limit is Side.NEGATIVE) == high, (s.limit is Side.POSITIVE) == high


def _status_863(s: Snapshot) -> list[int]:
    negative, positive = _limit_lines(s)
    return [
        _bits(0, 0, not s.moving, s.referenced, 0, 0, 0, not s.servo),
        # bit 1 busy: it is executing this very TS; bit 4 a stored macro runs (a line the
        # host typed is direct mode, §5.7, so `TS` typed alone reports 02, not 12)
        _bits(0, True, 0, 0, s.macro_running),
        _bits(0, 0, s.negative),
        _bits(s.limits_on, s.limits_high, s.homing, s.brake, s.joystick),
        _bits(0, s.reference_high, positive, negative) | (s.buttons << 4),
        s.error,
    ]


def _status_663(s: Snapshot) -> list[int]:
    negative, positive = _limit_lines(s)
    macro = s.macro_running
    return [
        # bit 0 Ready: set when no macro runs, as in the manual's idle `s:03 07 00` (§6.4 TS)
        _bits(not macro, not s.moving, s.homing, s.joystick, macro,
              not s.servo, s.brake, s.moving),
        _bits(negative, s.reference_high, positive) | (s.buttons << 4),
        s.error,
    ]


def macros(stored: Mapping[int, str], slots: list[int]) -> str:
    """TM/TZ: 'MC001 MR55555' per stored macro, one per line; '' when none (docs/uploader.md)."""
    return "\r\n".join(tm_line(s, stored[s]) for s in slots if s in stored)
