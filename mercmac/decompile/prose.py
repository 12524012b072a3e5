"""A stored program in plain words: every macro the way the manual's §3.8.6
describes its examples, grouped as a person reads a program."""
from __future__ import annotations

import json

from mercmac.commands import Mnemonic, lookup, unit
from mercmac.mdtext import slot_name
from mercmac.names import dot, markdown, mermaid, printable
from mercmac.render.sim import plural
from mercmac.timespec import format_span
from mercmac.decompile.lines import (Line, condition_run, every_period, idle_pass_ms, model_of,
                                     names, read_lines, runs)


class Reader:
    """A stored program read for describing: its lines, model, unit and macro names."""

    def __init__(self, macros: dict[int, str], model: str | None,
                 given: dict[int, str] | None = None, inputs: dict[int, str] | None = None,
                 outputs: dict[int, str] | None = None, box: bool = True):
        self.lines = read_lines(macros)
        # I/O lines that a rig wires to another controller, by number: 'input 2 (from
        # y.out2)', 'output 1 (to y.in1)'; the others are the box's buttons and LEDs
        # (MS176E §4.5.1), or, on a controller without the box (`box` false), plain
        # inputs and outputs.
        self.inputs, self.outputs, self.box = inputs or {}, outputs or {}, box
        self.model = model_of(self.lines, model)
        self.unit = unit(self.model)
        self.limits = _soft_limits(self.lines)
        # The source's names, as `sim` and `flash` show them (Macro.label); a raw slot's
        # name is its tag, and it gets a name made from what it does instead.
        self.given = {s: n for s, n in (given or {}).items() if n != slot_name(s)}
        self.names = names(self.lines, self.given)

    # -- words for one line -------------------------------------------------------------------------
    def condition(self, run) -> str:
        """The XN/XF of `run` in words: buttons held or not, wired inputs on or off."""
        buttons = [o for o in run if o.arg not in self.inputs]
        parts = [_condition(buttons, self.box)] if buttons else []
        parts += [f"{self.inputs[o.arg]} is {'on' if o.mnemonic == Mnemonic.XN else 'off'}"
                  for o in run if o.arg in self.inputs]
        return " and ".join(parts)

    def label(self, slot: int) -> str:
        """'jog (MC01)' for a macro the source names, 'MC01 (mode_1)' for a raw one."""
        if slot in self.given and slot in self.lines:
            return f"{self.names[slot]} ({slot_name(slot)})"
        return f"{slot_name(slot)} ({self.names[slot]})" if slot in self.lines else slot_name(slot)

    def words(self, line: Line) -> str:
        if line.ops is None:
            return "cannot be read as commands: " + (line.text or "empty")
        if not line.ops:
            return "does nothing"
        return self.phrase(list(line.ops), line)

    def phrase(self, ops: list, line: Line) -> str:
        """`ops`, a part of `line` that ends with it: its RPs repeat the whole line."""
        run = condition_run(ops)
        if run:
            rest = ops[len(run):]
            return (f"only while {self.condition(run)}: "
                    + (self.phrase(rest, line) if rest else "nothing"))
        period = every_period(ops)
        if period is not None and not _repeats(ops[:-3]):
            body = self.steps(ops[:-3])
            return (f"every {period} ms, {self.times(line)}: "
                    + (_series(body) if body else "wait"))
        steps, mine = [], ops
        for i, op in enumerate(ops):
            run = condition_run(ops[i:])
            if run:
                steps.append(f"only while {self.condition(run)}: "
                             + self.phrase(ops[i + len(run):], line))
                mine = ops[:i]
                break
            steps.append(self.command(op, tail=i == len(ops) - 1))
        if _repeats(mine) and not _repeats(ops[len(mine):]):  # said once, after the last RP
            return f"{_series(steps)}; the line runs {self.times(line)}"
        return _series(steps)

    def times(self, line: Line) -> str:
        """'4,294,967,296 times (about 1,094 d)', as the simulator counts them; 'up to'
        when a condition or a call may end the line sooner."""
        found = runs(line, self.lines)
        said = ("" if found.exact else "up to ") + plural(found.times, "time")
        return said + (f" ({_length(found.ms)})" if found.ms is not None else "")

    def steps(self, ops: list) -> list[str]:
        return [self.command(op, tail=False) for op in ops]

    def command(self, op, tail: bool) -> str:
        m, n, unit = op.mnemonic, op.arg, self.unit
        if m == Mnemonic.EM:
            target = self.lines.get(n)
            if target is None:
                return f"run {slot_name(n)} (not defined: nothing happens)"
            run = condition_run(target.ops)
            when = f" if {self.condition(run)}" if run and len(run) < len(target.ops) else ""
            return ("go to " if tail else "run ") + self.label(n) + when
        if m == Mnemonic.MR:
            return f"move {n:+,} {unit}" + self._limited(n, relative=True)
        if m == Mnemonic.MA:
            return f"move to position {n:,}" + self._limited(n, relative=False)
        if m == Mnemonic.GH:
            return "go home (position 0)"
        if m == Mnemonic.DH:
            return f"make the current position {n or 0}"
        if m == Mnemonic.AB:
            return "stop smoothly" if n == 1 else "stop at once"
        if m == Mnemonic.SV:
            return f"set the velocity to {n:,} {unit}/s"
        if m == Mnemonic.SA:
            return f"set the acceleration to {n:,} {unit}/s²"
        if m == Mnemonic.WA:
            return f"wait {n:,} ms"
        if m == Mnemonic.WS:
            return f"wait until on target and {1000 if n is None else n} ms more"
        if m in (Mnemonic.WF, Mnemonic.WN) and n in self.inputs:
            return f"wait until {self.inputs[n]} is {'off' if m == Mnemonic.WF else 'on'}"
        if m in (Mnemonic.WF, Mnemonic.WN) and not self.box:
            return f"wait until input {n} is {'off' if m == Mnemonic.WF else 'on'}"
        if m in (Mnemonic.WF, Mnemonic.WN):
            return f"wait until button {n} is {'released' if m == Mnemonic.WF else 'pressed'}"
        if m == Mnemonic.CP:
            return _leds(n, self.box)
        if m in (Mnemonic.CN, Mnemonic.CF):
            return f"{self.output(n)} {'on' if m == Mnemonic.CN else 'off'}"
        if m == Mnemonic.RP:
            return f"repeat the line {plural(65535 if n is None else n, 'more time')}"
        if m == Mnemonic.FE:
            return f"search the reference (FE{0 if n is None else n})"
        summary = lookup(m).summary.split(":")[0].split(" (")[0]
        return f"{summary[0].lower()}{summary[1:]} ({op.text})"

    def output(self, n: int) -> str:
        """Output line n in words: its wire, the box's LED, or a plain output."""
        return self.outputs.get(n, f"LED {n}" if self.box else f"output {n}")

    def _limited(self, n: int, relative: bool) -> str:
        """What stops a move the soft limits clamp (MS176E §4.4.2): a jog far past them
        (`MR 9999999` against JH 20000) ends at the limit, wherever it starts."""
        low, high = self.limits
        if relative:
            span = None if low is None or high is None else high - low
            side, limit = ("upper", high) if n > 0 else ("lower", low)
            if limit is None or span is None or abs(n) < span:
                return ""
            return f" (a jog: the {side} soft limit, {limit:,}, stops it)"
        if high is not None and n > high:
            return f" (the upper soft limit stops it at {high:,})"
        if low is not None and n < low:
            return f" (the lower soft limit stops it at {low:,})"
        return ""

    # -- the program ----------------------------------------------------------------------------------
    def reached(self) -> set[int]:
        seen, todo = set(), [0] if 0 in self.lines else []
        while todo:
            s = todo.pop()
            if s in seen or s not in self.lines:
                continue
            seen.add(s)
            todo += self.lines[s].ems()
        return seen

    def startup(self) -> set[int]:
        """The macros macro 0 reaches before any polling loop: what runs once at power-on."""
        seen, todo = set(), [0] if 0 in self.lines else []
        while todo:
            s = todo.pop()
            if s in seen or s not in self.lines or every_period(self.lines[s].ops) is not None:
                continue
            seen.add(s)
            todo += self.lines[s].ems()
        return seen

    def modes(self, ending: bool = False) -> list[dict]:
        """Loops entered by a tail EM of a line that a button selects; with `ending`, the
        other targets of such a goto: macros that stop the program (an abort that ends in
        direct mode is no mode)."""
        out = []
        for line in self.lines.values():
            run = condition_run(line.ops)
            if run and line.ops[-1].mnemonic == Mnemonic.EM:
                target = line.ops[-1].arg
                if target in self.lines and self.goes_on(target) != ending:
                    out.append({"mode": target, "name": self.names[target], "by": line.slot,
                                "condition": self.condition(run),
                                "first": self.phrase(list(line.ops[len(run):-1]), line) or "",
                                "at_power_on": line.slot in self.startup()})
        return out

    def goes_on(self, slot: int, seen: frozenset = frozenset()) -> bool:
        """Whether running `slot` keeps the program running: it loops (RP), or goes on to
        another macro (a tail EM) that does; a macro that ends ends the program (§3.8.4)."""
        ops = self.lines[slot].ops or ()
        if slot in seen or any(op.mnemonic == Mnemonic.RP for op in ops):
            return True
        tail = ops[-1] if ops else None
        if tail is None or tail.mnemonic != Mnemonic.EM or tail.arg not in self.lines:
            return False
        return self.goes_on(tail.arg, seen | {slot})

    def loops(self) -> list[dict]:
        out = []
        for line in self.lines.values():
            period = every_period(line.ops)
            if period is None:
                continue
            answers = []
            for target in line.ems():
                t = self.lines.get(target)
                run = condition_run(t.ops if t else None)
                if t is not None and run:
                    answers.append({"slot": target, "condition": self.condition(run),
                                    "does": self.phrase(list(t.ops[len(run):]), t)})
            out.append({"slot": line.slot, "name": self.names[line.slot], "period_ms": period,
                        "pass_ms": idle_pass_ms(line, self.lines), "answers": answers})
        return out

    def leds(self) -> list[dict]:
        """What each macro does to the LEDs (or outputs): on, off, and a pulse as one (CN n,
        WA t, CF n: on for t ms, then off again)."""
        out = []
        for line in self.lines.values():
            ops, lit, i = line.ops or (), [], 0
            while i < len(ops):
                op = ops[i]
                if _pulse(ops, i):
                    lit.append(f"{self.output(op.arg)} on for {ops[i + 1].arg:,} ms, then off "
                               "again (a pulse)")
                    i += 3
                    continue
                if op.mnemonic in (Mnemonic.CP, Mnemonic.CN, Mnemonic.CF):
                    lit.append(self.command(op, tail=False))
                i += 1
            if lit:
                out.append({"slot": line.slot, "name": self.names[line.slot], "lights": lit})
        return out

    def data(self) -> dict:
        reached = self.reached()
        return {
            "model": self.model, "unit": self.unit,
            "power_on": ({"slot": 0, "does": self.words(self.lines[0])}
                         if 0 in self.lines else None),
            "modes": self.modes(), "ends": self.modes(ending=True), "loops": self.loops(),
            "leds": self.leds(), "box": self.box,
            "unreached": [s for s in self.lines if s not in reached and 0 in self.lines],
            "macros": [{"slot": s, "name": self.names[s], "line": line.text,
                        "does": self.words(line), "calls": line.ems(),
                        "runs": self.runs(line), "reached": s in reached}
                       for s, line in self.lines.items()],
        }

    def runs(self, line: Line) -> dict | None:
        """How often the line runs and for how long (ms), as the simulator counts."""
        found = runs(line, self.lines)
        return None if found is None else {"times": found.times, "duration_ms": found.ms,
                                           "exact": found.exact}


