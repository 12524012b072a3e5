"""The rig rules (MR004-MR012 in mercmac/diagnostics.py; the file's own, MR001-MR003, are
load.py's), and `check RIG`: the rig file's findings and each program's, each program
checked with its controller's model (docs/rigs.md).

    rig file --load--> Rig --each program: compiler.checking with the rig's model-->
             --the rig rules over the Rig and the lowered programs--> findings per file
"""
from __future__ import annotations

import re
from collections import defaultdict
from typing import Callable, Iterator, NamedTuple

from mercmac import suppress
from mercmac.compiler import Compilation
from mercmac.compiler import checking
from mercmac.compiler.checking import Choice, Findings
from mercmac.diagnostics import Report
from mercmac.ops import Op
from mercmac.commands import Mnemonic
from mercmac.rig.load import RigFile
from mercmac.rig.model import Controller, Line, LineKind, Rig, Wire
from mercmac.source import Source, Span, read_source, split_lines

ADDRESSES = range(16)  # DIP switches 1-4 (MS176E §3.1.3, §3.2)
# A wait for a line to go ON (§6.4 WN): the lines start OFF, so only WN waits for the other
# side to act; a WF on a line no one has raised yet passes at once.
RAISE_WAIT = Mnemonic.WN
READS = (Mnemonic.WN, Mnemonic.WF, Mnemonic.XN, Mnemonic.XF)  # and the conditions: "interaxis communication" (§4.5.1)
_TARGET = re.compile(r"[ \t]*target[ \t]+([A-Za-z0-9-]+)", re.IGNORECASE)


class Checked(NamedTuple):
    """One controller's program as checked: its findings, and the report the rig rules add
    to (diagnostics in the program file)."""

    controller: Controller
    findings: Findings | None  # None: the program could not be read
    report: Report


def check_rig(rig_file: RigFile, choice: Choice,
              read: Callable[[str], Source] = read_source) -> list[Findings]:
    """The findings of the rig file and of each of its programs under `choice` (its
    `target` is set aside: each program is checked with its controller's model);
    `read(path)` reads a program (the language server passes the editor's text)."""
    report = Report(rig_file.source.name)
    report.items += rig_file.report.items
    rig = rig_file.rig
    programs = [_program(c, choice, report, rig_file, read)
                for c in rig.controllers] if rig else []
    if rig is not None:
        _rig_rules(rig, rig_file, programs, report)
    own = Findings(Compilation(rig_file.source, report, None),
                   [d for d in report.items if d.rule.code in choice.rules])
    return [own] + [_with_rig_rules(p, choice) for p in programs if p.findings]


def _program(controller: Controller, choice: Choice, report: Report,
             rig_file: RigFile, read: Callable[[str], Source] = read_source) -> Checked:
    from mercmac.outfile import reason

    try:
        source = read(controller.program)
    except OSError as e:
        report.add("rig-program", rig_file.places.of("controllers", controller.name, "program"),
                   controller=controller.name, why=reason(e))
        return Checked(controller, None, Report(controller.program))
    findings = checking.check(source, Choice(choice.rules, controller.model))
    return Checked(controller, findings, Report(source.name))


def _with_rig_rules(checked: Checked, choice: Choice) -> Findings:
    """The program's findings with the rig rules' own in its file, all under its
    `// mercmac: ignore[...]` comments (read once, so each bad comment is said once)."""
    compilation = checked.findings.compilation
    return Findings(compilation, suppress.kept([*compilation.report.items, *checked.report.items],
                                               choice.rules, compilation.source))


def _rig_rules(rig: Rig, rig_file: RigFile, programs: list[Checked], report: Report) -> None:
    places = rig_file.places
    _addresses(rig, places, report)
    for checked in programs:
        if checked.findings is not None:
            _model(checked, places, report)
    lowered = {p.controller.name: _ops(p) for p in programs}
    if len(rig.controllers) >= 2:
        for checked in programs:
            _select(checked, lowered[checked.controller.name], len(rig.controllers))
    _joystick(rig, places, report)
    _inputs_driven_twice(rig, report)
    _outputs_never_set(rig, lowered, report)
    _inputs_undriven(rig, programs, lowered)
    _wait_cycles(rig, lowered, report)
    _stuck_on_undriven(rig, programs)


# -- addresses and models (§3.2) ----------------------------------------------------------

def _addresses(rig: Rig, places, report: Report) -> None:
    seen: dict[int, str] = {}
    for c in rig.controllers:
        span = places.of("controllers", c.name, "address")
        if c.address not in ADDRESSES:
            report.add("address-range", span, address=c.address)
        elif c.address in seen:
            report.add("address-repeated", span, controller=c.name, address=c.address,
                       other=seen[c.address])
        seen.setdefault(c.address, c.name)


