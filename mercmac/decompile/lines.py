"""A stored program read back: its lines as ops, who calls whom, and names for its macros."""
from __future__ import annotations

from typing import NamedTuple

from mercmac import mdtext
from mercmac.commands import C663, C863, MODELS, Kind, Mnemonic, lookup
from mercmac.source import split_lines

CONDITIONS = (Mnemonic.XN, Mnemonic.XF)
# Each executed command takes one controller cycle, 1 ms by default (docs/simulator.md, "Time").
CYCLE_MS = 1
# Commands that take one cycle and go on; a wait for the motor or an input, a condition that
# may leave, a call and macro management take what the machine makes of them.
_ONE_CYCLE = (Kind.MOTION, Kind.OUTPUT, Kind.SETTING, Kind.REPORT, Kind.REPEAT)


class Line(NamedTuple):
    """One slot as stored: its normal text and, when it reads as commands, its ops."""

    slot: int
    text: str
    ops: tuple | None  # None: the line has errors and stays a raw block

    def ems(self) -> list[int]:
        return [op.arg for op in self.ops or () if op.mnemonic == Mnemonic.EM]


def read_macros(text: str) -> dict[int, str]:
    """The macros of a `[MCnn]` file, `MDn,...` lines or a `TM` report, by slot (last wins)."""
    macros: dict[int, str] = {}
    for raw in split_lines(text):
        found = mdtext.listed(raw.split("//", 1)[0].lstrip())
        if found is not None and found.slot is not None:
            macros[found.slot] = found.body.strip()
    return macros


def read_lines(macros: dict[int, str]) -> dict[int, Line]:
    lines = {}
    for slot, text in sorted(macros.items()):
        norm = mdtext.normal(text)
        parsed = mdtext.parse_line(norm, slot=slot)
        lines[slot] = Line(slot, norm, None if parsed.errors or not norm else tuple(parsed.ops))
    return lines


def model_of(lines: dict[int, Line], model: str | None) -> str | None:
    """The model a `VE` named, else the one model that has every command used."""
    if model:
        found = [m for m in MODELS if m.replace("-", "") in model.upper().replace("-", "")]
        if found:
            return found[0]
    fits = set(MODELS)
    for line in lines.values():
        for op in line.ops or ():
            fits &= lookup(op.mnemonic).models
    return next(iter(fits)) if len(fits) == 1 else None


def callers(lines: dict[int, Line]) -> dict[int, list[int]]:
    """slot -> the slots whose lines EM to it (one entry per EM)."""
    out: dict[int, list[int]] = {}
    for line in lines.values():
        for target in line.ems():
            out.setdefault(target, []).append(line.slot)
    return out


def condition_run(ops) -> list:
    """The XN/XF commands a line starts with."""
    run = []
    for op in ops or ():
        if op.mnemonic not in CONDITIONS:
            break
        run.append(op)
    return run


def every_period(ops) -> int | None:
    """T when the line is `...,WA T,RP,RP` (an `every T` loop), else None."""
    ops = ops or ()
    if len(ops) >= 3 and [(o.mnemonic, o.arg) for o in ops[-2:]] == [(Mnemonic.RP, None)] * 2 \
            and ops[-3].mnemonic == Mnemonic.WA:
        return ops[-3].arg
    return None


class Runs(NamedTuple):
    """How often a line with RPs runs, and for how long (docs/simulator.md, "Repeat counters")."""

    times: int  # how often the line's start runs
    ms: int | None  # the whole line, first command to last, when every command's time is known
    exact: bool  # False: a condition, or a call that does not come back, may end it sooner


def runs(line: Line, lines: dict[int, Line]) -> Runs | None:
    """None for a line without RP. `RP n` runs what stands before it n+1 times (a bare RP:
    65,536); a later RP runs the whole line again, where the earlier RP's forgotten counter
    starts over, so the counts multiply: `WA20,RP,RP` runs 65,536 x 65,536 times. Each
    command counts as often as the RPs after it make the line pass it."""
    ops = line.ops or ()
    if not any(op.mnemonic == Mnemonic.RP for op in ops):
        return None
    times, ms = 1, 0
    for op in reversed(ops):
        if op.mnemonic == Mnemonic.RP:
            times *= _repeat_count(op)
        took = _command_ms(op)
        ms = None if ms is None or took is None else ms + took * times
    ends = any(op.mnemonic in CONDITIONS or (op.mnemonic == Mnemonic.EM
                                              and not _comes_back(op.arg, line.slot, lines))
               for op in ops)
    return Runs(times, ms, not ends)


