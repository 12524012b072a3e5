"""Checks on the syntax tree: commands, arguments, names and slots (SPEC §2).

The pass also resolves what lowering needs: each valid native command as an
`Op`, each `const`, each named macro. Checks only report and carry on.
"""
from __future__ import annotations

import functools

from mercmac import mdtext
from mercmac.commands import MODELS, Arg, lookup
from mercmac.compiler import ast
from mercmac.compiler.parse import BROKEN, nearest_keyword
from mercmac.compiler.program import MAX_RP, MAX_WA, MAX_WAITS, SLOTS, Op, rp_counts
from mercmac.diagnostics import Report
from mercmac.source import Span
from mercmac.suggest import suggest

MAX_REPEAT = MAX_RP + 1  # `repeat N` lowers to RP N-1; MS176E §6.4 RP: n <= 32568
MAX_PERIOD_MS = MAX_WA * MAX_WAITS  # `every T` lowers to WA T, several WAs past 65535 ms
INPUTS = range(1, 7)  # XN/XF: 1-4 inputs, 5 joystick, 6 joystick button (§6.4 XN)


class Env:
    """What the checks resolved, for lowering."""

    def __init__(self, target: str | None = None, unsure: frozenset[str] = frozenset()):
        self.target = target
        # names a broken line may define (issue 10): not reported as undefined
        self.unsure = unsure
        self.consts: dict[str, int] = {}
        self.macros: dict[str, ast.MacroDef] = {}
        self.ops: dict[ast.Command, Op] = {}
        self.values: dict[ast.Value, int] = {}


def check_module(module: ast.Module, report: Report, target: str | None,
                 unsure: frozenset[str] = frozenset()) -> Env:
    """Report every AST-level problem; return the resolved environment.

    `unsure`: names that lines left out of `module` (syntax errors) may define; their
    uses are not reported as undefined, as the broken line may well define them."""
    env = Env(target=target, unsure=unsure)
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
            report.add("bad-argument", t.span, "model", model=t.model)
    if env.target is None and targets and targets[-1].model in MODELS:
        env.target = targets[-1].model
    first_const: dict[str, Span] = {}
    for item in module.items:
        if isinstance(item, ast.Const):
            if item.name in env.consts:
                report.add("duplicate-name", item.span, kind="const", name=item.name,
                           first=first_const[item.name].line)
            first_const.setdefault(item.name, item.span)
            # an invalid value is reported here once; its uses resolve to None and stay quiet
            env.consts[item.name] = _resolve(item.value, env, report) if isinstance(
                item.value, ast.Invalid) else item.value
        elif isinstance(item, ast.MacroDef) and item.name != BROKEN:
            first = env.macros.get(item.name)
            if first is not None:
                report.add("duplicate-name", item.span, kind="macro", name=item.name,
                           first=first.span.line)
            else:
                env.macros[item.name] = item


def _claim_slot(slot: int, span: Span, what: str, slots: dict[int, Span], report: Report) -> None:
    if slot not in SLOTS:
        shown = slot if slot < ast.TOO_BIG else f"of more than {ast.MAX_DIGITS} digits"
        report.add("slot-range", span, slot=shown)
    elif slot in slots:
        report.add("duplicate-slot", span, what=what, slot=slot, first=slots[slot].line)
    else:
        slots[slot] = span


def _block(body: tuple, env: Env, report: Report) -> None:
    for i, stmt in enumerate(body):
        if isinstance(stmt, ast.Command):
            _command(stmt, env, report, raw=False)
        elif isinstance(stmt, (ast.Call, ast.Goto)):
            _macro_name(stmt.name, stmt.span, env, report)
            if isinstance(stmt, ast.Goto) and i != len(body) - 1:
                report.add("goto-not-last", stmt.span)
        elif isinstance(stmt, ast.When):
            for c in stmt.conditions:
                _bounded(c.value, env, report, INPUTS, "when")
            _block(stmt.body, env, report)
        elif isinstance(stmt, ast.Repeat):
            _repeat_count(stmt, env, report)
            _loop_goto(stmt, "repeat", report)
            _block(stmt.body, env, report)
        elif isinstance(stmt, ast.Every):
            if _bounded(stmt.period, env, report, range(0, MAX_PERIOD_MS + 1), "every",
                        max=MAX_PERIOD_MS, wa=MAX_WA) == 0:
                report.add("every-zero", stmt.span)
            _loop_goto(stmt, "every", report)
            _block(stmt.body, env, report)


def _repeat_count(stmt: ast.Repeat, env: Env, report: Report) -> None:
    """1-32569 lowers to one RP, a product of two such counts to two; 0 runs nothing."""
    number = _resolve(stmt.count, env, report)
    if number == 0:
        report.add("repeat-zero", stmt.span)
    elif number is not None and (number < 0 or rp_counts(number) is None):
        report.add("argument-range", stmt.count.span, "repeat", number=number, max=MAX_REPEAT)


