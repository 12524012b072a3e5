"""The tests' reference semantics, time-free: the high-level meaning of a module, and
the one reference interpreter of the firmware (docs/simulator.md), `Firmware`, that both the
lowering tests and the VM's differential test run.

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


class Firmware:
    """The controller's execution of stored lines, straight from docs/simulator.md, without time.

    `lines` is {slot: [(mnemonic, arg)]}; `inputs` are held for the whole run. Every
    command that is not control flow is an effect (`effects`, as text); the outputs
    pattern after each change of CN/CF/CP (`patterns`) and what TI and TB report
    (`reports`) are kept too, so that the VM can be compared with it
    (test_vm_differential) and lowered programs with their source (test_properties).
    """

    def __init__(self, lines: dict[int, list[tuple[str, int | None]]], inputs: set[int],
                 limit: int | None = None):
        self.lines, self.inputs, self.limit = lines, inputs, limit
        self.effects: list[str] = []
        self.reports: list[str] = []
        self.patterns: list[int] = []
        self.outputs = 0

    def run(self, steps: int = 200_000) -> bool:
        """Run macro 0; True if the program ended (or `limit` effects were made) within
        `steps` executed commands."""
        if 0 not in self.lines:
            return True
        slot, pc, return_point = 0, 0, None
        counters: dict[tuple[int, int], int] = {}  # (slot, index of the RP) -> count
        jumped: dict[int, int] = {}  # slot -> index of the RP that last jumped (for TI)
        for _ in range(steps):
            line = self.lines[slot]
            exit_macro = pc >= len(line)
            if not exit_macro:
                name, n = line[pc]
                pc += 1
                if name == "EM":
                    if n in self.lines:  # EM to an empty slot does nothing
                        # "stores 'continue after this EM in the current macro' ... and starts n"
                        return_point, slot, pc = (slot, pc), n, 0
                        for key in [k for k in counters if k[0] == n]:
                            del counters[key]  # "Counters of a macro reset when it is entered"
                        jumped.pop(n, None)
                elif name == "RP":
                    key = (slot, pc - 1)
                    first = 65535 if n is None else n  # a bare RP means 65535
                    counters[key] = first if key not in counters else counters[key] - 1
                    if counters[key] > 0:
                        jumped[slot], pc = pc - 1, 0
                    else:
                        del counters[key]  # a later arrival starts again
                elif name in ("XN", "XF"):
                    exit_macro = (n in self.inputs) != (name == "XN")
                elif self._effect(name, n, counters.get((slot, jumped.get(slot)), 0)):
                    return True
            if exit_macro:  # the macro ends: return, or the program ends
                if return_point is None:
                    return True
                (slot, pc), return_point = return_point, None
        return False

    def _effect(self, name: str, n: int | None, remaining: int) -> bool:
        """Record one effect; True when `limit` effects are recorded."""
        self.effects.append(name if n is None else f"{name}{n}")
        before = self.outputs
        if name == "CN":
            self.outputs |= 1 << (n - 1)
        elif name == "CF":
            self.outputs &= ~(1 << (n - 1))
        elif name == "CP":
            self.outputs = n
        elif name == "TI":  # the remaining count of the RP that last jumped
            self.reports.append(f"X:{remaining:+011d}")
        elif name == "TB":
            self.reports.append("B:0")
        if self.outputs != before:
            self.patterns.append(self.outputs)
        return self.limit is not None and len(self.effects) >= self.limit


def firmware_trace(lines: dict[int, list[tuple[str, int | None]]], inputs: set[int],
                   limit: int = 200, steps: int = 200_000) -> list[str]:
    """The effects of running macro 0 of stored lines, ending in CUT when the step budget
    ran out first."""
    firmware = Firmware(lines, inputs, limit)
    return firmware.effects + ([] if firmware.run(steps) else [CUT])


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
