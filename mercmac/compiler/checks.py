"""Checks on the syntax tree: commands, arguments, names and slots (SPEC §2).

The pass also resolves what lowering needs: each valid native command as an
`Op`, each `const`, each named macro. Checks only report and carry on.
"""
from __future__ import annotations

import functools

from mercmac.commands import MODELS, Arg, lookup, nearest
from mercmac.compiler import ast
from mercmac.compiler.program import MAX_WA, MAX_WAITS, SLOTS, Op, rp_counts
from mercmac.diagnostics import Report
from mercmac.source import Span

MAX_REPEAT = 32_568 + 1  # `repeat N` lowers to RP N-1; MS176E §6.4 RP: n <= 32568
MAX_PERIOD_MS = MAX_WA * MAX_WAITS  # `every T` lowers to WA T, several WAs past 65535 ms
INPUTS = range(1, 7)  # XN/XF: 1-4 inputs, 5 joystick, 6 joystick button (§6.4 XN)


class Env:
    """What the checks resolved, for lowering."""

    def __init__(self, target: str | None = None):
        self.target = target
        self.consts: dict[str, int] = {}
        self.macros: dict[str, ast.MacroDef] = {}
        self.ops: dict[ast.Command, Op] = {}
        self.values: dict[ast.Value, int] = {}


def check_module(module: ast.Module, report: Report, target: str | None) -> Env:
    """Report every AST-level problem; return the resolved environment."""
    env = Env(target=target)
    _declarations(module, report, env)
    slots: dict[int, Span] = {}
    for item in module.items:
        if isinstance(item, ast.RawBlock):
            _claim_slot(item.slot, item.span, f"MC{item.slot:02d}", slots, report)
            for command in item.commands:
                _command(command, env, report, raw=True)
        elif isinstance(item, ast.Autostart):
            _claim_slot(0, item.span, "the autostart macro (macro 0)", slots, report)
            _block(item.body, env, report)
        elif isinstance(item, ast.MacroDef):
            if isinstance(item.pin, ast.Invalid):
                _resolve(item.pin, env, report)
            elif item.pin is not None:
                _claim_slot(item.pin.value, item.pin.span, f"macro {item.pin.value}", slots, report)
            _block(item.body, env, report)
    return env


def _declarations(module: ast.Module, report: Report, env: Env) -> None:
    targets = [i for i in module.items if isinstance(i, ast.Target)]
    for t in targets:
        if t.model not in MODELS:
            report.add("bad-argument", t.span, f"unknown model '{t.model}': use C-663 or C-863")
    if env.target is None and targets and targets[-1].model in MODELS:
        env.target = targets[-1].model
    for item in module.items:
        if isinstance(item, ast.Const):
            if item.name in env.consts:
                report.add("duplicate-name", item.span, f"const '{item.name}' is defined twice")
            # an invalid value is reported here once; its uses resolve to None and stay quiet
            env.consts[item.name] = _resolve(item.value, env, report) if isinstance(
                item.value, ast.Invalid) else item.value
        elif isinstance(item, ast.MacroDef):
            first = env.macros.get(item.name)
            if first is not None:
                report.add("duplicate-slot", item.span,
                           f"macro '{item.name}' is defined twice (first at line {first.span.line})")
            else:
                env.macros[item.name] = item


def _claim_slot(slot: int, span: Span, what: str, slots: dict[int, Span], report: Report) -> None:
    if slot not in SLOTS:
        shown = slot if slot < ast.TOO_BIG else f"of more than {ast.MAX_DIGITS} digits"
        report.add("slot-range", span, f"macro number {shown} is outside 0-31")
    elif slot in slots:
        report.add("duplicate-slot", span,
                   f"{what} defines slot {slot} again (first at line {slots[slot].line}); "
                   "the controller silently keeps only the last definition")
    else:
        slots[slot] = span


def _block(body: tuple, env: Env, report: Report) -> None:
    for i, stmt in enumerate(body):
        if isinstance(stmt, ast.Command):
            _command(stmt, env, report, raw=False)
        elif isinstance(stmt, (ast.Call, ast.Goto)):
            _macro_name(stmt.name, stmt.span, env, report)
            if isinstance(stmt, ast.Goto) and i != len(body) - 1:
                report.add("syntax", stmt.span,
                           "goto transfers for good, so it must be the last statement of its block")
        elif isinstance(stmt, ast.When):
            for c in stmt.conditions:
                _bounded(c.value, env, report, INPUTS,
                         "when takes inputs 1-6 (1-4 buttons, 5 joystick, 6 joystick button)")
            _block(stmt.body, env, report)
        elif isinstance(stmt, ast.Repeat):
            _repeat_count(stmt, env, report)
            _loop_goto(stmt, "repeat", report)
            _block(stmt.body, env, report)
        elif isinstance(stmt, ast.Every):
            _bounded(stmt.period, env, report, range(0, MAX_PERIOD_MS + 1),
                     f"every takes a whole period of 0-{MAX_PERIOD_MS} ms (it lowers to WA, "
                     f"several WAs of at most {MAX_WA} ms past that)")
            _loop_goto(stmt, "every", report)
            _block(stmt.body, env, report)


