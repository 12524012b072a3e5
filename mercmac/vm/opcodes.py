"""The bytecode: one IntEnum of opcodes and the one operand table (clox `chunk.h`).

The assembler, the disassembler and the dispatch loop all read `OPERANDS`.
Opcode names are the manual's mnemonics where a command has behaviour of its
own; commands that only store a value share SET, report commands share REPORT,
so the mnemonics themselves stay in `mercmac.commands` alone.
"""
from __future__ import annotations

from enum import Enum, IntEnum

from mercmac.commands import COMMANDS, Kind, Mnemonic


class Opcode(IntEnum):
    """One per behaviour the dispatch loop distinguishes; hot ones first (match order: each
    case the match passes costs a lookup of `Opcode.X`, about 70 ns on Python 3.11)."""

    XN = 0
    XF = 1
    EM = 2
    RP = 3
    REPORT = 4  # a report command: operand (mnemonic, argument); loops that poll run many
    WA = 5
    WS = 6
    WN = 7
    WF = 8
    MR = 9
    MA = 10
    GH = 11
    AB = 12
    AB1 = 13
    ST = 14
    DH = 15
    FE = 16
    CN = 17
    CF = 18
    CP = 19
    SV = 20
    SA = 21
    JH = 22
    JL = 23
    JC = 24
    MN = 25
    MF = 26
    JN = 27
    JF = 28
    BN = 29
    BF = 30
    LN = 31
    LF = 32
    LH = 33
    LL = 34
    ZM = 35
    ZP = 36
    ZI = 37
    JT = 38
    SET = 39  # a setting that is only stored (DP, JB, SC, ...): operand (mnemonic, value)
    RT = 40
    RM = 41
    RZ = 42
    RMALL = 43
    BAD = 44  # unknown or not on this model: error 06 "Wrong Command" (§6.4 TS)


class Operand(str, Enum):
    """What an instruction carries after its opcode."""

    NONE = "none"
    VALUE = "value"  # an integer, the command's default filled in when omitted
    INPUT = "input"  # an input line 1-6 (§6.4 XN)
    OUTPUT = "output"  # an output line 1-4 (§6.4 CN)
    SLOT = "slot"  # a macro number (§6.4 EM)
    COUNT = "count"  # a repeat count (§6.4 RP)
    PATTERN = "pattern"  # a 4-bit output pattern (§6.4 CP)
    KEYED = "keyed"  # (mnemonic, value or None): SET, REPORT, BAD


_VALUE = Operand.VALUE
OPERANDS: dict[Opcode, Operand] = {
    Opcode.XN: Operand.INPUT, Opcode.XF: Operand.INPUT,
    Opcode.WN: Operand.INPUT, Opcode.WF: Operand.INPUT,
    Opcode.EM: Operand.SLOT, Opcode.RM: Operand.SLOT,
    Opcode.RP: Operand.COUNT,
    Opcode.CN: Operand.OUTPUT, Opcode.CF: Operand.OUTPUT, Opcode.CP: Operand.PATTERN,
    Opcode.WA: _VALUE, Opcode.WS: _VALUE, Opcode.MR: _VALUE, Opcode.MA: _VALUE,
    Opcode.DH: _VALUE, Opcode.FE: _VALUE, Opcode.SV: _VALUE, Opcode.SA: _VALUE,
    Opcode.JH: _VALUE, Opcode.JL: _VALUE, Opcode.JN: _VALUE, Opcode.ZM: _VALUE,
    Opcode.ZP: _VALUE, Opcode.ZI: _VALUE, Opcode.JT: _VALUE,
    Opcode.SET: Operand.KEYED, Opcode.REPORT: Operand.KEYED, Opcode.BAD: Operand.KEYED,
} | {op: Operand.NONE for op in (
    Opcode.GH, Opcode.AB, Opcode.AB1, Opcode.ST, Opcode.JC, Opcode.MN, Opcode.MF,
    Opcode.JF, Opcode.BN, Opcode.BF, Opcode.LN, Opcode.LF, Opcode.LH, Opcode.LL,
    Opcode.RT, Opcode.RZ, Opcode.RMALL)}

# Kinds whose commands have no behaviour of their own fall into the shared opcodes.
_SHARED = {Kind.SETTING: Opcode.SET, Kind.REPORT: Opcode.REPORT, Kind.OUTPUT: Opcode.SET,
           Kind.MOTION: Opcode.SET}


def opcode_for(mnemonic: str, arg: int | None) -> Opcode:
    """The opcode of a base command; BAD for a mnemonic the command table lacks."""
    command = COMMANDS.get(mnemonic)
    if command is None:
        return Opcode.BAD
    if mnemonic == Mnemonic.AB and arg == 1:  # §6.4 AB1: "AB1" is a command of its own
        return Opcode.AB1
    if mnemonic in Opcode.__members__:
        return Opcode[mnemonic]
    return _SHARED.get(command.kind, Opcode.BAD)