def _repeats(ops) -> bool:
    return any(op.mnemonic == Mnemonic.RP for op in ops)


def _length(ms: int) -> str:
    """'92 ms' when that is exact, else 'about 1,094 d' (three digits, as the timeline)."""
    rounded, exact = format_span(ms * 1000), format_span(ms * 1000, digits=None)
    return exact if len(exact) <= len(rounded) else f"about {rounded}"


def _soft_limits(lines: dict[int, Line]) -> tuple[int | None, int | None]:
    """The lower and upper soft limit the program sets (JL, JH; MS176E §4.4.2), each when
    it sets one value only."""
    found = {Mnemonic.JL: set(), Mnemonic.JH: set()}
    for line in lines.values():
        for op in line.ops or ():
            if op.mnemonic in found and op.arg is not None:
                found[op.mnemonic].add(op.arg)
    low, high = found[Mnemonic.JL], found[Mnemonic.JH]
    return (next(iter(low)) if len(low) == 1 else None,
            next(iter(high)) if len(high) == 1 else None)


def _pulse(ops, i: int) -> bool:
    """Whether ops[i:i+3] is CN n, WA t, CF n: output n on for t ms."""
    return (i + 2 < len(ops) and ops[i].mnemonic == Mnemonic.CN
            and ops[i + 1].mnemonic == Mnemonic.WA and ops[i + 1].arg is not None
            and ops[i + 2].mnemonic == Mnemonic.CF and ops[i + 2].arg == ops[i].arg)


