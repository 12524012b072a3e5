"""The disassembler (clox `debug.c`): bytecode back to readable instructions; backs --trace."""
from __future__ import annotations

from mercmac.mdtext import slot_name
from mercmac.vm.assemble import Chunk
from mercmac.vm.opcodes import OPERANDS, Opcode, Operand


def operand_text(opcode: Opcode, operand: object) -> str:
    """The operand as the operand table describes it."""
    kind = OPERANDS[opcode]
    if kind is Operand.NONE:
        return ""
    if kind is Operand.KEYED:
        mnemonic, value = operand
        return mnemonic if value is None else f"{mnemonic} {value}"
    if kind is Operand.SLOT:
        return slot_name(operand)
    if kind is Operand.PATTERN:
        return f"{operand:04b}"[::-1].replace("1", "●").replace("0", "○")
    if kind is Operand.INPUT:
        return f"in{operand}"
    if kind is Operand.OUTPUT:
        return f"out{operand}"
    return str(operand)


def instruction(chunk: Chunk, ip: int) -> str:
    """'MC15 #04  WA     20        WA20   (line 7)'."""
    opcode, value = chunk.code[ip]
    span = chunk.spans[ip]
    where = f"line {span.line}" if span else "no source"
    return (f"{chunk.label:<20} #{ip:02d}  {opcode.name:<6} {operand_text(opcode, value):<10}"
            f" {chunk.texts[ip]:<12} ({where})")

