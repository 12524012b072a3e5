"""Raw macros -> high-level .mcm source whose build stores the very same lines.

Each slot is written as richly as the round trip allows: a construct (`every`, `repeat`,
`when` with its hoisted macros folded back, `call`, `goto`) only where compiling the
source gives back the exact line in the exact slot; else a named macro of native
commands; else the raw `[MCnn]` block, with a comment that says why. Every candidate
is checked by compiling the whole source and comparing the slots.
"""
from __future__ import annotations

import functools
from collections import Counter
from typing import NamedTuple

from mercmac import mdtext
from mercmac.commands import Mnemonic
from mercmac.compiler import ast
from mercmac.decompile.lines import (CONDITIONS, Line, condition_run, every_period, model_of,
                                     names, read_lines)
from mercmac.diagnostics import Severity
from mercmac.fmt import printer
from mercmac.fmt.printer import Comment, Commented, RawText, Run
from mercmac.names import printable

RAW, NATIVE, PLAIN, FOLD = 0, 1, 2, 3  # how richly a slot is written
# How deep folded blocks may nest. The compiler lowers a hoisted block that calls on twice
# (once to learn that it does), so each level doubles the work of checking a candidate:
# a chain of conditional slots folded into one another took 17 s at 20 slots, past 300 s
# at 24.
MAX_NEST = 4
# Compiles one decompile may spend per slot. The search needs at most about seven per slot
# (raise, again for callers, fold, unpin by halves); the examples use three or fewer. Past
# the budget, each slot stays as the search left it, which is exact already: a bound on
# the time of any 32-slot program (benchmarks/decompile_speed.py), whatever its shape.
COMPILES_PER_SLOT = 4
_LOOP_STOP = (Mnemonic.RP, Mnemonic.TI)  # what a loop body may not hold (RP, TI: the counter)


