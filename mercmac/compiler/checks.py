"""Checks on the syntax tree: commands, arguments, names and slots (docs/checks.md).

The pass also resolves what lowering needs: each valid native command as an
`Op`, each `const`, each named macro. Checks only report and carry on.
"""
from __future__ import annotations

import functools

from mercmac import mdtext
from mercmac.commands import MODELS, Arg, lookup
from mercmac.compiler import ast
from mercmac.compiler.parse import BROKEN, keyword_candidates
from mercmac.compiler.program import MAX_RP, MAX_WA, MAX_WAITS, SLOTS, rp_counts
from mercmac.compiler.sampling import check_loops
from mercmac.ops import Op
from mercmac.diagnostics import DISPLAY_ONLY, SAFE, UNSAFE, Applicability, Fix, Report
from mercmac.source import Span
from mercmac.suggest import candidates, question

MAX_REPEAT = MAX_RP + 1  # `repeat N` lowers to RP N-1; MS176E §6.4 RP: n <= 32568
MAX_PERIOD_MS = MAX_WA * MAX_WAITS  # `every T` lowers to WA T, several WAs past 65535 ms
INPUTS = range(1, 7)  # XN/XF: 1-4 inputs, 5 joystick, 6 joystick button (§6.4 XN)


class Env:
    """What the checks resolved, for lowering."""

    def __init__(self, target: str | None = None, unsure: frozenset[str] = frozenset()):
        self.target = target
        # names a broken line may define: not reported as undefined
        self.unsure = unsure
        self.consts: dict[str, int] = {}
        self.macros: dict[str, ast.MacroDef] = {}
        self.ops: dict[ast.Command, Op] = {}
        self.values: dict[ast.Value, int] = {}
        # `repeat`/`every` blocks that hold a `when`: timed once the file is checked (slow-poll)
        self.polls: list[ast.Repeat | ast.Every] = []


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
            _claim_slot(item.slot, item.span, mdtext.slot_name(item.slot), slots, report)
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
    if env.polls:
        check_loops(env.polls, env, report)
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


def _block(body: tuple, env: Env, report: Report) -> bool:
    """Check a block; whether a `when` stands in it outside the loops it holds."""
    reads = False
    for i, stmt in enumerate(body):
        if isinstance(stmt, ast.Command):
            _command(stmt, env, report, raw=False)
        elif isinstance(stmt, (ast.Call, ast.Goto)):
            _macro_name(stmt, env, report)
            if isinstance(stmt, ast.Goto) and i != len(body) - 1:
                report.add("goto-not-last", stmt.span)
        elif isinstance(stmt, ast.When):
            for c in stmt.conditions:
                _bounded(c.value, env, report, INPUTS, "when")
            _block(stmt.body, env, report)
            reads = True
        elif isinstance(stmt, ast.Repeat):
            _repeat_count(stmt, env, report)
            _loop_goto(stmt, "repeat", report)
            if _block(stmt.body, env, report):
                env.polls.append(stmt)
        elif isinstance(stmt, ast.Every):
            if _bounded(stmt.period, env, report, range(0, MAX_PERIOD_MS + 1), "every",
                        max=MAX_PERIOD_MS, wa=MAX_WA) == 0:
                report.add("every-zero", stmt.span)
            _loop_goto(stmt, "every", report)
            if _block(stmt.body, env, report):
                env.polls.append(stmt)
    return reads


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


def _macro_name(stmt: ast.Call | ast.Goto, env: Env, report: Report) -> None:
    name = stmt.name
    if name not in env.macros and name not in env.unsure:
        meant, sure = _nearest(name, env.macros)
        report.add("undefined-name", stmt.span, "macro", name=name, hint=_did_you_mean(meant),
                   fix=_fix(name_span(stmt), meant, sure))


def name_span(stmt: ast.Call | ast.Goto) -> Span:
    """Where the macro name of a `call` or `goto` stands: it ends the statement."""
    end = stmt.span.end_column
    return Span(stmt.span.end_line, end - len(stmt.name), stmt.span.end_line, end)


