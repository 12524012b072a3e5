"""Two small, time-free interpreters for tests: the high-level meaning of a
module, and the firmware's execution of a lowered program (SPEC §3).

Both record the "effects" (every command that is not control flow) until the
program ends or a budget runs out, so traces can be compared.
"""
from __future__ import annotations

from mercmac.compiler import ast
from mercmac.compiler.checks import Env

CONTROL = {"EM", "XN", "XF", "RP"}
CUT = "..."  # ends a trace cut short by its step budget (long loops without effects)


class Budget(Exception):
    """The trace is long enough to compare."""


class _Goto(Exception):
    """Transfer for good to the named macro."""

    def __init__(self, name: str):
        self.name = name


def high_level_trace(module: ast.Module, env: Env, inputs: set[int], limit: int = 200,
                     steps: int = 200_000) -> list[str]:
    """What the autostart block means, run with inputs held as given."""
    trace: list[str] = []
    budget = [steps]
    macros = {m.name: m for m in module.items if isinstance(m, ast.MacroDef)}
    start = next(i for i in module.items if isinstance(i, ast.Autostart))

    def emit(text):
        trace.append(text)
        if len(trace) >= limit:
            raise Budget

    def tick():
        budget[0] -= 1
        if budget[0] < 0:
            trace.append(CUT)
            raise Budget

    def run(body):
        for stmt in body:
            tick()
            if isinstance(stmt, ast.Command):
                op = env.ops[stmt]
                if op.mnemonic in CONTROL:
                    raise AssertionError("control commands are not generated")
                emit(op.text)
            elif isinstance(stmt, ast.Call):
                run(macros[stmt.name].body)
            elif isinstance(stmt, ast.Goto):
                raise _Goto(stmt.name)
            elif isinstance(stmt, ast.When):
                if all((env.values[c.value] in inputs) != c.negated for c in stmt.conditions):
                    run(stmt.body)
            elif isinstance(stmt, ast.Repeat):
                for _ in range(env.values[stmt.count]):
                    run(stmt.body)
                    tick()
            elif isinstance(stmt, ast.Every):
                for _ in range(2**32):
                    run(stmt.body)
                    emit(f"WA{env.values[stmt.period]}")
                    tick()

    body = start.body
    while True:  # a goto cycle without effects runs until the step budget
        try:
            run(body)
            break
        except Budget:
            break
        except _Goto as g:
            body = macros[g.name].body
            try:
                tick()
            except Budget:
                break
    return trace


def firmware_trace(lines: dict[int, list[tuple[str, int | None]]], inputs: set[int],
                   limit: int = 200, steps: int = 200_000) -> list[str]:
    """Run macro 0 of stored lines {slot: [(mnemonic, arg)]} straight from SPEC §3."""
    trace: list[str] = []
    slot, pc, counters, ret = 0, 0, {}, None
    for _ in range(steps):
        ops = lines[slot]
        if pc >= len(ops):  # the macro ends: return, or the program ends
            if ret is None:
                return trace
            (slot, pc, counters), ret = ret, None
            continue
        name, arg = ops[pc]
        if name == "EM":
            if arg in lines:  # EM to an empty slot does nothing
                ret = (slot, pc + 1, counters)
                slot, pc, counters = arg, 0, {}
                continue
        elif name in ("XN", "XF"):
            if (arg in inputs) != (name == "XN"):
                pc = len(ops)
                continue
        elif name == "RP":
            n = 65535 if arg is None else arg
            if pc not in counters:
                counters[pc] = n
                if n > 0:
                    pc = 0
                    continue
            else:
                counters[pc] -= 1
                if counters[pc] > 0:
                    pc = 0
                    continue
                del counters[pc]
        else:
            trace.append(name if arg is None else f"{name}{arg}")
            if len(trace) >= limit:
                return trace
        pc += 1
    return trace + [CUT]


def _merged(trace: list[str]) -> list[str]:
    """Consecutive waits as one (`WA60000,WA60000` is `WA120000`), `WA0` dropped: time-free."""
    out: list[str] = []
    for text in trace:
        if text.startswith("WA") and text[2:].isdigit():
            ms = int(text[2:]) + (int(out.pop()[2:]) if out and out[-1].startswith("WA") else 0)
            if ms:
                out.append(f"WA{ms}")
        else:
            out.append(text)
    return out


def same_effects(got: list[str], want: list[str], limit: int = 200) -> bool:
    """Whether two traces mean the same; a trace cut at `limit` is compared as a prefix."""
    a, b = _merged([t for t in got if t != CUT]), _merged([t for t in want if t != CUT])
    if len(got) < limit and len(want) < limit and CUT not in got + want:
        return a == b
    n = min(len(a), len(b)) - 1  # the last entry of a cut trace may be a partial wait
    return a[:max(n, 0)] == b[:max(n, 0)]
