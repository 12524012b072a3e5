"""Checks on the lowered program, where the firmware's rules really apply
(docs/checks.md, docs/simulator.md).

Run on what will be uploaded, so hoisting and splitting are checked too:
the one return point, EM to empty slots, reachability, SC placement,
contradictory conditions, the 16-command limit and goto placement.
"""
from __future__ import annotations

from mercmac.commands import Mnemonic
from mercmac.compiler.program import MAX_COMMANDS, Macro, Program
from mercmac.compiler.sampling import check_raw_loop
from mercmac.ops import USER_ORIGINS, Op, Origin, Role
from mercmac.diagnostics import Report, Severity

_CONDITIONS = (Mnemonic.XN, Mnemonic.XF)


def check_program(program: Program, report: Report) -> None:
    """Report every rule that needs the lowered program."""
    for m in program.macros.values():
        _length(m, report)
        _placement(m, report)
        _contradictions(m, report)
        calls = False
        for i, op in enumerate(m.ops):
            if op.mnemonic == Mnemonic.EM:
                _call(program, m, i, op, report)
                calls = True
        if calls and m.origin is Origin.RAW:  # a raw loop polls through the macros it calls
            check_raw_loop(program, m, report)
    _reachability(program, report)


def _length(m: Macro, report: Report) -> None:
    if m.origin == Origin.RAW and len(m.ops) > MAX_COMMANDS:
        report.add("too-many-commands", m.span, macro=m.written, count=len(m.ops),
                   max=MAX_COMMANDS)


def _placement(m: Macro, report: Report) -> None:
    for i, op in enumerate(m.ops):
        if op.mnemonic == Mnemonic.SC and m.slot != 0:
            moved = "" if m.origin in USER_ORIGINS else "moved"
            report.add("sc-outside-autostart", op.span or m.span, moved, macro=m.written)
        if op.role == Role.GOTO and i != len(m.ops) - 1:
            report.add("goto-not-last", op.span or m.span, "loop")


def _contradictions(m: Macro, report: Report) -> None:
    seen: dict[tuple[str, int], Op] = {}
    for op in m.ops:
        if op.mnemonic not in _CONDITIONS:
            continue
        other = seen.get((Mnemonic.XF if op.mnemonic == Mnemonic.XN else Mnemonic.XN, op.arg))
        if other is not None:
            report.add("contradictory-condition", op.span or m.span, macro=m.written,
                       input=op.arg, first=other.text, second=op.text)
        seen.setdefault((op.mnemonic, op.arg), op)


def _call(program: Program, caller: Macro, index: int, op: Op, report: Report) -> None:
    if op.arg is None:
        return  # its target got no slot: reported as slot-range
    callee = program.macros.get(op.arg)
    if callee is None:
        report.add("undefined-macro", op.span or caller.span, slot=op.arg)
        return
    remainder = caller.ops[index + 1:]
    if not remainder:
        return
    chain = _goto_chain(program, callee) if op.role == Role.CALL else None
    if chain:
        report.add("nested-call", op.span or caller.span, "goto", severity=Severity.ERROR,
                   caller=caller.written, callee=callee.written, chain=" -> ".join(chain),
                   rest=",".join(o.text for o in remainder))
        return
    if _returns(program, callee, remainder):
        return
    inner = program.macros[next(o.arg for o in callee.ops
                                if o.mnemonic == Mnemonic.EM and o.arg in program.macros)]
    raw = op.role == Role.RAW  # on raw blocks the manual's own way of switching modes
    report.add("nested-call", op.span or caller.span,
               "" if raw else _advice(op, caller, inner),
               severity=Severity.WARNING if raw else Severity.ERROR, caller=caller.written,
               callee=callee.written, inner=inner.written, rest=",".join(o.text for o in remainder),
               max=MAX_COMMANDS, target=inner.name, loop=caller.name,
               line=_loop_line(remainder, caller))


