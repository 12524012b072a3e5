"""AST -> Program: the high-level constructs as plain macros (SPEC §1).

- `when` blocks become an XN/XF prefix; the block moves into a macro of its
  own, called with EM, unless it already ends its macro.
- `repeat N` becomes `...,RP N-1` and `every T` `...,WA T,RP,RP`, hoisted into
  a macro of their own unless they are the whole macro (RP repeats the line).
- Where a hoisted block calls out, the code after it would need a second
  return point (MS176E §3.8.4): that rest moves into a macro of its own that
  both the block and its caller reach by a tail EM.
- Blocks over 16 commands are chained through a tail EM when no RP needs the
  whole line; slots are allocated around raw blocks and pins.
"""
from __future__ import annotations

from typing import NamedTuple

from mercmac.compiler import ast
from mercmac.compiler.checks import Env
from mercmac.compiler.program import MAX_COMMANDS, SLOTS, Macro, Op, Program
from mercmac.diagnostics import Report
from mercmac.source import Span


class _Macro:
    """A macro being lowered: its EM targets may not have slots yet."""

    __slots__ = ("name", "origin", "span", "slot", "ops")

    def __init__(self, name: str, origin: str, span: Span, slot: int | None = None):
        self.name, self.origin, self.span, self.slot = name, origin, span, slot
        self.ops: list = []  # Op, or _Em before allocation


class _Em(NamedTuple):
    """An EM whose target slot is not allocated yet."""

    target: _Macro
    span: Span
    role: str


def _calls_on(ops: list) -> bool:
    """Whether a called block takes its caller's return point and may then end
    other than through a goto (after an inner call, an XN/XF exit ends the program)."""
    calls = [i for i, op in enumerate(ops) if _is_em(op) and op.role != "goto"]
    if not calls:
        return False
    ends_in_goto = _is_em(ops[-1]) and ops[-1].role == "goto"
    exits_after = any(isinstance(op, Op) and op.mnemonic in ("XN", "XF") for op in ops[calls[0]:])
    return exits_after or not ends_in_goto


def _is_em(op) -> bool:
    return isinstance(op, _Em) or (isinstance(op, Op) and op.mnemonic == "EM")