def _model(checked: Checked, places, report: Report) -> None:
    """The program's own `target` line against the rig's model (the check used the rig's)."""
    c, source = checked.controller, checked.findings.compilation.source
    target = _declared_target(source)
    if target is not None and target.upper() != c.model:
        report.add("model-mismatch", places.of("controllers", c.name, "model"),
                   controller=c.name, model=c.model, target=target)


def _declared_target(source: Source) -> str | None:
    """The model the last `target` line of a program names (the one the compiler takes)."""
    found = None
    for line in split_lines(source.text):
        match = _TARGET.match(line)
        found = match.group(1) if match else found
    return found


# -- the lowered programs ---------------------------------------------------------------

class Step(NamedTuple):
    """One command of a program in the order a run meets it first (from macro 0)."""

    op: Op
    macro: str  # as messages name it: 'scan (MC03)', 'the `when` at line 4 (MC05)'


def _ops(checked: Checked) -> list[Step]:
    """The commands of a lowered program from macro 0 on, each macro entered at its first
    EM (then the rest of the caller): a run's order, branches (XN/XF) taken. None for a
    program with errors: nothing with errors is read further
    (docs/architecture.md, "One way down")."""
    compilation = checked.findings.compilation if checked.findings else None
    program = compilation.program if compilation else None
    if program is None or compilation.report.has_errors or 0 not in program.macros:
        return []
    steps: list[Step] = []
    _walk(program, 0, set(), steps)
    return steps


def _walk(program, slot: int, seen: set[int], steps: list[Step]) -> None:
    stack = [(slot, 0)]
    seen.add(slot)
    while stack:  # iterative: a long chain of macros must not recurse
        slot, at = stack.pop()
        macro = program.macros[slot]
        label = macro.written  # a hoisted block as the user wrote it: 'the `when` at line 4'
        for i in range(at, len(macro.ops)):
            op = macro.ops[i]
            steps.append(Step(op, label))
            if op.mnemonic == Mnemonic.EM and op.arg in program.macros and op.arg not in seen:
                seen.add(op.arg)
                stack += [(slot, i + 1), (op.arg, 0)]
                break


def _select(checked: Checked, steps: list[Step], count: int) -> None:
    """SC in macro 0 (§3.1.2): reported in the program, where the SC stands."""
    macro0 = checked.findings.compilation.program.macros[0] if steps else None
    for op in macro0.ops if macro0 else ():
        if op.mnemonic == Mnemonic.SC:
            checked.report.add("select-networked", op.span or Span(1, 1),
                               controller=checked.controller.name, count=count)


# -- the joystick (§3.6) -----------------------------------------------------------------

def _joystick(rig: Rig, places, report: Report) -> None:
    branches = rig.joystick
    if "Y" in branches and not {"X", "Z"} & set(branches):  # a C-819.20 on its Y-cable
        report.add("joystick-branch", places.of("joystick", "Y"), "power",
                   controller=branches["Y"])
    first: dict[str, str] = {}
    for branch, name in branches.items():
        if name in first:
            report.add("joystick-branch", places.of("joystick", branch), "socket",
                       first=first[name], second=branch, controller=name)
        first.setdefault(name, branch)


# -- the wires (§4.5.1) -------------------------------------------------------------------

def _inputs_driven_twice(rig: Rig, report: Report) -> None:
    by_input: dict[tuple[str, int], list[Wire]] = defaultdict(list)
    for wire in rig.wires:
        by_input[wire.target.controller, wire.target.number].append(wire)
    for (name, number), wires in by_input.items():
        for later in wires[1:]:
            report.add("input-driven-twice", later.span, "wire", line=str(later.target),
                       first=str(wires[0].source), second=str(later.source))
        if number in rig.box_inputs(name):
            report.add("input-driven-twice", wires[0].span, "button", line=str(wires[0].target),
                       wire=str(wires[0]), button=number)


def _sets(op: Op, number: int) -> bool:
    """Whether `op` raises output `number`: CN n, a CP pattern with its bit, or a trigger
    mode on output 4 (§4.5.2)."""
    arg = op.arg or 0
    return ((op.mnemonic == Mnemonic.CN and arg == number)
            or (op.mnemonic == Mnemonic.CP and arg >> (number - 1) & 1 == 1)
            or (op.mnemonic == Mnemonic.ZM and number == 4 and arg != 0))


def _outputs_never_set(rig: Rig, lowered: dict[str, list[Step]], report: Report) -> None:
    for wire in rig.wires:
        steps = lowered.get(wire.source.controller)
        if steps and not any(_sets(s.op, wire.source.number) for s in steps):
            report.add("output-never-set", wire.span, wire=str(wire),
                       controller=wire.source.controller, number=wire.source.number)


def _driven(rig: Rig) -> set[tuple[str, int]]:
    """(controller, input) of every input a wire or a connected box button drives."""
    return ({(w.target.controller, w.target.number) for w in rig.wires}
            | {(rig.box, n) for n in rig.box_buttons if rig.box})