def _nearest(name: str, known) -> tuple[str | None, Applicability]:
    """The defined name nearest to `name` (mercmac.suggest: at most a third of the name in
    edits), else the first with the same first three letters; None when none is near. SAFE
    when it is the only name of its kind that near (by its first letters: of two or more),
    else UNSAFE: one of several is a guess."""
    near = candidates(name, known, limit=len(name) // 3)
    if not near:
        low = name.lower()
        near = sorted(k for k in known if k.lower().startswith(low[:3]))
        if len(low) < 2:  # one letter begins too many names to be sure of any
            return (near[0] if near else None), UNSAFE
    return (near[0], SAFE if len(near) == 1 else UNSAFE) if near else (None, UNSAFE)


def _did_you_mean(meant: str | None) -> str:
    """What a message ends with for a word `meant` instead of the one written."""
    return f"; {question(meant)}" if meant else ""


def _fix(span: Span, meant: str | None, sure: Applicability) -> Fix | None:
    """The word at `span` replaced by the one `meant`, as sure as `sure`."""
    return Fix.replacing(span, meant, sure) if meant else None


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
            meant, sure = _nearest(value.name, env.consts)
            report.add("undefined-name", value.span, "const", name=value.name,
                       hint=_did_you_mean(meant), fix=_fix(value.name_span, meant, sure))
        return None
    number = env.consts[value.name]
    if value.sign == "-" and number is not None:  # `MR -FAR`: range-checked as -5000 would be
        number = -number
    env.values[value] = number
    return number


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
        values, where, fix = dict(f.values), _where(cmd, f), None
        if f.rule == "unknown-command":
            values["hint"], meant, sure = _unknown_hint(
                cmd.word, _argument(cmd.value), type(cmd.value), raw, values["hint"],
                values["guess"])
            fix = Fix.replacing(where, meant, sure) if meant else None
        report.add(f.rule, where, f.variant, fix=fix, **values)
    if checked.op is not None:
        env.ops[cmd] = checked.op._replace(span=cmd.span)


# A 1 MB line of unknown commands asks for the same few words 250,000 times (check_large).
@functools.lru_cache(maxsize=1024)
def _unknown_hint(word: str, argument: str | None, kind: type, raw: bool, spelling: str,
                  guess: str | None) -> tuple[str, str | None, Applicability]:
    """What an unknown command's message ends with, the word meant when there is one, and
    how sure that is (docs/checks.md, "Fixes"): the hint of a natural guess (`LED 1`: write
    `CN 1`; compiler/guesses.py; its command only displayed), else a keyword misspelled
    (`cal scan`: safe when no other keyword is as near), else the nearest mnemonic by
    spelling (mdtext's hint `spelling` and its `guess`: another command, so unsafe).
    `kind`: the type of the command's value (NoneType when it has none)."""
    from mercmac.compiler import guesses  # only once a command is unknown: `check` starts quick

    guessed = guesses.hint(word, argument, raw=raw)
    if guessed is not None:
        return f"; {guessed}", guesses.command(word, raw=raw), DISPLAY_ONLY
    near = keyword_candidates(word) if not raw and kind is not type(None) else []
    if near:  # only `call NAME` and `goto NAME` are whole without a block
        meant = near[0] if near[0] in _NAMING and kind is ast.Name else None
        return _did_you_mean(near[0]), meant, SAFE if len(near) == 1 else UNSAFE
    return spelling, guess, UNSAFE


_NAMING = ("call", "goto")  # the keywords a statement `KEYWORD NAME` starts with (docs/language.md)


def _argument(value) -> str | None:
    """The argument as the user wrote it, near enough for a hint: `1`, `FAST`."""
    if isinstance(value, ast.Number):
        return str(value.value)
    return value.name if isinstance(value, ast.Name) else None


def _where(cmd: ast.Command, f: mdtext.Finding) -> Span:
    if f.where == "word":
        s = cmd.word_span
        # the word's own span unless the place meant is inside it: a span per unknown
        # command of a 1 MB line is 250,000 spans (check_large)
        return s if not f.skip else Span(s.line, s.column + f.skip, s.end_line, s.end_column)
    return cmd.value.span if f.where == "value" else cmd.span