class _Writer:
    """Writes the source for one choice of levels (slot -> RAW..FOLD) and pins: a tree of
    mercmac.compiler.ast, printed by mercmac.fmt.printer. Nodes built here have no span."""

    def __init__(self, lines: dict[int, Line], names: dict[int, str], model: str | None):
        self.lines, self.names, self.model = lines, names, model
        self.levels = {s: RAW for s in lines}
        self.pinned = {s: True for s in lines}
        self.why: dict[int, str] = {}
        self.fold_ok: set[int] = set(lines)  # helpers that may fold into their caller
        self.too_deep: set[int] = set()  # helpers left unfolded to bound the nesting
        self.counts = Counter(t for line in lines.values() for t in line.ems())

    # -- which slots fold into their caller -----------------------------------------------------
    def folds(self) -> dict[int, int]:
        """helper slot -> caller slot, nested at most MAX_NEST deep: past that, the
        shallowest helpers too deep stay macros of their own, and the rest is folded again."""
        self.too_deep = set()
        while True:
            out = self._folds()
            depth = _depths(out)
            deep = {h for h, d in depth.items() if d > MAX_NEST}
            if not deep:
                return out
            self.too_deep |= {h for h in deep if depth[h] == min(depth[d] for d in deep)}

    def _folds(self) -> dict[int, int]:
        """helper slot -> caller slot, for hoisted `when` and loop macros (and the rest
        after a loop that calls out) written back in their caller."""
        out: dict[int, int] = {}
        self.loops: dict[int, tuple] = {}
        for line in self.lines.values():
            if self.levels[line.slot] != FOLD:
                continue
            ops = line.ops
            for i, op in enumerate(ops):
                if op.mnemonic != Mnemonic.EM or not self._helper(op.arg, line.slot):
                    continue
                helper = self.lines[op.arg].ops
                loop = self._loop(op.arg)
                run = condition_run(helper)
                if 0 < len(run) < len(helper):
                    rest = helper[-1].arg if helper[-1].mnemonic == Mnemonic.EM else None
                    if self._rest(rest, ops, i, line.slot, op.arg) and len(run) < len(helper) - 1:
                        # a `when` that calls out, and the rest of the line after it
                        out[op.arg] = out[rest] = line.slot
                        self.loops[op.arg] = (_when(run, ()), helper[len(run):-1], rest, False)
                    elif i < len(ops) - 1:  # a tail `when` would stand in its caller's line
                        out[op.arg] = line.slot
                elif loop and i and not _stops(ops[:i]) and every_period(ops) is None:
                    rest = loop[2]
                    if rest is None:  # a loop that calls nothing: the line goes on after it
                        out[op.arg], self.loops[op.arg] = line.slot, loop
                    elif self._rest(rest, ops, i, line.slot, op.arg):
                        out[op.arg], self.loops[op.arg] = line.slot, loop
                        out[rest] = line.slot
        return out

    def _rest(self, rest: int | None, ops, i: int, caller: int, helper: int) -> bool:
        """Whether `rest` is the macro that both a hoisted block and its caller end in."""
        return (rest is not None and i == len(ops) - 2 and ops[-1].mnemonic == Mnemonic.EM
                and ops[-1].arg == rest  # (`MR3` after the call is no call of MC03)
                and self.counts[rest] == 2 and rest not in (0, caller, helper)
                and self.lines.get(rest) is not None and self.lines[rest].ops is not None
                and self.levels[rest] != RAW)

    def _helper(self, slot: int, caller: int) -> bool:
        line = self.lines.get(slot)
        return (line is not None and line.ops is not None and slot not in (0, caller)
                and self.counts[slot] == 1 and self.levels[slot] != RAW
                and slot in self.fold_ok and slot not in self.too_deep)

    def _loop(self, slot: int) -> tuple | None:
        """(block without its body, body ops, rest slot, True) of a hoisted `repeat N`/`every T`
        line, else None."""
        ops = list(self.lines[slot].ops)
        rest = None
        if ops and ops[-1].mnemonic == Mnemonic.EM:
            rest, ops = ops[-1].arg, ops[:-1]
        period = every_period(ops)
        if period is not None:
            head, body = ast.Every(_number(period), (), None), ops[:-3]
        elif ops and ops[-1].mnemonic == Mnemonic.RP and ops[-1].arg:
            head, body = ast.Repeat(_number(ops[-1].arg + 1), (), None), ops[:-1]
        else:
            return None
        if not body or _stops(body) or any(o.mnemonic in CONDITIONS for o in body):
            return None
        return head, body, rest, True

    # -- the text -----------------------------------------------------------------------------------
    def text(self) -> str:
        return printer.module(self.items())

    def items(self) -> list:
        """The file's items: a header comment, `target`, then each slot not folded away."""
        self.folded = self.folds()
        out: list = [Comment("// Decompiled by mercmac: each macro names the slot it came from.")]
        if self.model:
            out.append(ast.Target(self.model, None))
        out += [self.item(line) for slot, line in sorted(self.lines.items())
                if slot not in self.folded]
        return out

    def item(self, line: Line):
        """A slot as a raw block, or as a macro (or autostart) commented with its slot."""
        level, slot = self.levels[line.slot], line.slot
        if level == RAW:
            why = self.why.get(slot)
            node = RawText(slot, line.text) if line.ops is None else ast.RawBlock(
                slot, tuple(map(_command, line.ops)), None)
            return Commented(node, f"// kept raw: {why}") if why else node
        body = tuple(self.native(line.ops) if level == NATIVE else self.whole(line))
        node = ast.Autostart(body, None) if slot == 0 else ast.MacroDef(
            self.names[slot], _number(slot) if self.pinned[slot] else None, body, None)
        return Commented(node, _tag(slot))

    def whole(self, line: Line) -> list:
        """A line at its start: a loop that starts it, then what follows."""
        ops = list(line.ops)
        for i, op in enumerate(ops):
            if op.mnemonic == Mnemonic.RP:
                period = every_period(ops[:i + 2])
                if period is not None and i > 1 and not _stops(ops[:i - 1]):
                    body = tuple(self.seq(ops[:i - 1], loop=True))
                    return [ast.Every(_number(period), body, None),
                            *self.seq(ops[i + 2:], loop=False)]
                if op.arg and i and not _stops(ops[:i]) and not condition_run(ops[:i]):
                    body = tuple(self.seq(ops[:i], loop=True))
                    return [ast.Repeat(_number(op.arg + 1), body, None),
                            *self.seq(ops[i + 1:], loop=False)]
                break
        return self.seq(ops, loop=False)

    def seq(self, ops: list, loop: bool, hoisted: bool = False) -> list:
        """Statements for ops; `hoisted`: in a block that its own macro holds, where a tail
        `call` would make the compiler continue the caller in another macro: a `goto`."""
        out: list = []
        for i, op in enumerate(ops):
            last = i == len(ops) - 1
            run = condition_run(ops[i:])
            if run and not loop and len(run) < len(ops) - i:
                body = self.seq(ops[i + len(run):], loop=False, hoisted=hoisted)
                return out + [_when(run, body)]
            before = _em_to(ops[i - 1]) if i else None
            if (before in self.loops and before in self.folded and op.mnemonic == Mnemonic.EM
                    and self.loops[before][2] == op.arg):
                continue  # the rest after a folded loop is written after it (its EM)
            if op.mnemonic == Mnemonic.EM:
                out += self.em(op.arg, last and not loop, hoisted)
            else:
                out.append(_command(op))
        return out

    def em(self, slot: int, tail: bool, hoisted: bool = False) -> list:
        if slot in self.loops and slot in self.folded:
            head, body, rest, loop = self.loops[slot]
            block = head._replace(body=tuple(self.seq(list(body), loop=loop)))
            block = Commented(block, _tag(slot))
            if rest is None:
                return [block]
            return [block, Comment(f"{_tag(rest)}:"), *self.whole(self.lines[rest])]
        if slot in self.folded:
            helper = self.lines[slot].ops
            run = condition_run(helper)
            body = self.seq(list(helper[len(run):]), loop=False, hoisted=True)
            return [Commented(_when(run, body), _tag(slot))]
        line = self.lines.get(slot)
        if line is None or self.levels.get(slot, RAW) == RAW or slot == 0:
            return [_em(slot)]
        calls_on = bool(line.ems())
        if tail:
            goto = hoisted or calls_on or _never_returns(line)
            return [(ast.Goto if goto else ast.Call)(self.names[slot], None)]
        return [_em(slot)] if calls_on else [ast.Call(self.names[slot], None)]

    def native(self, ops) -> list:
        return [Run(tuple(map(_command, ops)))]