def _inputs_undriven(rig: Rig, programs: list[Checked], lowered: dict[str, list[Step]]) -> None:
    driven = _driven(rig)
    for checked in programs:
        name = checked.controller.name
        said: set[int] = set()
        for step in lowered[name]:
            number = step.op.arg
            if step.op.mnemonic in READS and number in range(1, 5) and number not in said \
                    and (name, number) not in driven:
                said.add(number)
                checked.report.add("input-undriven", step.op.span or Span(1, 1),
                                   controller=name, number=number,
                                   command=f"{step.op.mnemonic}{number}")


# -- wait cycles ------------------------------------------------------------------------

class _Node(NamedTuple):
    """An output of a controller, and the wired inputs it waits on before first raising it."""

    output: Line
    waits: tuple[tuple[Line, str], ...]  # (input waited on, in which macro)
    macro: str  # where the output is first raised


def _wait_cycles(rig: Rig, lowered: dict[str, list[Step]], report: Report) -> None:
    """A cycle of outputs, each raised only after a wait on an input driven by the next."""
    nodes = {str(n.output): n for n in _nodes(rig, lowered)}
    driver = {str(w.target): w for w in rig.wires}
    reported: set[frozenset[str]] = set()
    for start in nodes:
        cycle = _cycle(start, nodes, driver)
        if cycle and frozenset(cycle) not in reported:
            reported.add(frozenset(cycle))
            _report_cycle([nodes[k] for k in cycle], driver, report)


def _nodes(rig: Rig, lowered: dict[str, list[Step]]) -> Iterator[_Node]:
    wired = {(w.target.controller, w.target.number) for w in rig.wires}
    for c in rig.controllers:
        waits: list[tuple[Line, str]] = []
        raised: set[int] = set()
        for step in lowered.get(c.name, ()):
            op = step.op
            if op.mnemonic == RAISE_WAIT and (c.name, op.arg) in wired:
                waits.append((Line(c.name, LineKind.IN, op.arg), step.macro))
            for number in range(1, 5):
                if number not in raised and _sets(op, number):
                    raised.add(number)
                    yield _Node(Line(c.name, LineKind.OUT, number), tuple(waits), step.macro)


def _cycle(start: str, nodes: dict[str, _Node], driver: dict[str, Wire]) -> list[str] | None:
    """The outputs of a cycle through `start`, or None: depth first, each output entered
    once (what can reach `start` is found on its first visit), so a rig of many wires costs
    a pass over its waits per output, not one per path."""
    stack, seen = [(start, [start])], {start}
    while stack:
        key, path = stack.pop()
        for line, _ in nodes[key].waits:
            wire = driver.get(str(line))
            following = str(wire.source) if wire else None
            if following == start:
                return path
            if following in nodes and following not in seen:
                seen.add(following)
                stack.append((following, path + [following]))
    return None


def _wait_on(node: _Node, other: _Node, driver: dict[str, Wire]) -> tuple[Line, str]:
    """The wait of `node` on an input that `other`'s output drives."""
    return next(w for w in node.waits if driver[str(w[0])].source == other.output)


def _report_cycle(cycle: list[_Node], driver: dict[str, Wire], report: Report) -> None:
    """Reported at the wire into the first wait of the cycle, naming its first two sides."""
    first, second, third = (cycle[i % len(cycle)] for i in range(3))
    first_wait, second_wait = _wait_on(first, second, driver), _wait_on(second, third, driver)
    report.add("wait-cycle", driver[str(first_wait[0])].span,
               first=f"{first.output.controller}'s {first_wait[1]}", first_line=str(first_wait[0]),
               first_out=str(first.output),
               second=f"{second.output.controller}'s {second_wait[1]}",
               second_line=str(second_wait[0]), second_out=str(second.output))


# -- sure dead-locks on an input nothing drives (docs/rigs.md) ------------------------

class _Stop(NamedTuple):
    """Where a controller's sure path from macro 0 stops: the first WN it surely reaches
    (None: the program ends), and the outputs it may have raised on the way."""

    wait: Step | None
    raised: frozenset[int]