def _loop_goto(stmt, kind: str, report: Report) -> None:
    """A loop whose block always reaches a goto runs once: the goto leaves it on the
    first pass (a goto that ends a loop inside it counts: that loop runs once too)."""
    goto = _first_goto(stmt.body)
    if goto is not None:
        report.add("goto-ends-loop", goto.span, kind=kind, line=stmt.span.line)


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
    if name not in env.macros and name not in env.unsure:
        hint = _suggest(name, env.macros)
        report.add("undefined-name", span, "macro", name=name, hint=hint)


def _suggest(name: str, known) -> str:
    """'did you mean' the defined name nearest to `name` (mercmac.suggest: at most a third
    of the name in edits), else the first with the same first three letters."""
    close = suggest(name, known, limit=len(name) // 3)
    if close is None:
        low = name.lower()
        close = min((k for k in known if k.lower().startswith(low[:3])), default=None)
    return f"; did you mean '{close}'?" if close else ""


def _bounded(value: ast.Value, env: Env, report: Report, allowed: range, what: str,
             **values) -> int | None:
    """Report a `when` input or an `every` period outside `allowed` (message variant `what`);
    the number, or None when it has none."""
    number = _resolve(value, env, report)
    if number is not None and number not in allowed:
        report.add("argument-range", value.span, what, number=number, **values)
    return number


def _resolve(value: ast.Value, env: Env, report: Report) -> int | None:
    if isinstance(value, ast.Invalid):
        report.add(value.rule, value.span, value.variant, **dict(value.values))
        return None
    if isinstance(value, ast.Number):
        env.values[value] = value.value
        return value.value
    if value.name not in env.consts:
        if value.name in env.unsure:
            return None
        if value.name in env.macros:
            report.add("undefined-name", value.span, "const-is-macro", name=value.name)
        else:
            report.add("undefined-name", value.span, "const", name=value.name,
                       hint=_suggest(value.name, env.consts))
        return None
    env.values[value] = env.consts[value.name]
    return env.consts[value.name]


def _command(cmd: ast.Command, env: Env, report: Report, *, raw: bool) -> None:
    """Validate one native command as mdtext validates a stored one; record its Op."""
    value = cmd.value
    spec = lookup(cmd.word)
    if (value is not None and spec is not None and spec.arg is not Arg.NONE
            and not (raw and isinstance(value, ast.Name))):
        value = _resolve(value, env, report)  # a const, or a number too long to use
        if value is None:
            return
    elif isinstance(value, ast.Name):
        value = value.name
    elif value is not None:  # a number, or one too long for any range
        value = value.value if isinstance(value, ast.Number) else mdtext.TooLong(0)
    checked = mdtext.validate(cmd.word, value, model=env.target)
    for f in checked.findings:
        values = dict(f.values)
        if f.rule == "unknown-command":
            values["hint"] = _unknown_hint(cmd, values["hint"], raw)
        report.add(f.rule, _where(cmd, f), f.variant, **values)
    if checked.op is not None:
        env.ops[cmd] = checked.op._replace(span=cmd.span)


def _unknown_hint(cmd: ast.Command, spelling: str, raw: bool) -> str:
    """What an unknown command's message ends with: the hint of a natural guess (`LED 1`:
    write `CN 1`; compiler/guesses.py), else a keyword misspelled (`cal scan`: a keyword,
    not a command), else the nearest mnemonic by spelling (`spelling`, from mdtext)."""
    guessed = _guessed(cmd.word, _argument(cmd.value), raw)
    if guessed is not None:
        return f"; {guessed}"
    keyword = nearest_keyword(cmd.word) if not raw and cmd.value is not None else None
    return f"; did you mean '{keyword}'?" if keyword is not None else spelling


# A 1 MB line of unknown commands asks for the same few words 250,000 times (check_large).
@functools.lru_cache(maxsize=1024)
def _guessed(word: str, argument: str | None, raw: bool) -> str | None:
    from mercmac.compiler import guesses  # only once a command is unknown: `check` starts quick

    return guesses.hint(word, argument, raw=raw)


def _argument(value) -> str | None:
    """The argument as the user wrote it, near enough for a hint: `1`, `FAST`."""
    if isinstance(value, ast.Number):
        return str(value.value)
    return value.name if isinstance(value, ast.Name) else None


def _where(cmd: ast.Command, f: mdtext.Finding) -> Span:
    if f.where == "word":
        s = cmd.word_span
        return Span(s.line, s.column + f.skip, s.end_line, s.end_column)
    return cmd.value.span if f.where == "value" else cmd.span