class _Lowerer:
    def __init__(self, env: Env, report: Report):
        self.env, self.report = env, report
        self.order: list[_Macro] = []
        self.named: dict[str, _Macro] = {}

    def new(self, name: str, origin: str, span: Span, slot: int | None = None) -> _Macro:
        m = _Macro(name, origin, span, slot)
        self.order.append(m)
        return m

    def helper(self, owner: _Macro, kind: str, span: Span) -> _Macro:
        """A compiler-made macro, named after its owner and line: 'jog.when@12'."""
        name = f"{owner.name}.{kind}@{span.line}"
        if any(m.name == name for m in self.order):  # two blocks on one line
            name += f":{span.column}"
        return self.new(name, kind, span)

    # -- statements --------------------------------------------------------
    def seq(self, stmts: tuple, owner: _Macro, *, at_start: bool, loop: bool,
            cont: _Macro | None = None) -> list:
        """The ops of a statement sequence that runs to the end of `owner`'s line
        (inside a repeat/every body: up to the loop's RP), then tail-EMs `cont`."""
        out: list = []
        for i, stmt in enumerate(stmts):
            rest = stmts[i + 1:]
            whole = at_start and not out and not rest and not loop
            if isinstance(stmt, ast.Command):
                if stmt in self.env.ops:
                    out.append(self.env.ops[stmt])
            elif isinstance(stmt, (ast.Call, ast.Goto)):
                target = self.named.get(stmt.name)
                if target is not None:
                    out.append(_Em(target, stmt.span, "call" if isinstance(stmt, ast.Call) else "goto"))
            elif isinstance(stmt, ast.Repeat) and self.count(stmt) == 1:
                return out + self.seq(stmt.body + rest, owner, at_start=at_start and not out,
                                      loop=loop, cont=cont)
            elif isinstance(stmt, ast.When) and not rest and not loop and cont is None:
                return out + self.conditions(stmt) + self.seq(stmt.body, owner, at_start=False, loop=False)
            elif isinstance(stmt, (ast.Repeat, ast.Every)) and whole:
                return out + self.loop_ops(stmt, owner) + _tail(cont, stmt.span)
            else:
                block = self.helper(owner, type(stmt).__name__.lower(), stmt.span)
                out.append(_Em(block, stmt.span, "hoist"))
                mark = len(self.order)
                block.ops = self.block_ops(stmt, block, None)
                if (rest or cont) and not loop and _calls_on(block.ops):
                    # The block takes the return point: what follows it continues in
                    # a macro that both the block and this line reach by a tail EM.
                    del self.order[mark:]
                    after = cont
                    if rest:
                        after = self.helper(owner, "rest", rest[0].span)
                        after.ops = self.seq(rest, after, at_start=True, loop=False, cont=cont)
                    block.ops = self.block_ops(stmt, block, after)
                    return out + _tail(after, stmt.span)
        if out and isinstance(out[-1], _Em) and out[-1].role == "goto":
            return out
        return out + _tail(cont, stmts[-1].span if stmts else owner.span)

    def block_ops(self, stmt, block: _Macro, cont: _Macro | None) -> list:
        """A hoisted when/repeat/every block's ops, ending with a tail EM to `cont`."""
        if isinstance(stmt, ast.When):
            return self.conditions(stmt) + self.seq(stmt.body, block, at_start=False, loop=False,
                                                    cont=cont)
        return self.loop_ops(stmt, block) + _tail(cont, stmt.span)

    def loop_ops(self, stmt, owner: _Macro) -> list:
        body = self.seq(stmt.body, owner, at_start=False, loop=True)
        if isinstance(stmt, ast.Repeat):
            return body + [Op("RP", self.count(stmt) - 1, stmt.span)]
        # every T: wait T, then RP,RP = 65536 x 65536 passes, "forever" (§3.8.6 Example 1)
        return body + [Op("WA", self.value(stmt.period) or 0, stmt.span),
                       Op("RP", None, stmt.span), Op("RP", None, stmt.span)]

    def conditions(self, stmt: ast.When) -> list:
        return [Op("XF" if c.negated else "XN", self.value(c.value), c.span)
                for c in stmt.conditions if self.value(c.value) is not None]

    def count(self, stmt: ast.Repeat) -> int:
        """The repeat count; an invalid one (already reported) counts as 1."""
        count = self.value(stmt.count)
        return count if count and count > 0 else 1

    def value(self, v: ast.Value) -> int | None:
        return self.env.values.get(v)

    # -- items -------------------------------------------------------------
    def module(self, module: ast.Module) -> None:
        for item in module.items:
            if isinstance(item, ast.MacroDef) and self.env.macros.get(item.name) is item:
                pin = item.pin.value if item.pin is not None and item.pin.value in SLOTS else None
                self.named[item.name] = self.new(item.name, "macro", item.span, pin)
        for item in module.items:
            if isinstance(item, ast.RawBlock):
                m = self.new(f"MC{item.slot:02d}", "raw", item.span, item.slot)
                m.ops = [self.env.ops[c] for c in item.commands if c in self.env.ops]
            elif isinstance(item, ast.Autostart):
                m = self.new("autostart", "autostart", item.span, 0)
                m.ops = self.seq(item.body, m, at_start=True, loop=False)
            elif isinstance(item, ast.MacroDef) and item.name in self.named:
                m = self.named[item.name]
                if self.env.macros[item.name] is item:
                    m.ops = self.seq(item.body, m, at_start=True, loop=False)

    def split(self) -> None:
        """Fit lowered macros into 16 commands (MS176E §3.8) where the meaning allows.

        A line without RP is chained through a tail EM. A loop (RP repeats the
        whole line) keeps its line and moves runs of plain commands into macros
        it calls: those call nothing, so the loop keeps its return point.
        """
        for m in list(self.order):
            if m.origin == "raw" or len(m.ops) <= MAX_COMMANDS:
                continue
            if any(_is_op(op, "RP") for op in m.ops):
                self.shrink_loop(m)
            else:
                self.chain(m)

    def part_name(self, m: _Macro) -> str:
        """'jog.part2', 'jog.part3', ...: the next free part name of a split macro."""
        names = {x.name for x in self.order}
        n = 2
        while f"{m.name}.part{n}" in names:
            n += 1
        return f"{m.name}.part{n}"

    def chain(self, m: _Macro) -> None:
        part = m
        while len(part.ops) > MAX_COMMANDS:
            tail = self.new(self.part_name(m), "part", m.span)
            keep = MAX_COMMANDS - 1
            tail.ops, part.ops = part.ops[keep:], part.ops[:keep]
            part.ops.append(_Em(tail, _span_of(tail.ops[0], m.span), "continue"))
            part = tail

    def shrink_loop(self, m: _Macro) -> None:
        while len(m.ops) > MAX_COMMANDS:
            runs = _movable_runs(m.ops)
            if not runs:
                self.report.add("too-many-commands", m.span,
                                f"'{m.name}' needs {len(m.ops)} commands and a macro holds "
                                f"{MAX_COMMANDS}. It cannot be split: its RP repeats the whole "
                                "line, and what it holds cannot move into a called macro "
                                "(calls, conditions, TI). Move part of it into a macro of its own")
                return
            start, end = max(runs, key=lambda r: r[1] - r[0])
            end = min(end, start + MAX_COMMANDS)
            part = self.new(self.part_name(m), "part", m.span)
            part.ops = m.ops[start:end]
            m.ops[start:end] = [_Em(part, _span_of(part.ops[0], m.span), "hoist")]


    def allocate(self) -> dict[int, _Macro]:
        taken: dict[int, _Macro] = {}
        for m in self.order:
            if m.slot is not None:
                taken[m.slot] = m  # duplicates were reported; the last wins as on the controller
        # Slot 0 is the autostart macro: never given to a macro that did not ask for it.
        free = (s for s in SLOTS if s and s not in taken)
        for m in self.order:
            if m.slot is None:
                m.slot = next(free, None)
                if m.slot is None:
                    self.report.add("slot-range", m.span,
                                    f"no free slot for '{m.name}': the program needs "
                                    f"{len(self.order)} macros and the controller holds 32")
                    continue
                taken[m.slot] = m
        return taken