def _condition(run, box: bool = True) -> str:
    """'button 1 is held', or on a controller without the box 'input 1 is on'."""
    on = [str(o.arg) for o in run if o.mnemonic == Mnemonic.XN]
    off = [str(o.arg) for o in run if o.mnemonic == Mnemonic.XF]
    what, held, free = ("button", "held", "not pressed") if box else ("input", "on", "off")
    parts = []
    if on:
        parts.append(f"{what} {on[0]} is {held}" if len(on) == 1
                     else f"{what}s {' and '.join(on)} are {held}")
    if off:
        parts.append(f"{what} {off[0]} is {free}" if len(off) == 1
                     else f"{what}s {' and '.join(off)} are {free}")
    return " and ".join(parts).replace(f"{what} 5", "the joystick input").replace(
        f"{what} 6", "the joystick button")


def _leds(pattern: int, box: bool = True) -> str:
    lit = [str(i + 1) for i in range(4) if pattern >> i & 1]
    one, many = ("LED", "LEDs") if box else ("output", "outputs")
    if not lit:
        return f"all {many} off"
    return (f"{one} {lit[0]}" if len(lit) == 1 else f"{many} {', '.join(lit[:-1])} and {lit[-1]}") \
        + " on, the others off"


def _series(steps: list[str]) -> str:
    """'a, b, then c': the manual's way of saying one command after another."""
    if len(steps) <= 1:
        return "".join(steps)
    return ", ".join(steps[:-1]) + ", then " + steps[-1].removeprefix("then ")