def idle_pass_ms(line: Line, lines: dict[int, Line]) -> int | None:
    """How long one pass of a loop line takes while no input is on: its commands up to the
    first RP (which jumps back), a call costing its EM and the condition the called macro
    starts with, which is false and ends it (MS176E §6.4 XN). None when a command's time is
    the machine's to decide. A `when` in the loop samples its input once a pass: a press
    shorter than this may be missed (docs/simulator.md, "Conditions")."""
    ms = 0
    for op in line.ops or ():
        if op.mnemonic == Mnemonic.EM:
            callee = lines.get(op.arg)
            starts = callee is not None and callee.ops and callee.ops[0].mnemonic == Mnemonic.XN
            if not starts:  # (a false XN ends it: what it would call never runs)
                return None
            ms += 2 * CYCLE_MS
        else:
            took = _command_ms(op)
            if took is None:
                return None
            ms += took
        if op.mnemonic == Mnemonic.RP:
            return ms
    return None


def _repeat_count(op) -> int:
    """How often an `RP n` lets the line pass it: n + 1 (a bare RP is RP65535;
    docs/simulator.md, "Repeat counters")."""
    return (lookup(Mnemonic.RP).default if op.arg is None else op.arg) + 1


def _command_ms(op) -> int | None:
    """How long one command takes, or None when the machine decides (a wait, a call)."""
    if op.mnemonic == Mnemonic.WA:  # §6.4 WA: n ms from its start, at least its cycle
        return max(op.arg, CYCLE_MS)
    if op.mnemonic == Mnemonic.JT:
        from mercmac.vm.machine import JT_US  # §6.4 JT: "takes about 2 seconds"

        return JT_US // 1000
    return CYCLE_MS if lookup(op.mnemonic).kind in _ONE_CYCLE else None


def _comes_back(target: int, caller: int, lines: dict[int, Line]) -> bool:
    """Whether `EM target` returns to the caller's line: the target calls no macro, which
    would take the one return point (MS176E §3.8.4), and does not enter the caller anew."""
    line = lines.get(target)
    return target != caller and (line is None or not any(
        lookup(op.mnemonic).kind in (Kind.CALL, Kind.MACRO) for op in line.ops or ()))


def button_words(ops) -> str:
    """'1', '2_and_3', 'not_2': the inputs of a condition run, for a name."""
    return "_and_".join(("not_" if op.mnemonic == Mnemonic.XF else "") + str(op.arg) for op in ops)


def names(lines: dict[int, Line], given: dict[int, str] | None = None) -> dict[int, str]:
    """A stable, unique name for each slot: the `given` one (the source's), else one made
    from what its line does, unlike any given one."""
    calls = callers(lines)
    modes: dict[int, str] = {}
    for line in lines.values():  # a loop entered by a tail EM of a conditioned line: a mode
        run = condition_run(line.ops)
        if run and line.ops and line.ops[-1].mnemonic == Mnemonic.EM:
            modes.setdefault(line.ops[-1].arg, button_words(run))
    out = {s: name for s, name in (given or {}).items() if s in lines}
    used = set(out.values())
    # What a loop answers is named after the loop: the loops are named first.
    answers = {s for s, line in lines.items() if condition_run(line.ops)
               and len(calls.get(s, ())) == 1 and every_period(lines[calls[s][0]].ops) is not None}
    for slot, line in sorted(lines.items(), key=lambda item: (item[0] in answers, item[0])):
        if slot in out:
            continue
        if slot in answers:
            base = f"{out[calls[slot][0]]}_button_{button_words(condition_run(line.ops))}"
        else:
            base = "autostart" if slot == 0 else _name(line, modes.get(slot),
                                                       0 in calls.get(slot, ()))
        name, n = base, 2
        while name in used:
            name, n = f"{base}_{n}", n + 1
        used.add(name)
        out[slot] = name
    return dict(sorted(out.items()))


def _name(line: Line, mode: str | None, from_autostart: bool) -> str:
    ops = line.ops or ()
    run = condition_run(ops)
    if run:
        words = button_words(run)
        return f"on_button_{words}" if all(o.arg <= 4 for o in run) else f"on_input_{words}"
    period = every_period(ops)
    if period is not None:
        return f"mode_{mode}" if mode else f"poll_{period}ms"
    mnemonics = {op.mnemonic for op in ops}
    if ops and all(lookup(m).kind.value in ("setting", "motion", "wait") for m in mnemonics) \
            and mnemonics & {Mnemonic.SV, Mnemonic.SA, Mnemonic.FE, Mnemonic.DP, Mnemonic.BF}:
        return "init" if from_autostart else "settings"
    if ops and all(lookup(m).kind.value in ("output", "wait") for m in mnemonics):
        return "pulse" if mnemonics & {Mnemonic.CN, Mnemonic.CF} else "leds"
    if Mnemonic.RP in mnemonics:
        return "loop"
    if ops and mnemonics == {Mnemonic.EM}:
        return "dispatch"
    if mnemonics & {Mnemonic.MA, Mnemonic.MR, Mnemonic.GH}:
        return "move"
    return mdtext.slot_name(line.slot).lower()


__all__ = ["C663", "C863", "Line", "Runs", "read_macros", "read_lines", "model_of", "names", "runs"]
