"""How often a `when` inside a loop reads its inputs: the `slow-poll` rule (docs/checks.md).

A condition is read once, when its XN/XF runs (MS176E §5.5, §6.4 XN/XF), so a `when` in a
loop reads its inputs once per pass, and a press that begins and ends between two reads is
never seen. A pass lasts at least the waits in it: WA n, n ms from its start (§6.4 WA); the
period of an `every`, its WA; WS n, n ms after a move of unknown length (§6.4 WS); WN/WF, as
long as the input takes. The commands themselves take a controller cycle each and are left
out, so the time is a lower bound (docs/simulator.md, "Time").

Only loops that hold a `when` are timed, and only once the whole file is checked (a `call`
may name a macro further down): checking plain commands costs nothing more.
"""
from __future__ import annotations

from typing import NamedTuple

from mercmac.commands import COMMANDS, Mnemonic
from mercmac.compiler import ast
from mercmac.compiler.program import SLOTS, Macro, Program
from mercmac.diagnostics import Report
from mercmac.ops import Op
from mercmac.source import Span

# A quick press of a pushbutton lasts a few tenths of a second: a loop whose pass is longer
# than this may miss one, so it is worth saying how long a button must be held.
SLOW_MS = 250
_CONDITIONS = (Mnemonic.XN, Mnemonic.XF)


class Pass(NamedTuple):
    """The least time one pass of a loop takes, in ms; `sure`: no wait of unknown length."""

    ms: int
    sure: bool = True

    def __add__(self, other: Pass) -> Pass:
        return Pass(self.ms + other.ms, self.sure and other.sure)

    def times(self, n: int) -> Pass:
        return Pass(self.ms * n, self.sure)

    def took(self) -> str:
        """'400 ms', or 'at least 400 ms' when a WS, WN, WF or a call may add to it."""
        return f"{self.ms} ms" if self.sure else f"at least {self.ms} ms"


NOTHING = Pass(0)
UNKNOWN = Pass(0, sure=False)


def op_time(op: Op) -> Pass:
    """The least time one command takes (its cycle left out)."""
    name = op.mnemonic
    if name == Mnemonic.WA:
        return Pass(op.arg or 0)
    if name == Mnemonic.WS:  # n ms after the move, whose length is not known here
        return Pass(COMMANDS[name].default if op.arg is None else op.arg, sure=False)
    if name in (Mnemonic.WN, Mnemonic.WF, Mnemonic.EM):
        return UNKNOWN
    return NOTHING


def check_loops(loops: list, env, report: Report) -> None:
    """Report each `when` read once per pass of a `repeat` or `every` in `loops` (those
    whose block holds a `when`) whose pass takes longer than SLOW_MS."""
    timer = _Timer(env)
    for loop in loops:
        took = timer.loop(loop)
        if took is None or took.ms <= SLOW_MS:
            continue
        kind = "every" if isinstance(loop, ast.Every) else "repeat"
        for when in _whens(loop.body):
            last = when.conditions[-1].span
            report.add("slow-poll", Span(when.span.line, when.span.column, last.end_line,
                                         last.end_column),
                       inputs=_inputs(when, env), kind=kind, line=loop.span.line,
                       took=took.took())


def check_raw_loop(program: Program, m: Macro, report: Report) -> None:
    """A raw `[MCnn]` line that loops (an RP that jumps) and calls macros that start with
    conditions, as the manual's Example 4 does (MS176E §3.8.6): each such EM reads its
    macro's inputs once per pass of the line."""
    end = next((i for i, op in enumerate(m.ops)
                if op.mnemonic == Mnemonic.RP and op.arg != 0), None)  # RP0 jumps nowhere
    if end is None:
        return
    took, reads = NOTHING, []
    for op in m.ops[:end]:  # the first RP that jumps repeats everything before it
        callee = program.macros.get(op.arg) if op.mnemonic == Mnemonic.EM else None
        if callee is None:
            took += op_time(op)
            continue
        first = next((i for i, o in enumerate(callee.ops) if o.mnemonic in _CONDITIONS), None)
        before = callee.ops if first is None else callee.ops[:first]
        for o in before:  # what runs before the conditions runs every pass
            took += UNKNOWN if o.mnemonic == Mnemonic.RP else op_time(o)
        if first is not None:
            reads.append((op, callee, callee.ops[first]))
    if took.ms <= SLOW_MS:
        return
    for op, callee, condition in reads:
        report.add("slow-poll", op.span or m.span, "raw", call=op.text, callee=callee.written,
                   condition=condition.text, input=condition.arg, loop=m.written,
                   took=took.took())


class _Timer:
    """The least time of a pass of a loop, and of a run of each macro a pass calls."""

    def __init__(self, env):
        self.env = env
        self.macros: dict[str, Pass | None] = {}  # by name; None: it never comes back
        self.depth = 0  # calls being timed, one inside the other

    def loop(self, loop) -> Pass | None:
        """One pass of a `repeat` or `every` block; None when it never comes round."""
        took = self.block(loop.body)
        if took is None or isinstance(loop, ast.Repeat):
            return took
        period = self.env.values.get(loop.period)  # every T: WA T after the block
        return None if period is None else took + Pass(period)

    def block(self, body: tuple) -> Pass | None:
        """A run of a block with no input pressed: a `when` block adds nothing. None when
        it does not come to its end (a goto, an `every`, a count that is not known)."""
        took = NOTHING
        for s in body:
            if isinstance(s, ast.Command):
                op = self.env.ops.get(s)
                took += NOTHING if op is None else op_time(op)
            elif isinstance(s, ast.Repeat):
                count, inner = self.env.values.get(s.count), self.block(s.body)
                if count is None or inner is None:
                    return None
                took += inner.times(max(count, 0))
            elif isinstance(s, ast.Call):
                inner = self.called(s.name)
                if inner is None:
                    return None
                took += inner
            elif isinstance(s, (ast.Goto, ast.Every)):
                return None  # the pass never comes back round
        return took

    def called(self, name: str) -> Pass | None:
        if name in self.macros:
            return self.macros[name]
        macro = self.env.macros.get(name)
        # calls deeper than the controller has slots cannot be stored anyway (nested-call,
        # slot-range say why): not followed, so a long chain cannot exhaust Python's stack
        if macro is None or self.depth >= len(SLOTS):
            return UNKNOWN
        self.macros[name] = UNKNOWN  # a call back into it while it is timed: unknown
        self.depth += 1
        try:
            self.macros[name] = self.block(macro.body)
        finally:
            self.depth -= 1
        return self.macros[name]


def _whens(body: tuple):
    """The `when` blocks read once per pass of the loop whose block is `body`: those in it
    and in its `when` blocks, not those of the loops it holds (each reports its own)."""
    for s in body:
        if isinstance(s, ast.When):
            yield s
            yield from _whens(s.body)


def _inputs(when: ast.When, env) -> str:
    """'input 1', 'inputs 2 and 3': what a `when` reads."""
    numbers = [str(env.values.get(c.value, "?")) for c in when.conditions]
    if len(numbers) == 1:
        return f"input {numbers[0]}"
    return f"inputs {', '.join(numbers[:-1])} and {numbers[-1]}"