# -- renderings ------------------------------------------------------------------------------------

def describe(macros: dict[int, str], *, model: str | None = None, fmt: str = "text",
             names: dict[int, str] | None = None, level: int = 1,
             inputs: dict[int, str] | None = None, outputs: dict[int, str] | None = None,
             box: bool = True) -> str:
    """The program in words; `names`: the source's macro names by slot (Program.names());
    `level`: the markdown heading level of its title (a rig's programs are sections);
    `inputs`, `outputs`: words for the lines a rig wires, by number (Reader.inputs); `box`:
    whether the controller has the pushbutton box (its inputs are buttons, outputs LEDs)."""
    reader = Reader(macros, model, names, inputs, outputs, box)
    data = reader.data()
    if fmt == "json":
        return json.dumps(data, indent=2, ensure_ascii=False) + "\n"
    if fmt not in ("text", "markdown"):
        raise ValueError(f"unknown format {fmt!r}: text, markdown or json")
    md = fmt == "markdown"
    title, section = "#" * level, "#" * (level + 1)
    out = [f"{title} {markdown(_title(reader, data))}" if md else _title(reader, data)]
    for head, items in _sections(reader, data):
        if not items:
            continue
        out += ["", f"{section} {head}" if md else f"{head}:"]
        out += [_item(depth, text, md) for depth, text in items]
    if md:
        out += ["", f"{section} Call graph", "", "```mermaid", _mermaid(reader), "```"]
    return "\n".join(out) + "\n"


