"""The assembler: lowered macros (the very `MD` text that is uploaded) -> bytecode chunks."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Iterable

from mercmac.commands import C863, COMMANDS
from mercmac.compiler.program import Macro, Program
from mercmac.mdtext import slot_name
from mercmac.ops import Op
from mercmac.source import Span
from mercmac.vm.opcodes import OPERANDS, Opcode, Operand, opcode_for

DIRECT = -1  # the slot of a command line typed in direct mode (MS176E §5.7.1)


@dataclass(slots=True)
class Chunk:
    """One macro's bytecode: instructions plus, per instruction, its text and span."""

    slot: int
    name: str
    code: list[tuple[Opcode, object]] = field(default_factory=list)
    texts: list[str] = field(default_factory=list)
    spans: list[Span | None] = field(default_factory=list)
    # 'main (MC05)', 'MC05', 'direct': named once, as every report and macro entry names it
    label: str = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        if self.slot == DIRECT:
            self.label = "direct"
        else:
            tag = slot_name(self.slot)
            self.label = tag if self.name in ("", tag) else f"{self.name} ({tag})"

    @property
    def line(self) -> str:
        """The line as the controller stores it (upper case, no spaces): what TM reports."""
        return ",".join(self.texts)


def operand(op: Op, opcode: Opcode) -> object:
    """Encode one argument as the operand table says; defaults come from the command table."""
    kind = OPERANDS[opcode]
    if kind is Operand.NONE:
        return None
    if kind is Operand.KEYED:
        return (op.mnemonic, op.arg)
    if op.arg is not None:
        return op.arg
    return COMMANDS[op.mnemonic].default or 0


def assemble_ops(ops: Iterable[Op], slot: int, name: str, model: str = C863) -> Chunk:
    """Assemble base commands; commands the model lacks become BAD (error 06, §6.4 TS)."""
    chunk = Chunk(slot, name)
    for op in ops:
        opcode = opcode_for(op.mnemonic, op.arg)
        command = COMMANDS.get(op.mnemonic)
        if command is not None and not command.available_on(model):
            opcode = Opcode.BAD
        chunk.code.append((opcode, operand(op, opcode)))
        chunk.texts.append(op.text)
        chunk.spans.append(op.span)
    return chunk


def assemble_macro(macro: Macro, model: str = C863) -> Chunk:
    return assemble_ops(macro.ops, macro.slot, macro.name, model)


def assemble(program: Program, model: str = C863) -> dict[int, Chunk]:
    """Every stored macro of a program, by slot."""
    return {slot: assemble_macro(m, model) for slot, m in program.macros.items()}
