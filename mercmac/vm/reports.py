"""Report strings exactly as the firmware sends them, without CR LF ETX (MS176E §6.1.3, §6.4).

The one place that formats reports: the simulator and the virtual controller
of `mercmac emulate` both call `report()`.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from mercmac.commands import C663, COMMANDS, Command, Mnemonic

if TYPE_CHECKING:
    from mercmac.vm.machine import Machine

# §6.4 CS and VE examples; the model name in VE is how a host tells C-663 from C-863.
CHECKSUM = "C:0230-15"
VERSION = "(c)2009 Physik Instrumente(PI) Karlsruhe, {model}, Ver. {firmware}, 2009-21-07"
TABLE_DONE = "Table done"  # §6.4 JT: sent when the table is generated


def number(identifier: str, value: float) -> str:
    """'P:+0000005555': sign and ten digits (§6.4 TP, TT, TI, TL, GL examples)."""
    return f"{identifier}{round(value):+011d}"


def report(mnemonic: str, arg: int | None, m: Machine) -> str:
    """The report of one report command (kind REPORT in the command table)."""
    command = COMMANDS[mnemonic]
    ident = command.report or ""
    if mnemonic.endswith("?"):
        return _query(command, ident, m)
    if command.reads:  # G*: the D* setting (§6.2)
        return number(ident, m.setting(command.reads))
    t = m.clock.now
    axis = m.axis
    match mnemonic:
        case Mnemonic.TP:
            return number(ident, axis.position(t))
        case Mnemonic.TT:
            return number(ident, axis.target)
        case Mnemonic.TI:
            return number(ident, m.iteration())
        case Mnemonic.TL:
            return number(ident, axis.sa)
        case Mnemonic.TY:
            return number(ident, axis.sv)
        case Mnemonic.TV:
            return number(ident, axis.velocity(t))
        case Mnemonic.TD:  # the dynamic target: the profile's position (perfect tracking)
            return number(ident, axis.position(t))
        case Mnemonic.TE:  # §6.4 TE: target minus actual position
            return number(ident, axis.target - round(axis.position(t)))
        case Mnemonic.TF | Mnemonic.TR:  # the model tracks perfectly and has no force sensor
            return number(ident, 0)
        case Mnemonic.TC:
            return channel(arg or 0, m)
        case Mnemonic.TA:
            return analog(arg or 0, m)
        case Mnemonic.TS:
            return status(m)
        case Mnemonic.TB:
            return f"B:{m.options.address}"
        case Mnemonic.CS:
            return CHECKSUM
        case Mnemonic.VE:
            return VERSION.format(model=m.model, firmware=m.options.firmware)
        case Mnemonic.TM:
            return macros(m, [arg] if arg else [s for s in m.stored_macros() if s != 0])
        case Mnemonic.TZ:
            return macros(m, [0])
    raise ValueError(f"no report format for {mnemonic}")


def _query(command: Command, ident: str, m: Machine) -> str:
    """'JH:+250000', 'ZM:2': the value set by the command the query belongs to."""
    setting = command.mnemonic[:-1]
    value = {Mnemonic.JH: m.axis.jh, Mnemonic.JL: m.axis.jl, Mnemonic.JN: m.axis.joystick,
             Mnemonic.ZM: m.trigger.mode, Mnemonic.ZP: m.trigger.position,
             Mnemonic.ZI: m.trigger.increment}.get(setting)
    value = m.setting(setting) if value is None else value
    return f"{ident}{value}" if command.unsigned else f"{ident}{value:+d}"


def channel(n: int, m: Machine) -> str:
    """TCn: 'H01:1'; TC0: all four inputs as one hex digit, 'H00:5' (§6.4 TC)."""
    if n == 0:
        return f"H00:{m.inputs.pattern():X}"
    return f"H0{n}:{int(m.inputs[n])}"


def analog(n: int, m: Machine) -> str:
    """TAn: 8-bit readings; a digital line reads 255 when ON. The joystick (5) rests at
    mid-scale, 128, and reads 255 at full tilt (SPEC §3: ON above mid-scale)."""
    def value(k: int) -> int:
        if k == 5:
            return 255 if m.inputs[5] else 128
        return 255 if m.inputs[k] else 0
    if n == 0:  # §6.4 TA: "A:185" followed by the other channels, one per line
        return "A:" + "\r\n".join(str(value(k)) for k in range(1, 5))
    return f"A{n}:{value(n)}"


def status(m: Machine) -> str:
    """TS: six bytes on the C-863, three on the C-663 (§6.4 TS tables)."""
    blocks = _status_663(m) if m.model == C663 else _status_863(m)
    return "S:" + " ".join(f"{b:02X}" for b in blocks)


def _bits(*flags: bool) -> int:
    return sum(1 << i for i, on in enumerate(flags) if on)


def _limit_lines(m: Machine, t: float) -> tuple[bool, bool]:
    """(negative, positive): the levels of the two limit switch lines, not whether a switch
    is hit. §6.4 TS calls these bits "limit signal (input)" and shows them so: the C-663's
    idle example `s:03 07 00` has both limit bits set, which only levels can be (no stage
    sits on both switches), since PI's stepper stages switch active-low (§4.4.1 NOTE) -
    as EPICS' drvPIC663 reads them. The C-863 example `S:04 02 00 03 02 00` (LH, §3.4.1)
    has both clear. The stage is taken to match LH/LL, as motion needs (§4.4.1), so a
    line is high when its switch is hit under LH and when it is not hit under LL."""
    hit = m.axis.limit_switch(t)
    return (hit == "negative") == m.limits_high, (hit == "positive") == m.limits_high


def _status_863(m: Machine) -> list[int]:
    t, axis = m.clock.now, m.axis
    on_target = not axis.moving(t)
    negative, positive = _limit_lines(m, t)
    return [
        _bits(0, 0, on_target, axis.referenced, 0, 0, 0, not axis.servo),
        # bit 1 busy: it is executing this very TS; bit 4 a stored macro runs (a line the
        # host typed is direct mode, §5.7, so `TS` typed alone reports 02, not 12)
        _bits(0, True, 0, 0, m.macro is not None),
        _bits(0, 0, axis.negative),
        _bits(m.limits_on, m.limits_high, axis.homing, m.brake, axis.joystick > 0),
        _bits(0, axis.reference_high(t), positive, negative) | (m.inputs.pattern() << 4),
        m.error,
    ]


def _status_663(m: Machine) -> list[int]:
    t, axis = m.clock.now, m.axis
    negative, positive = _limit_lines(m, t)
    moving = axis.moving(t)
    macro = m.macro is not None  # a stored macro runs; a typed line (direct mode) is none
    return [
        # bit 0 Ready: set when no macro runs, as in the manual's idle `s:03 07 00` (§6.4 TS)
        _bits(not macro, not moving, axis.homing, axis.joystick > 0, macro,
              not axis.servo, m.brake, moving),
        _bits(negative, axis.reference_high(t), positive) | (m.inputs.pattern() << 4),
        m.error,
    ]


def macros(m: Machine, slots: list[int]) -> str:
    """TM/TZ: 'MC001 MR55555' per stored macro, one per line; '' when none (SPEC §4)."""
    stored = m.stored_macros()
    return "\r\n".join(f"MC{s:03d} {stored[s]}" for s in slots if s in stored)