def described(macros: dict[int, str], *, model: str | None = None,
              names: dict[int, str] | None = None, inputs: dict[int, str] | None = None,
              outputs: dict[int, str] | None = None, box: bool = True) -> dict:
    """What `describe --format json` prints, as data (a rig's JSON holds one per program)."""
    return Reader(macros, model, names, inputs, outputs, box).data()


def _item(depth: int, text: str, md: bool) -> str:
    """One item of a section; a nested one under the item before it. In markdown a nested
    item starts at its parent's text (CommonMark §5.2: four spaces more make a code block).
    A raw line read from a controller may hold any byte: shown escaped, as a name is."""
    if md:
        return "  " * depth + "- " + markdown(text)
    return "  " + "    " * depth + printable(text)


def _title(reader: Reader, data: dict) -> str:
    model = f"a {reader.model}" if reader.model else "a Mercury controller (model unknown)"
    return f"{plural(len(reader.lines), 'macro')} for {model}; distances in {reader.unit}"


def _sections(reader: Reader, data: dict) -> list[tuple[str, list[tuple[int, str]]]]:
    """The sections in order, each item (depth, text): depth 1 is an item of the one above."""
    label = reader.label
    power = [f"{label(0)}: {data['power_on']['does']}"] if data["power_on"] else [
        "nothing: there is no macro 0, so nothing runs by itself"]
    ways: dict[int, list[str]] = {}
    for m in data["modes"]:
        when = " at power-on" if m["at_power_on"] else ""
        first = f", which first does: {m['first']}" if m["first"] else ""
        ways.setdefault(m["mode"], []).append(
            f"{m['condition']}{when} (through {label(m['by'])}{first})")
    modes = [f"{label(mode)}: chosen while " + "; or while ".join(how)
             for mode, how in ways.items()]
    ends = [f"{label(m['mode'])}: while {m['condition']} (through {label(m['by'])}), "
            f"{reader.phrase(list(reader.lines[m['mode']].ops or ()), reader.lines[m['mode']]) or 'nothing'}"
            "; then the program ends (direct mode)" for m in data["ends"]]
    loops = []
    for loop in data["loops"]:
        loops.append((0, f"{label(loop['slot'])}: every {loop['period_ms']} ms"
                      + _pass(loop["pass_ms"], reader.box)))
        loops += [(1, f"while {a['condition']}, {label(a['slot'])}: {a['does']}")
                  for a in loop["answers"]]
    leds = [f"{label(x['slot'])}: " + "; ".join(x["lights"]) for x in data["leds"]]
    every = [f"{label(m['slot'])}: {m['does']}" for m in data["macros"]]
    never = [f"{label(s)}" for s in data["unreached"]]
    by = "buttons" if reader.box else "inputs"
    return [("At power-on", _top(power)), (f"Modes chosen by {by}", _top(modes)),
            (f"Stops chosen by {by}", _top(ends)),
            (f"Polling loops and the {by} they answer", loops),
            ("LEDs" if reader.box else "Outputs", _top(leds)),
            ("Every macro", _top(every)), ("Never reached from macro 0", _top(never))]