def _depths(folded: dict[int, int]) -> dict[int, int]:
    """helper -> how many folded blocks it stands in (1: in a macro of its own); a cycle
    of folds counts as deeper than any bound."""
    out: dict[int, int] = {}
    for helper in folded:
        depth, at = 1, folded[helper]
        while at in folded and depth <= MAX_NEST:
            depth, at = depth + 1, folded[at]
        out[helper] = depth
    return out


def _em_to(op) -> int | None:
    return op.arg if op.mnemonic == Mnemonic.EM else None


def _never_returns(line: Line) -> bool:
    return every_period(line.ops) is not None


def _stops(ops) -> bool:
    return any(op.mnemonic in _LOOP_STOP for op in ops)


# A candidate is a tree of a few hundred nodes, most of them the last candidate's: each
# number and command is made once (benchmarks/decompile_speed.py).
@functools.lru_cache(maxsize=4096)
def _number(n: int) -> ast.Number:
    return ast.Number(n, None)


def _command(op) -> ast.Command:
    return _native(op.mnemonic, op.arg)


@functools.lru_cache(maxsize=4096)
def _native(mnemonic: str, arg: int | None) -> ast.Command:
    return ast.Command(mnemonic, None if arg is None else _number(arg), None, None)


def _em(slot: int) -> ast.Command:
    return _native(Mnemonic.EM, slot)


def _when(run, body) -> ast.When:
    """`when 1 and not 2 { body }` for a run of XN1,XF2."""
    return ast.When(_conditions(tuple(run)), tuple(body), None)


@functools.lru_cache(maxsize=1024)
def _conditions(run: tuple) -> tuple[ast.Condition, ...]:
    return tuple(ast.Condition(_number(op.arg), op.mnemonic == Mnemonic.XF, None) for op in run)


def _tag(slot: int) -> str:
    """The comment that names the slot a block came from: `// MC05`."""
    return f"// {mdtext.slot_name(slot)}"


# -- checking a candidate ---------------------------------------------------------------------------

class _Result(NamedTuple):
    exact: bool  # the text builds to exactly the wanted lines, in their slots
    noise: Counter  # its errors and warnings, by rule


class _Search:
    """The candidates the writer's choices make, each compiled once and compared with the
    lines wanted; `best` is the last exact one that warns no more than the raw form.

    Compiling is parsing, mostly: the language server's Rechecker parses each top-level
    block once per distinct text, so a candidate that changes one slot re-parses one block.
    """

    def __init__(self, writer: _Writer, want: dict[int, str]):
        from mercmac.lsp.recheck import Rechecker

        self.writer, self.want = writer, want
        self.rechecker = Rechecker("decompiled.mcm", writer.model)
        self.budget = COMPILES_PER_SLOT * len(want) + 8
        self.seen: dict[str, _Result] = {}
        self.normals: dict[str, str] = {}
        self.best = self.result()

    def result(self) -> _Result:
        """Does the writer's text store `want`, and what errors and warnings does it give?"""
        text = self.writer.text()
        if text in self.seen:
            return self.seen[text]
        if self.budget <= 0:
            return _Result(False, Counter())  # not tried: as good as refused
        self.budget -= 1
        comp = self.rechecker.check(text).compilation
        noise = Counter(d.rule.name for d in comp.report.items
                        if d.severity in (Severity.ERROR, Severity.WARNING))
        got = {} if comp.program is None else {
            m.slot: self.normal(m.line) for m in comp.program.macros.values()}
        self.seen[text] = _Result(got == self.want, noise)
        return self.seen[text]

    def normal(self, line: str) -> str:
        """mdtext.normal, once per line: most lines come back unchanged in every candidate."""
        if line not in self.normals:
            self.normals[line] = mdtext.normal(line)
        return self.normals[line]

    def better(self) -> bool:
        """Whether the writer's choice is exact and warns no more; it is the best then."""
        result = self.result()
        if result.exact and all(result.noise[k] <= self.best.noise[k] for k in result.noise):
            self.best = result
            return True
        return False