def _repeat_count(stmt: ast.Repeat, env: Env, report: Report) -> None:
    """1-32569 lowers to one RP, a product of two such counts to two; 0 runs nothing."""
    number = _resolve(stmt.count, env, report)
    if number == 0:
        report.add("repeat-zero", stmt.span, "repeat 0 never runs its block: it is left out")
    elif number is not None and (number < 0 or rp_counts(number) is None):
        report.add("argument-range", stmt.count.span,
                   f"{number} is out of range: repeat takes a count 0-{MAX_REPEAT} (it lowers "
                   f"to RP n-1, RP n <= 32568), or a product of two such counts (two RPs)")


def _loop_goto(stmt, kind: str, report: Report) -> None:
    """A loop whose block always reaches a goto runs once: the goto leaves it on the
    first pass (a goto that ends a loop inside it counts: that loop runs once too)."""
    goto = _first_goto(stmt.body)
    if goto is not None:
        report.add("goto-ends-loop", goto.span,
                   f"this goto ends the {kind} block (line {stmt.span.line}) on its first pass: "
                   "the block runs once. Drop the loop, or put the goto in a when block")


def _first_goto(body: tuple):
    for s in body:
        if isinstance(s, ast.Goto):
            return s
        if isinstance(s, (ast.Repeat, ast.Every)):
            inner = _first_goto(s.body)
            if inner is not None:
                return inner
    return None


def _macro_name(name: str, span: Span, env: Env, report: Report) -> None:
    if name not in env.macros:
        hint = _suggest(name, env.macros)
        report.add("undefined-name", span, f"no macro named '{name}'{hint}")


def _suggest(name: str, known) -> str:
    close = [k for k in known if k.lower() == name.lower()] or [
        k for k in known if k.lower().startswith(name.lower()[:3])]
    return f"; did you mean '{close[0]}'?" if close else ""


def _bounded(value: ast.Value, env: Env, report: Report, allowed: range, expects: str) -> None:
    number = _resolve(value, env, report)
    if number is not None and number not in allowed:
        report.add("argument-range", value.span, f"{number} is out of range: {expects}")


def _resolve(value: ast.Value, env: Env, report: Report) -> int | None:
    if isinstance(value, ast.Invalid):
        report.add(value.rule, value.span, value.message)
        return None
    if isinstance(value, ast.Number):
        env.values[value] = value.value
        return value.value
    if value.name not in env.consts:
        hint = (f"; '{value.name}' is a macro: write `call {value.name}` or `goto {value.name}`"
                if value.name in env.macros else _suggest(value.name, env.consts))
        report.add("undefined-name", value.span, f"no const named '{value.name}'{hint}")
        return None
    env.values[value] = env.consts[value.name]
    return env.consts[value.name]


def _command(cmd: ast.Command, env: Env, report: Report, *, raw: bool) -> None:
    """Validate one native command; record its Op when it is valid."""
    spec = lookup(cmd.word)
    if spec is None:
        _unknown(cmd, report)
        return
    arg = None
    if cmd.value is not None:
        if spec.arg is Arg.NONE:
            report.add("bad-argument", cmd.value.span, f"{spec.expects()}")
            return
        if raw and isinstance(cmd.value, ast.Name):
            report.add("bad-argument", cmd.value.span,
                       f"{spec.expects()}, found '{cmd.value.name}' (a raw block takes numbers only)")
            return
        arg = _resolve(cmd.value, env, report)
        if arg is None:
            return
        if not spec.in_range(arg):
            report.add("argument-range", cmd.value.span,
                       f"{spec.mnemonic}{arg} is out of range: {spec.expects()} "
                       f"({spec.range_text()})")
            return
    elif spec.arg is Arg.REQUIRED:
        report.add("bad-argument", cmd.span, f"{spec.expects()}: the argument is missing")
        return
    elif spec.note_default:
        report.add("default-argument", cmd.span,
                   f"{spec.mnemonic} without an argument: the controller uses {spec.default}")
    _command_rules(spec, cmd, env, report)
    env.ops[cmd] = Op(spec.mnemonic, arg, cmd.span, "raw" if spec.mnemonic == "EM" else "")


def _command_rules(spec, cmd: ast.Command, env: Env, report: Report) -> None:
    if not spec.storable:
        report.add("not-in-macro", cmd.span,
                   f"{spec.mnemonic} cannot be stored in a macro ({spec.section})")
    if not spec.available_on(env.target):
        only = " and ".join(sorted(spec.models))
        report.add("model-unsupported", cmd.span,
                   f"{spec.mnemonic} is not available on the {env.target} ({only} only)")
    if spec.mnemonic == "JN":
        report.add("joystick-in-macro", cmd.span,
                   "JN enables the joystick from a macro: the axis may move if no joystick "
                   "is connected (MS176E §3.6.1 caution)")


# A file may repeat one unknown word thousands of times (issue 7): look each up once.
_nearest = functools.lru_cache(maxsize=1024)(nearest)


def _unknown(cmd: ast.Command, report: Report) -> None:
    """`EMxx` is EM with a placeholder for its argument; `FOO5` is an unknown command."""
    word = cmd.word
    spec = lookup(word[:2])
    # The manual writes arguments as placeholders: EMxx (Example 3), EMn, MDn,xxx (§3.8.5).
    if spec is not None and len(word) > 2 and set(word[2:].lower()) <= {"x", "n"}:
        s = cmd.word_span
        report.add("syntax", Span(s.line, s.column + 2, s.end_line, s.end_column),
                   f"{spec.expects()}, found the placeholder '{word[2:]}'")
        return
    guess = _nearest(word.upper())
    hint = f"; did you mean {guess}?" if guess else ""
    report.add("unknown-command", cmd.word_span, f"unknown command '{word}'{hint}")