def _is_op(op, mnemonic: str) -> bool:
    return isinstance(op, Op) and op.mnemonic == mnemonic


# Commands that behave the same in a called macro: not calls, conditions (they
# would end the called macro, not the loop), RP, or TI (it reads the loop's counter).
_STAY = ("EM", "XN", "XF", "RP", "TI")


def _movable_runs(ops: list) -> list[tuple[int, int]]:
    """[start, end) of every run of two or more commands that can move into a called macro."""
    runs, start = [], None
    for i, op in enumerate(ops + [None]):
        movable = isinstance(op, Op) and op.mnemonic not in _STAY
        if movable and start is None:
            start = i
        elif not movable and start is not None:
            if i - start >= 2:
                runs.append((start, i))
            start = None
    return runs


def _tail(cont: _Macro | None, span: Span) -> list:
    return [] if cont is None else [_Em(cont, span, "continue")]


def _span_of(op, default: Span) -> Span:
    return op.span or default


def _final(op) -> Op:
    if isinstance(op, _Em):
        return Op("EM", op.target.slot, op.span, op.role)
    return op


def lower(module: ast.Module, env: Env, report: Report, file: str = "") -> Program:
    """The program a module stands for (errors are reported, never raised)."""
    lowerer = _Lowerer(env, report)
    lowerer.module(module)
    lowerer.split()
    slots = lowerer.allocate()
    macros = {
        slot: Macro(slot, m.name, [_final(op) for op in m.ops], m.span, m.origin)
        for slot, m in sorted(slots.items())
    }
    return Program(macros, env.target, file)