def decompile(macros: dict[int, str], *, model: str | None = None, origin: str = "") -> str:
    """.mcm source whose `build` stores `macros` in the same slots (normalised lines)."""
    lines = read_lines(macros)
    writer = _Writer(lines, names(lines), model_of(lines, model))
    for s, line in lines.items():
        if line.ops is None:
            writer.why[s] = ("an empty line" if not line.text
                             else "the line does not read as commands")
    stand_in = {s: line for s, line in lines.items()}
    # Lines with errors stay raw and out of the check: a stand-in keeps their slot taken.
    for s, line in lines.items():
        if line.ops is None:
            stand_in[s] = Line(s, "WA0", (mdtext.parse_line("WA0").ops))
    checker = _Writer(stand_in, writer.names, writer.model)
    search = _Search(checker, {s: line.text for s, line in stand_in.items()})
    if not search.best.exact:  # the raw form itself does not build back (cannot happen for valid lines)
        return _finish(writer, origin)
    valid = [s for s in sorted(lines) if lines[s].ops is not None]
    checker.levels.update(dict.fromkeys(valid, FOLD))
    if not search.better():  # everything folded where it can be
        checker.fold_ok = set()
        if not search.better():  # every slot named, nothing folded
            checker.levels.update(dict.fromkeys(valid, RAW))
            _raise(search, valid)
        _fold(search)
    for s in valid:
        if checker.levels[s] == RAW:
            writer.why[s] = "a named form of it builds another line or adds a warning"
    _unpin(search)
    writer.levels.update({s: checker.levels[s] for s in valid})
    writer.pinned, writer.fold_ok = checker.pinned, checker.fold_ok
    return _finish(writer, origin)


def _raise(search: _Search, valid: list[int]) -> None:
    """Write each slot as richly as the round trip allows, one slot at a time; then once
    more the slots that call a slot named after they were tried (a call by name may do)."""
    levels = search.writer.levels
    for s in valid:
        _raise_slot(search, s)
    for s in valid:
        if any(c > s and levels.get(c, RAW) != RAW for c in search.writer.lines[s].ems()):
            _raise_slot(search, s)


def _raise_slot(search: _Search, s: int) -> None:
    levels = search.writer.levels
    for level in (FOLD, PLAIN, NATIVE):
        if level <= levels[s]:
            return
        old, levels[s] = levels[s], level
        if search.better():
            return
        levels[s] = old


def _fold(search: _Search) -> None:
    """Fold hoisted `when` macros into their callers one by one, where the slots allow."""
    checker = search.writer
    for s in sorted(checker.lines):
        if checker.levels[s] == RAW or not s:
            continue
        checker.fold_ok.add(s)
        if not search.better():
            checker.fold_ok.discard(s)


def _unpin(search: _Search, group: list[int] | None = None) -> None:
    """Drop the pins that the slot allocation makes needless: all at once, else by halves."""
    checker = search.writer
    if group is None:
        group = [s for s in sorted(checker.lines, reverse=True) if s and checker.levels[s] != RAW]
    checker.pinned.update(dict.fromkeys(group, False))
    if search.better():
        return
    checker.pinned.update(dict.fromkeys(group, True))
    if len(group) > 1:
        _unpin(search, group[:len(group) // 2])
        _unpin(search, group[len(group) // 2:])


def _finish(writer: _Writer, origin: str) -> str:
    from mercmac.fmt import format_text

    items = writer.items()
    if origin:  # escaped: a name with a line end must not end the comment
        items.insert(0, Comment(f"// Read from {printable(origin)}."))
    text = printer.module(items)
    try:  # the printer's layout is fmt's; fmt reads a `//` in a raw block's line as a comment
        return format_text(text)
    except Exception:  # a raw block that does not parse keeps the text as written
        return text
