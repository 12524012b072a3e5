"""AST -> Program: the high-level constructs as plain macros (docs/language.md).

- `when` blocks become an XN/XF prefix; the block moves into a macro of its
  own, called with EM, unless it already ends its macro.
- `repeat N` becomes `...,RP N-1` and `every T` `...,WA T,RP,RP`, hoisted into
  a macro of their own unless they are the whole macro (RP repeats the line).
- Where a hoisted block calls out, the code after it would need a second
  return point (MS176E §3.8.4): that rest moves into a macro of its own that
  both the block and its caller reach by a tail EM.
- Blocks over 16 commands are chained through a tail EM when no RP needs the
  whole line; slots are allocated around raw blocks and pins.
- A loop that starts its line stays in it (RP jumps to the line's
  start); a macro that calls on only through its own blocks is inlined into a
  call with code after it; small repeats in a block that must call nothing
  are unrolled; `repeat N` past RP's range is two RPs, long periods several
  WAs; a loop whose block reaches a goto runs once; an empty macro is `WA0`.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import NamedTuple

from mercmac.commands import Mnemonic
from mercmac.compiler import ast
from mercmac.compiler.checks import Env
from mercmac.compiler.program import (MAX_COMMANDS, SLOTS, Macro, Program, as_written, rp_counts,
                                      wait_pieces)
from mercmac.diagnostics import Report
from mercmac.mdtext import slot_name
from mercmac.ops import Op, Origin, Role
from mercmac.source import Span


class _Macro:
    """A macro being lowered: its EM targets may not have slots yet."""

    __slots__ = ("name", "origin", "span", "slot", "ops", "root", "depth", "too_long")

    def __init__(self, name: str, origin: Origin, span: Span, slot: int | None = None):
        self.name, self.origin, self.span, self.slot = name, origin, span, slot
        self.ops: list = []  # Op, or _Em before allocation
        self.root: _Macro | None = None  # of a helper: the user's macro it was made for
        self.depth = 0  # of a helper: how many owners it has, the root one included
        self.too_long = False  # a loop line reported as too long to split (`split` fits again)


class _Em(NamedTuple):
    """An EM whose target slot is not allocated yet."""

    target: _Macro
    span: Span
    role: Role


def _calls_on(ops: list) -> bool:
    """Whether a called block takes its caller's return point and may then end
    other than through a goto (after an inner call, an XN/XF exit ends the program).
    A block chained into parts is read as the one line it stands for."""
    ops = _unchained(ops)
    calls = [i for i, op in enumerate(ops) if _is_em(op) and op.role is not Role.GOTO]
    if not calls:
        return False
    ends_in_goto = _is_em(ops[-1]) and ops[-1].role is Role.GOTO
    exits_after = any(isinstance(op, Op) and op.mnemonic in (Mnemonic.XN, Mnemonic.XF)
                      for op in ops[calls[0]:])
    return exits_after or not ends_in_goto


def _unchained(ops: list) -> list:
    """A line with its chained parts (tail EMs 'continue' to a part) read back as one."""
    whole = list(ops)
    last = whole[-1] if whole else None
    # a loop, not recursion: a long block is chained into thousands of parts
    while (isinstance(last, _Em) and last.role is Role.CONTINUE
           and last.target.origin is Origin.PART):
        whole += last.target.ops  # the tail EM stays: it is a call too
        last = whole[-1]
    return whole


@dataclass(frozen=True, slots=True)
class _Context:
    """Where a statement sequence is lowered: whose line, and how that line may be laid out.
    A block's statements are lowered in a context derived from their line's (`replace`)."""

    owner: _Macro
    at_start: bool = True  # the sequence starts the owner's line (RP jumps back there)
    loop: bool = False  # a repeat/every body: it runs up to the loop's RP, then again
    cont: _Macro | None = None  # when the line is done, it continues there by a tail EM
    leaf: bool = False  # the line is called from a loop, so it must call nothing
    # a loop that starts the line may stay on it: not in a loop with a TI, which would
    # then read the inner loop's RP counter (MS176E §6.4 TI)
    nest: bool = True

    def rest(self, owner: _Macro) -> _Context:
        """The line of what follows a block that took the return point."""
        return replace(self, owner=owner, at_start=True, loop=False, nest=True)

    def block(self, owner: _Macro, cont: _Macro | None) -> _Context:
        """The line of a block hoisted from this one: a loop's or a leaf's must call nothing."""
        return replace(self, owner=owner, at_start=False, loop=False, cont=cont,
                       leaf=self.loop or self.leaf, nest=True)

    def body(self, stmt) -> _Context:
        """The line of a loop's body, which starts the line the loop's RP repeats."""
        return replace(self, at_start=True, loop=True, cont=None, nest=not _has_ti(stmt.body))


class _Todo:
    """The statements of a line still to lower. A body that runs in a statement's place
    (a loop that runs once, an inlined callee) is pushed, not joined to the rest: a line
    of thousands of them was a recursion and a copy per statement."""

    __slots__ = ("frames", "last")

    def __init__(self, stmts: tuple, span: Span):
        self.frames: list[list] = []  # [statements, index of the next one], innermost last
        self.last = span
        self.splice(stmts, span)

    def __bool__(self) -> bool:
        return bool(self.frames)

    def peek(self):
        stmts, i = self.frames[-1]
        return stmts[i]

    def pop(self):
        stmt, frame = self.peek(), self.frames[-1]
        frame[1] += 1
        if frame[1] == len(frame[0]):
            self.frames.pop()
        return stmt

    def splice(self, stmts: tuple, span: Span) -> None:
        """Lower `stmts` next. `last` is the span of the line's last statement (its tail
        EM points there), `span` (the owner's) when it has none."""
        if not self.frames:
            self.last = stmts[-1].span if stmts else span
        if stmts:
            self.frames.append([stmts, 0])


class _Taker(NamedTuple):
    """A hoisted block that takes its line's return point, and the rest it continues to."""

    stmt: object
    block: _Macro
    after: _Macro
    ctx: _Context  # the block's line


class _Line:
    """One line being lowered: its context, the statements left, its ops so far, and how
    it ended (a goto, or a hoisted block that took its return point)."""

    __slots__ = ("ctx", "todo", "ops", "started", "ended", "taker")

    def __init__(self, ctx: _Context, todo: _Todo):
        self.ctx, self.todo, self.ops = ctx, todo, []
        self.started = not ctx.at_start  # the line began before (a when block's XN/XF)
        self.ended, self.taker = False, None

    @property
    def first(self) -> bool:
        """Whether the statement being lowered starts the owner's line."""
        return not self.started and not self.ops

    @property
    def more(self) -> bool:
        """Whether statements follow the one being lowered on this line."""
        return bool(self.todo)

    @property
    def code_after(self) -> bool:
        """Whether anything runs after the statement: more statements, a tail EM, a loop's RP."""
        return self.more or self.ctx.cont is not None or self.ctx.loop

    def splice(self, stmts: tuple) -> None:
        self.todo.splice(stmts, self.ctx.owner.span)  # runs here, before what follows

    def end(self, ops: list, taker: _Taker | None = None) -> None:
        self.ops += ops
        self.ended, self.taker = True, taker


class _Added(Op):
    """An op the compiler adds to a loop (RP, WA): a too-long loop counts them apart from
    the commands the user wrote. Lowered ops are fresh objects, so the type is the mark
    (an id() of an op, once dropped, could be another op's)."""

    __slots__ = ()


def _is_em(op) -> bool:
    return isinstance(op, _Em) or (isinstance(op, Op) and op.mnemonic == Mnemonic.EM)


class _Lowerer:
    def __init__(self, env: Env, report: Report, inline: frozenset = frozenset()):
        self.env, self.report = env, report
        self.order: list[_Macro] = []
        self.names: set[str] = set()  # of the macros in `order`: a name is looked up, not searched
        self.next_part: dict[str, int] = {}  # owner -> the first part number that may be free
        self.named: dict[str, _Macro] = {}
        self.inlinable = inline  # named macros whose calls with code after them are inlined
        self.budget = 4000  # statements that inlining may copy: hostile input stays cheap
        self.loops: list[_Macro] = []  # the macro of each loop being lowered (for TI)
        self.warned: set = set()
        self.inlined: set[str] = set()
        # (span, leaf) of the hoisted blocks that call on: a statement is known by where it
        # stands (an inlined or unrolled copy is the same statement, lowered the same)
        self.calling_blocks: set[tuple] = set()

    def new(self, name: str, origin: Origin, span: Span, slot: int | None = None) -> _Macro:
        m = _Macro(name, origin, span, slot)
        self.order.append(m)
        self.names.add(name)
        return m

    def mark(self) -> tuple[int, int]:
        """Where the lowering stands: the macros made and the diagnostics given so far."""
        return len(self.order), len(self.report.items)

    def forget(self, mark: tuple[int, int]) -> None:
        """Drop what was lowered since `mark`: its macros (their names are free again) and
        its diagnostics (the lowering that is kept gives its own, once)."""
        made, said = mark
        self.names.difference_update(m.name for m in self.order[made:])
        self.next_part.clear()  # a dropped part's number may be taken again
        del self.order[made:]
        self.warned.difference_update(d.span for d in self.report.items[said:]
                                      if d.rule.name == "ti-moved")
        del self.report.items[said:]

    def helper(self, owner: _Macro, kind: str, span: Span) -> _Macro:
        """A compiler-made macro, named after its owner and line: 'jog.when@12'. One made
        for more owners than the controller has slots cannot be stored with them: it is
        named after the user's macro alone ('jog.rest@90'), so that a chain of thousands
        of rests does not make names thousands of owners long."""
        root = owner.root or owner
        name = f"{(owner if owner.depth < len(SLOTS) else root).name}.{kind}@{span.line}"
        if name in self.names:  # two blocks on one line
            name += f":{span.column}"
        made = self.new(name, Origin(kind), span)
        made.root, made.depth = root, owner.depth + 1
        return made

    # -- lines -------------------------------------------------------------
    def seq(self, stmts: tuple, ctx: _Context) -> list:
        """The ops of a statement sequence that runs to the end of its line (inside a
        repeat/every body: up to the loop's RP), then tail-EMs `ctx.cont`.

        Where a hoisted block takes the return point, the rest of the line is a
        line of its own; the rests are lowered one after another (a chain of
        thousands recursed), then each block with its rest as its tail,
        the last first: the order the macros were always made in.
        """
        todo, takers = _Todo(stmts, ctx.owner.span), []
        ops, taker = self.line(todo, ctx)
        while taker is not None:
            takers.append(taker)
            if not todo:  # nothing followed the block: its tail is `cont`
                break
            rest = taker.after
            rest.ops, taker = self.line(todo, ctx.rest(rest))
        for taker in reversed(takers):
            taker.block.ops = self.block_ops(taker.stmt, taker.ctx)
        return ops

    def line(self, todo: _Todo, ctx: _Context) -> tuple[list, _Taker | None]:
        """The ops of one line (see `seq`) and the hoisted block that took its return
        point, if one did: what is left in `todo` is then that block's rest."""
        line = _Line(ctx, todo)
        while todo and not line.ended:
            self.statement(todo.pop(), line)
        if not line.ended:
            line.ops += _tail(ctx.cont, todo.last)
        return line.ops, line.taker

    def statement(self, stmt, line: _Line) -> None:
        match stmt:
            case ast.Command():
                self.command(stmt, line)
            case ast.Call():
                self.call(stmt, line)
            case ast.Goto():
                self.goto(stmt, line)
            case ast.When():
                self.when(stmt, line)
            case ast.Repeat():
                self.repeat(stmt, line)
            case ast.Every():
                self.every(stmt, line)

    # -- statements, one kind each -------------------------------------------
    def command(self, stmt: ast.Command, line: _Line) -> None:
        """A native command; a TI moved away from the RP of its loop is reported."""
        op, owner = self.env.ops.get(stmt), line.ctx.owner
        if op is None:  # invalid: reported by the checks
            return
        if op.mnemonic == Mnemonic.TI and self.loops and self.loops[-1] is not owner \
                and op.span not in self.warned:
            self.warned.add(op.span)
            self.report.add("ti-moved", op.span, owner=as_written(owner.name),
                            loop=as_written(self.loops[-1].name))
        line.ops.append(op)

    def call(self, stmt: ast.Call, line: _Line) -> None:
        """An EM; the callee's body in its place where it calls on and code follows (a
        second return point, MS176E §3.8.4)."""
        if line.code_after and self.inline(stmt):
            line.splice(self.env.macros[stmt.name].body)
            return
        target = self.named.get(stmt.name)
        if target is not None:
            line.ops.append(_Em(target, stmt.span, Role.CALL))

    def goto(self, stmt: ast.Goto, line: _Line) -> None:
        """A goto transfers for good: nothing after it runs, and its EM ends the line."""
        target = self.named.get(stmt.name)
        line.end([] if target is None else [_Em(target, stmt.span, Role.GOTO)])

    def when(self, stmt: ast.When, line: _Line) -> None:
        """XN/XF and the block; a block that ends the line stays on it, others are hoisted."""
        ctx = line.ctx
        if line.more or ctx.loop or ctx.cont is not None:
            self.hoist(stmt, line)
            return
        line.ops += self.conditions(stmt)
        line.splice(stmt.body)
        line.started = True

    def repeat(self, stmt: ast.Repeat, line: _Line) -> None:
        """`repeat 0` runs nothing (reported as info); `repeat 1` (or a body that ends in a
        goto) runs once in its place; a small one on a line that must call nothing is
        written out; other counts loop."""
        first = line.first
        if self.count(stmt) == 0:
            return
        if self.once(stmt):
            line.splice(stmt.body)
        elif line.ctx.leaf and not first and self.unrollable(stmt):
            line.splice(stmt.body * self.count(stmt))
        else:
            self.loop(stmt, line, first)

    def every(self, stmt: ast.Every, line: _Line) -> None:
        """A polling loop; one whose body ends in a goto runs once, in its place."""
        if self.once(stmt):
            line.splice(stmt.body)
        else:
            self.loop(stmt, line, line.first)

    def loop(self, stmt, line: _Line, first: bool) -> None:
        """RP jumps to the start of the line: a loop that starts its line stays in it, and
        what follows runs on the same line once the loop is done; other loops are hoisted."""
        ctx = line.ctx
        if first and ctx.nest and not (ctx.loop and _has_ti(stmt.body)):
            line.ops += self.loop_ops(stmt, ctx)
        else:
            self.hoist(stmt, line)

    # -- blocks --------------------------------------------------------------
    def hoist(self, stmt, line: _Line) -> None:
        """Move a block into a macro of its own, called by an EM. If code follows it and
        the block calls on, it takes the return point: what follows continues in a macro
        (or the line's `cont`) that both the block and the line reach by a tail EM, and
        the block is lowered once that is (see `seq`)."""
        ctx = line.ctx
        block = self.helper(ctx.owner, type(stmt).__name__.lower(), stmt.span)
        line.ops.append(_Em(block, stmt.span, Role.HOIST))
        alone = ctx.block(block, None)
        if ctx.loop or not (line.more or ctx.cont is not None):  # nothing after: may call on
            block.ops = self.block_ops(stmt, alone)
        elif self.calls_on_alone(stmt, alone):
            after = self.helper(ctx.owner, "rest", line.todo.peek().span) if line.more else ctx.cont
            line.end(_tail(after, stmt.span), _Taker(stmt, block, after, ctx.block(block, after)))

    def calls_on_alone(self, stmt, ctx: _Context) -> bool:
        """Whether a hoisted block, lowered alone, calls on. If not, that lowering is the
        block's; if so, it is dropped and the answer kept: a block in nested blocks that
        call on was asked again in each lowering of theirs, 2^depth times."""
        key = (stmt.span, ctx.leaf)
        if key in self.calling_blocks:
            return True
        mark = self.mark()
        ctx.owner.ops = self.block_ops(stmt, ctx)
        if not _calls_on(ctx.owner.ops):
            return False
        self.forget(mark)
        self.calling_blocks.add(key)
        return True

    def block_ops(self, stmt, ctx: _Context) -> list:
        """A hoisted when/repeat/every block's ops, fitted, ending with a tail EM to `ctx.cont`."""
        block = ctx.owner
        if isinstance(stmt, ast.When):
            block.ops = self.conditions(stmt) + self.seq(stmt.body, ctx)
        else:
            block.ops = self.loop_ops(stmt, ctx) + _tail(ctx.cont, stmt.span)
        self.fit(block)  # a block that is split calls on, like one that calls
        return block.ops

    def loop_ops(self, stmt, ctx: _Context) -> list:
        """A loop that starts `ctx.owner`'s line: its body, then RP (every: WA, RP, RP)."""
        self.loops.append(ctx.owner)
        body = self.seq(stmt.body, ctx.body(stmt))
        self.loops.pop()
        if isinstance(stmt, ast.Repeat):
            # RP n runs the line n+1 times; two RPs multiply (program.rp_counts)
            return body + [_Added(Mnemonic.RP, n, stmt.span) for n in rp_counts(self.count(stmt))]
        # every T: wait T (several WAs past 65535 ms), then RP,RP = 65536 x 65536
        # passes, "forever" (§3.8.6 Example 1)
        period = self.value(stmt.period) or 0  # every 0ms: no WA0, a busy loop (every-zero)
        waits = [_Added(Mnemonic.WA, ms, stmt.span) for ms in wait_pieces(period)] if period else []
        return body + waits + [_Added(Mnemonic.RP, None, stmt.span),
                               _Added(Mnemonic.RP, None, stmt.span)]

    def conditions(self, stmt: ast.When) -> list:
        return [Op(Mnemonic.XF if c.negated else Mnemonic.XN, self.value(c.value), c.span)
                for c in stmt.conditions if self.value(c.value) is not None]

    def count(self, stmt: ast.Repeat) -> int:
        """The repeat count; an invalid one (already reported) counts as 1."""
        count = self.value(stmt.count)
        return count if count is not None and (count == 0 or rp_counts(count)) else 1

    def once(self, stmt) -> bool:
        """Whether a loop's body runs once: `repeat 1`, or a body that ends in a goto."""
        return (isinstance(stmt, ast.Repeat) and self.count(stmt) == 1) or _ends_in_goto(
            stmt.body, self.count)

    def unrollable(self, stmt: ast.Repeat) -> bool:
        """A repeat of plain commands that fits one macro when written out."""
        plain = all(isinstance(s, ast.Command) and s in self.env.ops
                    and self.env.ops[s].mnemonic not in _STAY for s in stmt.body)
        return plain and len(stmt.body) * self.count(stmt) <= MAX_COMMANDS

    def inline(self, stmt: ast.Call) -> bool:
        """Whether to run the callee's body in place of a call with code after it."""
        if stmt.name not in self.inlinable or self.budget <= 0:
            return False
        self.budget -= len(self.env.macros[stmt.name].body)
        self.inlined.add(stmt.name)
        return True

    def value(self, v: ast.Value) -> int | None:
        return self.env.values.get(v)

    # -- items -------------------------------------------------------------
    def module(self, module: ast.Module) -> None:
        for item in module.items:
            if isinstance(item, ast.MacroDef) and self.env.macros.get(item.name) is item:
                pin = item.pin.value if item.pin is not None and item.pin.value in SLOTS else None
                self.named[item.name] = self.new(item.name, Origin.MACRO, item.span, pin)
        for item in module.items:
            if isinstance(item, ast.RawBlock):
                m = self.new(slot_name(item.slot), Origin.RAW, item.span, item.slot)
                m.ops = [self.env.ops[c] for c in item.commands if c in self.env.ops]
            elif isinstance(item, ast.Autostart):
                m = self.new("autostart", Origin.AUTOSTART, item.span, 0)
                m.ops = self.seq(item.body, _Context(m)) or _nothing(item.span)
            elif isinstance(item, ast.MacroDef) and item.name in self.named:
                m = self.named[item.name]
                if self.env.macros[item.name] is item:
                    m.ops = self.seq(item.body, _Context(m)) or _nothing(item.span)

    def calling(self) -> set[str]:
        """The named macros whose lowered line calls on (contains an EM)."""
        return {m.name for m in self.order if m.origin is Origin.MACRO and any(map(_is_em, m.ops))}

    def split(self) -> None:
        """Fit every lowered macro into 16 commands (MS176E §3.8) where the meaning allows."""
        for m in list(self.order):
            self.fit(m)

    def fit(self, m: _Macro) -> None:
        """Fit one macro: the part after its last RP is chained through a tail EM; the
        part up to it stays on the line (RP repeats from the start) and moves runs of
        plain commands into macros it calls: those call nothing, so it keeps its
        return point."""
        while m.origin is not Origin.RAW and len(m.ops) > MAX_COMMANDS:
            last = max((i for i, op in enumerate(m.ops) if _is_op(op, Mnemonic.RP)), default=-1)
            if last + 1 < MAX_COMMANDS:
                self.chain(m)
                return
            runs = _movable_runs(m.ops[:last])
            if not runs:
                self.too_long_loop(m)
                return
            start, end = max(runs, key=lambda r: r[1] - r[0])
            end = start + min(end - start, len(m.ops) - MAX_COMMANDS + 1, MAX_COMMANDS)
            part = self.new(self.part_name(m), Origin.PART, m.span)
            part.ops = m.ops[start:end]
            m.ops[start:end] = [_Em(part, _span_of(part.ops[0], m.span), Role.HOIST)]

    def too_long_loop(self, m: _Macro) -> None:
        """A loop line that cannot be split, said in the user's terms: the commands they
        wrote, and the RP (WA) the loop adds, which they did not."""
        if m.too_long:
            return  # `split` fits every macro again
        m.too_long = True
        added = [op for op in m.ops if isinstance(op, _Added) or
                 (isinstance(op, _Em) and op.role in (Role.HOIST, Role.CONTINUE))]
        loop = next((op.span for op in added if isinstance(op, Op)), m.span)
        self.report.add("too-many-commands", loop, "loop", count=len(m.ops) - len(added),
                        added=_added_words(added), total=len(m.ops), max=MAX_COMMANDS,
                        room=max(0, MAX_COMMANDS - len(added)))

    def part_name(self, m: _Macro) -> str:
        """'jog.part2', 'jog.part3', ...: the next free part name of a split macro."""
        n = self.next_part.get(m.name, 2)  # not from 2 each time: thousands of parts
        while f"{m.name}.part{n}" in self.names:
            n += 1
        self.next_part[m.name] = n + 1
        return f"{m.name}.part{n}"

    def chain(self, m: _Macro) -> None:
        """Cut a line into parts of 15 commands and a tail EM to the next, the last part
        whole; each part is sliced once from the line (not the rest again at every cut)."""
        ops, part, keep, start = m.ops, m, MAX_COMMANDS - 1, 0
        while len(ops) - start > MAX_COMMANDS:
            tail = self.new(self.part_name(m), Origin.PART, m.span)
            part.ops = ops[start:start + keep] + [
                _Em(tail, _span_of(ops[start + keep], m.span), Role.CONTINUE)]
            part, start = tail, start + keep
        part.ops = ops[start:]

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
                    self.report.add("slot-range", m.span, "full", name=as_written(m.name),
                                    count=len(self.order))
                    continue
                taken[m.slot] = m
        return taken


def _added_words(added: list) -> str:
    """What a loop added, for a message: '1 RP', '1 WA and 2 RPs', '1 RP and 2 EMs'."""
    rps = sum(isinstance(op, Op) and op.mnemonic == Mnemonic.RP for op in added)
    was = sum(isinstance(op, Op) and op.mnemonic == Mnemonic.WA for op in added)
    ems = len(added) - rps - was  # tail and hoisting EMs
    parts = [f"{n} {what}{'s' * (n != 1)}" for n, what in
             ((rps, Mnemonic.RP), (was, Mnemonic.WA), (ems, Mnemonic.EM)) if n]
    return " and ".join(parts) or "nothing"


def _is_op(op, mnemonic: str) -> bool:
    return isinstance(op, Op) and op.mnemonic == mnemonic


# Commands that behave the same in a called macro: not calls, conditions (they
# would end the called macro, not the loop), RP, or TI (it reads the loop's counter).
_STAY = (Mnemonic.EM, Mnemonic.XN, Mnemonic.XF, Mnemonic.RP, Mnemonic.TI)


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


def _nothing(span: Span) -> list:
    """An empty macro: `WA0`, a command that does nothing, so that the slot holds no
    older macro (a bare `MDn` is no form of the manual's `MDn,<commands>`, §3.8.1)."""
    return [Op(Mnemonic.WA, 0, span)]


def _ends_in_goto(body: tuple, count) -> bool:
    """Whether a block always reaches a goto: one of its own, or one that ends a loop
    in it that runs at all (such a loop runs once)."""
    return any(isinstance(s, ast.Goto) or (
        isinstance(s, (ast.Repeat, ast.Every)) and not (isinstance(s, ast.Repeat) and count(s) == 0)
        and _ends_in_goto(s.body, count)) for s in body)


def _has_ti(body: tuple) -> bool:
    """Whether a TI stands in the block, at any depth."""
    return any(s.word.upper() == Mnemonic.TI if isinstance(s, ast.Command)
               else _has_ti(getattr(s, "body", ())) for s in body)


def _tail(cont: _Macro | None, span: Span) -> list:
    return [] if cont is None else [_Em(cont, span, Role.CONTINUE)]


def _span_of(op, default: Span) -> Span:
    return op.span or default


def _final(op) -> Op:
    if isinstance(op, _Em):
        return Op(Mnemonic.EM, op.target.slot, op.span, op.role)
    return Op(*op) if isinstance(op, _Added) else op


def lower(module: ast.Module, env: Env, report: Report, file: str = "") -> Program:
    """The program a module stands for (errors are reported, never raised).

    A call with code after it to a macro that calls on would need a second
    return point (MS176E §3.8.4): such a macro is inlined where it fits. Which
    macros call on is known once they are lowered, so lowering runs again with
    them inlined until nothing changes (diagnostics come from the last run).
    """
    candidates = _inlinable(module, env)
    inline: frozenset = frozenset()
    while True:
        scratch = Report(report.file)
        lowerer = _Lowerer(env, scratch, inline)
        lowerer.module(module)
        lowerer.split()
        more = inline | (lowerer.calling() & candidates)
        if more == inline:
            break
        inline = more
    slots = lowerer.allocate()
    report.items.extend(scratch.items)
    macros = {
        slot: Macro(slot, m.name, [_final(op) for op in m.ops], m.span, m.origin)
        for slot, m in sorted(slots.items())
    }
    return Program(macros, env.target, file, frozenset(lowerer.inlined))


def _inlinable(module: ast.Module, env: Env) -> frozenset:
    """Named macros whose body may run in a caller's place: those that call on only
    because blocks of theirs were hoisted or split. One that calls or goes to a
    macro as written is a nested call (docs/checks.md), and native EM/XN/XF/RP/TI would
    act on the caller's line."""

    def plain(body) -> bool:
        for s in body:
            if isinstance(s, (ast.Goto, ast.Call)):
                return False
            if isinstance(s, ast.Command):
                op = env.ops.get(s)
                if op is None or op.mnemonic in _STAY:
                    return False
            elif not plain(s.body):
                return False
        return True

    return frozenset(name for name, item in env.macros.items() if plain(item.body))