def _stuck_on_undriven(rig: Rig, programs: list[Checked]) -> None:
    """A dead-lock that is sure and waits on an input nothing drives (a cycle alone is
    _wait_cycles'): every controller, followed through the commands that surely run, ends
    or reaches a WN that never ends, on an input no wire and no box button drives (it stays
    OFF on the rig) or on a wire from an output its controller has not raised by then.
    Reported at each wait on an undriven input."""
    stops: dict[str, _Stop] = {}
    for checked in programs:
        stop = _sure_stop(rig, checked)
        if stop is None:
            return  # a controller that may go on may change anything: nothing is sure
        stops[checked.controller.name] = stop
    waiting = {name: stop.wait for name, stop in stops.items() if stop.wait is not None}
    if not waiting or not all(_never_ends(rig, name, step, stops)
                              for name, step in waiting.items()):
        return
    for checked in programs:
        name = checked.controller.name
        step = waiting.get(name)
        if step is not None and not rig.drivers(name, step.op.arg):
            others = "".join(f"; {_stuck_text(rig, other, stops)}"
                             for other in stops if other != name)
            checked.report.add("wait-cycle", step.op.span or Span(1, 1), "undriven",
                               controller=name, macro=step.macro, command=step.op.text,
                               line=str(_input(name, step)), others=others)


class _Place(NamedTuple):
    """Where a machine runs: a macro slot, a command in it, and the one return point."""

    slot: int
    ip: int
    ret: tuple[int, int] | None


def _sure_stop(rig: Rig, checked: Checked) -> _Stop | None:
    """The controller's run from macro 0 as the machine runs it, up to its first WN; None
    where the path is not sure: a condition (XN/XF), an RP that repeats a call or a
    condition, a loop without a wait, a wait a person or a wire may end at once (WF on a
    driven input, WN on a box button), or a program with errors."""
    compilation = checked.findings.compilation if checked.findings else None
    program = compilation.program if compilation else None
    if program is None or compilation.report.has_errors:
        return None
    name, raised, seen = checked.controller.name, set(), set()
    place = _settled(program, _Place(0, 0, None)) if 0 in program.macros else None
    while place is not None:
        if place in seen:
            return None  # round a loop without a wait: it runs on
        seen.add(place)
        macro = program.macros[place.slot]
        op = macro.ops[place.ip]
        if op.mnemonic == Mnemonic.WN:
            by_hand = op.arg in rig.by_hand(name)  # a person may still come: no sure stop
            return None if by_hand else _Stop(Step(op, macro.written), frozenset(raised))
        if not _passes(rig, name, op, macro.ops[:place.ip]):
            return None
        raised |= {n for n in range(1, 5) if _sets(op, n)}
        place = _after(program, place, op)
    return _Stop(None, frozenset(raised))  # the program ends (§3.8.4)


def _passes(rig: Rig, name: str, op: Op, before: list[Op]) -> bool:
    """Whether `op` surely runs on to the command after it (or into the macro it calls)."""
    if op.mnemonic in (Mnemonic.XN, Mnemonic.XF):
        return False  # the rest of the line may not run
    if op.mnemonic == Mnemonic.WF:  # the lines start OFF: one nothing drives stays OFF
        return op.arg not in rig.by_hand(name) and not rig.drivers(name, op.arg)
    return op.mnemonic != Mnemonic.RP or not _repeats_more(before)


def _after(program, place: _Place, op: Op) -> _Place | None:
    """Where the machine goes after `op` at `place`: into the macro an EM calls, its return
    point the command after the EM (the one return point, §3.8.4), or on; None: it ends."""
    if op.mnemonic == Mnemonic.EM and op.arg in program.macros:
        return _settled(program, _Place(op.arg, 0, (place.slot, place.ip + 1)))
    return _settled(program, place._replace(ip=place.ip + 1))


def _settled(program, place: _Place) -> _Place | None:
    """`place`, or where a macro's end leads: its return point, or the program's end."""
    while place.ip >= len(program.macros[place.slot].ops):
        if place.ret is None:
            return None
        place = _Place(*place.ret, None)
    return place


def _repeats_more(before: list[Op]) -> bool:
    """Whether an RP after `before` would repeat more than plain commands (a call or a
    condition): its line's second pass may then go elsewhere."""
    return any(op.mnemonic in (Mnemonic.EM, Mnemonic.XN, Mnemonic.XF) for op in before)


def _never_ends(rig: Rig, name: str, step: Step, stops: dict[str, _Stop]) -> bool:
    """Whether the WN of `step` waits for good while each controller stops where `stops`
    says: its input is driven by nothing, or by outputs not raised before their stop."""
    return all(w.source.number not in stops[w.source.controller].raised
               for w in rig.drivers(name, step.op.arg))


def _input(name: str, step: Step) -> Line:
    return Line(name, LineKind.IN, step.op.arg)


def _stuck_text(rig: Rig, name: str, stops: dict[str, _Stop]) -> str:
    """How another controller of a sure dead-lock stops, for the message."""
    step = stops[name].wait
    if step is None:
        return f"{name} ends"
    wires = rig.drivers(name, step.op.arg)
    said = f"{name} waits for {_input(name, step)} ({step.op.text}) in {step.macro}"
    if not wires:
        return f"{said}, which nothing drives either"
    source = wires[0].source
    before = "it waits too" if stops[source.controller].wait is not None else "it ends"
    return f"{said}, from {source}, which {source.controller} does not raise before {before}"