def _returns(program: Program, callee: Macro, remainder: list[Op]) -> bool:
    """Whether calling `callee` still lets the caller finish its line as written."""
    # An EM to an empty slot does nothing (MS176E §6.4 EM), so it keeps the return point.
    ems = [i for i, o in enumerate(callee.ops)
           if o.mnemonic == Mnemonic.EM and o.arg in program.macros]
    if not ems:
        return True
    if any(o.mnemonic in _CONDITIONS for o in callee.ops[ems[0]:]):
        return False  # an XN/XF after an inner call ends the program, not the callee
    alone = len(remainder) == 1 and remainder[0].mnemonic == Mnemonic.EM
    then = remainder[0].arg if alone else None
    return _ends_on_purpose(program, callee, then)


def _ends_on_purpose(program: Program, macro: Macro, then: int | None) -> bool:
    """Whether every run of `macro`, followed through tail EMs into compiler-made
    continuations, ends in a goto (a mode switch: the caller's rest is abandoned on
    purpose) or in a tail EM to `then`, the caller's own last step."""
    seen = set()
    while macro.ops and macro.slot not in seen:
        last = macro.ops[-1]
        if last.mnemonic != Mnemonic.EM:
            return False
        if last.role == Role.GOTO or (last.role == Role.CONTINUE and last.arg == then):
            return True  # raw EMs never count: on raw blocks the rule is the manual's, as written
        if last.role != Role.CONTINUE or last.arg not in program.macros:
            return False
        seen.add(macro.slot)
        macro = program.macros[last.arg]
        if any(o.mnemonic in _CONDITIONS for o in macro.ops):
            return False
    return False


def _goto_chain(program: Program, callee: Macro) -> list[str] | None:
    """The path from a called macro to a goto it may run ('g (MC01) -> goto m (MC02)'),
    through the macros the compiler made of its blocks; None when it has none."""
    seen, todo = {callee.slot}, [(callee, [callee.written])]
    while todo:
        macro, path = todo.pop(0)
        for o in macro.ops:
            target = program.macros.get(o.arg) if o.mnemonic == Mnemonic.EM else None
            if target is None:
                continue
            if o.role == Role.GOTO:
                return path + [f"goto {target.written}"]
            if o.role in (Role.HOIST, Role.CONTINUE) and target.slot not in seen:
                seen.add(target.slot)
                todo.append((target, path + [target.written]))
    return None


def _advice(op: Op, caller: Macro, inner: Macro) -> str:
    """The `nested-call` message variant that says what to do about it."""
    if inner.origin == Origin.PART:
        return "split"  # the callee was chained into parts
    if op.role == Role.CALL:
        return "call"
    # A when block hoisted out of a loop (the only hoisted block with code after its EM):
    # the pattern that works is goto the work and goto back to the loop's macro, which
    # the user can name only if the loop starts a macro of theirs (docs/language.md).
    return _LOOP_ADVICE[inner.origin == Origin.MACRO, caller.origin == Origin.MACRO]


# (the work is a macro of the user's, the loop starts a macro of theirs) -> variant
_LOOP_ADVICE = {(True, True): "loop", (False, True): "loop-block",
                (True, False): "loop-unnamed", (False, False): "loop-block-unnamed"}


def _loop_line(remainder: list[Op], caller: Macro) -> int | None:
    """The line of the innermost loop around a block: its RP is the first after the block's EM."""
    rp = next((o for o in remainder if o.mnemonic == Mnemonic.RP and o.span), None)
    span = rp.span if rp else caller.span
    return span.line if span else None


def _reachability(program: Program, report: Report) -> None:
    if 0 not in program.macros:
        return
    seen, todo = {0}, [0]
    while todo:
        for op in program.macros[todo.pop()].ops:
            if op.mnemonic == Mnemonic.EM and op.arg in program.macros and op.arg not in seen:
                seen.add(op.arg)
                todo.append(op.arg)
    for m in program.macros.values():
        if m.slot not in seen and m.origin in USER_ORIGINS and m.name not in program.inlined:
            report.add("unreachable-macro", m.span, macro=m.written)