def _pass(ms: int | None, box: bool) -> str:
    """How long a pass takes with nothing held: a `when` in the loop sees its input once a
    pass, so a shorter press may be missed (docs/simulator.md, "Conditions")."""
    if ms is None:
        return ""
    what = "a button must be held" if box else "an input must stay on"
    return f"; a pass takes {ms:,} ms with nothing held, so {what} at least that long to be seen"


def _top(texts: list[str]) -> list[tuple[int, str]]:
    return [(0, text) for text in texts]


def _edges(reader: Reader):
    """(caller, callee, label, tail) for every EM: `call` or `goto` (a tail EM, which never
    returns), with the condition that guards it: the XN/XF before it in the caller's line
    (a false one ends the line, MS176E §6.4 XN) and the one the callee starts with."""
    for s, line in reader.lines.items():
        guards = []
        for i, op in enumerate(line.ops or ()):
            if op.mnemonic in (Mnemonic.XN, Mnemonic.XF):
                guards.append(op)
            if op.mnemonic != Mnemonic.EM:
                continue
            tail = i == len(line.ops) - 1
            callee = reader.lines.get(op.arg)
            run = guards + condition_run(callee.ops if callee else ())
            words = "goto" if tail else "call"
            yield s, op.arg, words + (f" if {reader.condition(run)}" if run else ""), tail


def _node(reader: Reader, s: int) -> str:
    """'MC15 mode_1' plus the loop it runs, if any: 'every 20 ms', 'repeat 10 times'."""
    period = every_period(reader.lines[s].ops)
    found = runs(reader.lines[s], reader.lines)
    loop = f"every {period} ms" if period is not None else "" if found is None else \
        f"repeat {'' if found.exact else 'up to '}{found.times:,} times"
    return f"{slot_name(s)} {reader.names[s]}" + (f" ({loop})" if loop else "")


def _mermaid(reader: Reader) -> str:
    return "\n".join(["graph TD", *mermaid_body(reader)])


def mermaid_body(reader: Reader, prefix: str = "", indent: str = "    ") -> list[str]:
    """The call graph's nodes and edges as mermaid lines, node ids `prefix` + 'MCnn'."""
    out = []
    for s in reader.lines:
        out.append(f'{indent}{prefix}{slot_name(s)}["{mermaid(_node(reader, s))}"]')
    for s, t, label, tail in _edges(reader):
        out.append(f"{indent}{prefix}{slot_name(s)} {'-.->' if tail else '-->'}|{label}| "
                   f"{prefix}{slot_name(t)}")
    return out


def call_graph_dot(macros: dict[int, str], *, model: str | None = None,
                   names: dict[int, str] | None = None) -> str:
    """The call graph as Graphviz dot: solid edges for calls, dashed for a tail EM (goto),
    labelled with the condition that guards them; loops named on their macro."""
    return "\n".join(["digraph macros {", "    rankdir=LR;", "    node [shape=box];",
                      "    edge [fontsize=10];",
                      *dot_body(Reader(macros, model, names)), "}"]) + "\n"


def dot_body(reader: Reader, prefix: str = "", indent: str = "    ") -> list[str]:
    """The call graph's nodes and edges as dot lines, node ids `prefix` + 'MCnn' (a rig
    draws each controller's graph as a cluster of one picture)."""
    out = []
    for s in reader.lines:
        out.append(f'{indent}{prefix}{slot_name(s)} '
                   f'[label="{dot(_node(reader, s)).replace(" ", chr(92) + "n", 1)}"];')
    for s, t, label, tail in _edges(reader):
        style = ", style=dashed" if tail else ""
        out.append(f'{indent}{prefix}{slot_name(s)} -> {prefix}{slot_name(t)} '
                   f'[label="{dot(label)}"{style}];')
    return out
