"""Simulation output: the timeline, the trace, the summary (text) and the JSON
(docs/simulator.md, "What sim writes").

One controller's run shows as a program's (a lone program is a rig of one). A rig of
several shows one timeline of every controller, merged by time, each line carrying the
controller's name, with the wires' edges between them, then each controller's summary; a
wired input's change is the wire's edge, shown once as the wire, not as a button. Its JSON
holds one `sim --format json` object per controller and the wires' edges (docs/rigs.md).
"""
from __future__ import annotations

import heapq
import math
from itertools import islice
from typing import IO, Iterator

from mercmac.commands import unit
from mercmac.mdtext import slot_name
from mercmac.names import printable
from mercmac.render import jsontext
from mercmac.render.console import Line, write_lines
from mercmac.timespec import format_clock, format_span
from mercmac.vm import events as ev
from mercmac.vm import shapes
from mercmac.vm.motion import Ended
from mercmac.sim import record
from mercmac.sim.record import Fold, Folded, Recorder
from mercmac.sim.simulate import Edge, Result, Run

ON, OFF = "●", "○"
TEXT_LIMIT = 2000  # lines of the story and of -v (-vv shows every line); JSON keeps 10,000


def ms(t_us: float) -> int | float:
    """Microseconds as a JSON number of milliseconds: an int when whole."""
    value = t_us / 1000
    return int(value) if value == int(value) else round(value, 3)


def clock(t_us: float) -> str:
    """A time in the timeline: always to the millisecond, so that the column lines up."""
    return format_clock(t_us, places=3)


def plural(n: int, noun: str, nouns: str | None = None) -> str:
    """'1 LED change', '2 hazards', '1,000 reports'."""
    return f"{n:,} {noun if n == 1 else nouns or noun + 's'}"


def lamps(pattern: int) -> Line:
    """The four LEDs, output 1 first, lit ones bold yellow."""
    return [(ON, "bold yellow") if pattern >> i & 1 else (OFF, "dim") for i in range(4)]


def _where(where: ev.Where | None) -> str:
    if where is None:
        return ""
    return f"  [{where.label}, line {where.line}]" if where.line else f"  [{where.label}]"


# What a live session shows as it happens (`sim --interactive`, `sim --web`): a person's
# presses, the LEDs, reports, hazards, moves and the program's end.
LIVE_EVENTS = (ev.InputChanged, ev.JoystickMoved, ev.OutputsChanged, ev.Reported,
               ev.HazardFound, ev.MoveStarted, ev.MoveEnded, ev.HomeDefined, ev.ProgramEnded)


def event_line(event, unit: str = "counts") -> Line | None:
    """One timeline entry as a styled line; None for what the timeline does not show.
    `unit`: what the controller's distances count in (commands.unit: steps on a C-663)."""
    match event:
        case ev.InputChanged(t, n, on):
            name = {5: "joystick", 6: "joystick button"}.get(n, f"button {n}")
            return at(t) + [(f"{name} {'pressed' if on else 'released'}", "bold cyan")]
        case ev.JoystickMoved(t):
            return at(t) + [(_stick(event, unit), "bold cyan")]
        case ev.OutputsChanged(t, pattern):
            return at(t) + [("LEDs ", "")] + lamps(pattern)
        case ev.Reported(t, text, where):
            return at(t) + [("report ", ""), (text, "bold"), (_where(where), "dim")]
        case ev.HazardFound(t, rule, message, where, True):
            return at(t) + [(f"accepted {rule}: ", "yellow"), (message, ""), (_where(where), "dim")]
        case ev.HazardFound(t, rule, message, where):
            return at(t) + [(f"hazard {rule}: ", "bold red"), (message, "red"), (_where(where), "dim")]
        case ev.MoveStarted(t, kind, target, arrival, segments, where):
            return at(t) + [(_move(t, kind, target, arrival, segments), "green"),
                             (_where(where), "dim")]
        case ev.MoveEnded(t, Ended.ARRIVED, position):
            return at(t) + [(f"on target at {position}", "green")]
        case ev.MoveEnded(t, Ended.LIMIT, position):
            return at(t) + [(f"stopped by the limit switch at {position}", "bold red")]
        case ev.HomeDefined(t, position, where):
            return at(t) + [(f"home defined: position is now {position}", "green"), (_where(where), "dim")]
        case ev.ProgramEnded(t):
            return at(t) + [("program ended: back in direct mode", "bold")]
        case ev.FastForwarded(t, t_to, passes, period, loop, shape, _, shift):
            kind = ("identical pass", "identical passes") if not shift else ("pass", "passes")
            whose = "the target " if event.steady else ""  # (the stage runs on its profile)
            moved = (f", {whose or 'each '}{'+' if shift > 0 else '-'}"
                     f"{plural(abs(shift), unit.removesuffix('s'))} further"
                     f"{' each' if whose else ''}"
                     if shift else "")
            return at(t) + [(f"fast-forward {plural(passes, *kind)} of {loop.label} "
                              f"({format_span(period)}{_emitted(shape)} each{moved}) "
                              f"to {clock(t_to)}", "magenta"), (_where(loop), "dim")]
        case Folded():
            return _folded(event)
    return None


# MS176E §6.4 JT: the predefined response tables, by number
JOYSTICK_TABLES = {0: "linear", 1: "cubic", 2: "inverted linear", 3: "inverted cubic"}


def _stick(e: ev.JoystickMoved, unit: str = "counts") -> str:
    """'joystick at +0.50 (input 5 ON): commands +1,000 counts/s (JN 8000, cubic table)': the
    deflection and the velocity it commands (MS176E §3.6.1); the input 5 change it makes is
    said here, not on a line of its own (_story)."""
    where = f"at {e.deflection:+.2f}" if e.deflection else "back in the middle"
    head = f"joystick {where} (input 5 {'ON' if e.input_on else 'OFF'}): "
    if not e.maximum:
        return head + "commands nothing, joystick control is off (no JN)"
    v = e.velocity
    speed = "0" if not v else f"{v:+,.0f}" if abs(v) >= 1 else f"{v:+.2g}"
    table = JOYSTICK_TABLES.get(e.table, f"table {e.table}")
    return head + f"commands {speed} {unit}/s (JN {e.maximum}, {table} table)"


def _move(t: int, kind: ev.Motion, target: int, arrival: float, segments: tuple) -> str:
    """'move to -2000 from 0 (arrives 0.264 s, in 141 ms)'."""
    if arrival <= t:
        return f"{kind} to {target} (no motion)"
    # where the stage is at t: a profile kept from before (MoveStarted.kept) began earlier
    start = (f" from {round(next((s for s in segments if t < s.t1), segments[-1]).x(t))}"
             if segments else "")
    if kind == ev.Motion.JOYSTICK:  # it runs while deflected: the end of its range, not a goal
        return f"joystick runs toward {target}{start} (its range's end) while deflected"
    when = "never arrives" if arrival == math.inf else \
        f"arrives {clock(arrival)}, in {format_span(arrival - t)}"
    return f"{kind} to {target}{start} ({when})"


def _emitted(shape: tuple) -> str:
    """', 1 report, 2 LED changes': what each skipped pass emitted (counted in the summary)."""
    reports, changes = shapes.count(shape, shapes.REPORT), shapes.count(shape, shapes.OUTPUTS)
    parts = ([plural(reports, "report")] if reports else []) + \
        ([plural(changes, "LED change")] if changes else [])
    return "".join(f", {part}" for part in parts)


def _flow_text(fold: Folded, entering: bool) -> str:
    """'enter MC05 (host)', 'MC05 exits on XN1, back to main (MC01)'."""
    e = fold.event
    if entering:  # a poll's fold holds its exit, and a poll was entered by EM
        via = e.via if isinstance(e, ev.MacroEntered) else ev.Via.EM
        return f"enter {e.label}" if via is ev.Via.EM else f"enter {e.label} ({via})"
    back = f", back to {e.back_to}" if e.back_to else ""
    match e.why:
        case ev.Exit.END:
            why = "ends"
        case ev.Exit.STOPPED:
            why = "stopped"
        case failed:  # an XN or XF
            why = f"exits on {failed}"
    return f"{e.label} {why}{back}"


def _mode_text(fold: Folded) -> str:
    e = fold.event
    match fold.kind:
        case Fold.START:
            return f"{e.via}: {e.label} starts"
        case Fold.GOTO:
            return f"goto {e.label}"
        case Fold.LOOP:
            return f"enter the loop {e.label}"
    raise ValueError(f"{fold.kind} is not a mode change")


def _folded(fold: Folded) -> Line:
    """A fold on one line, as `-vv` shows it: at its first time, with its count."""
    return _fold_lines(fold, 2)[0][1]


def _shown(kind: Fold, level: int) -> int:
    """Lines a fold of a kind makes at a verbosity: a mode change always, an entry or exit
    from `-v` on, a poll (its entry and its exit) only at `-vv` (`-v` sums them up)."""
    match kind:
        case Fold.START | Fold.GOTO | Fold.LOOP:
            return 1
        case Fold.POLL:
            return 2 if level >= 2 else 0
        case Fold.ENTRY | Fold.LEFT:
            return 1 if level >= 1 else 0
    raise ValueError(f"no fold of kind {kind}")


def _fold_lines(fold: Folded, level: int) -> list[tuple[int, Line]]:
    """(time, line) for a fold at a verbosity; a repeated one is dated at its last time."""
    if not _shown(fold.kind, level):
        return []
    match fold.kind:
        case Fold.START | Fold.GOTO | Fold.LOOP:
            texts, style = [_mode_text(fold)], "bold blue"
        case Fold.POLL:
            texts, style = [_flow_text(fold, True), _flow_text(fold, False)], "blue"
        case kind:
            texts, style = [_flow_text(fold, kind is Fold.ENTRY)], "blue"
    if fold.count == 1:
        times = [fold.first_t, fold.last_t] if fold.kind is Fold.POLL else [fold.last_t]
        return [(t, at(t) + [(text, style)]) for t, text in zip(times, texts)]
    counts = [f"  x{fold.count:,} since {clock(fold.first_t)}", f"  x{fold.count:,}"]
    return [(fold.last_t, at(fold.last_t) + [(text + count, style)])
            for text, count in zip(texts, counts)]


def _polls(folds: list[Folded]) -> list[tuple[int, Line]]:
    """`-v`: one line for the polls of a stretch (macros entered only to test a button)."""
    polls = [f for f in folds if f.kind is Fold.POLL]
    if not polls:
        return []
    t = max(f.last_t for f in polls)
    slots = ", ".join(dict.fromkeys(slot_name(f.event.slot) for f in polls))
    text = (f"{plural(sum(f.count for f in polls), 'poll')} since "
            f"{clock(min(f.first_t for f in polls))}: {slots} tested and left")
    return [(t, at(t) + [(text, "dim blue")])]


def _stretch(folds: list[Folded], level: int) -> list[tuple[int, Line]]:
    """The macro flow between two other events, (time, line) in time order."""
    dated = [pair for fold in folds for pair in _fold_lines(fold, level)]
    if level == 1:
        dated += _polls(folds)
    return sorted(dated, key=lambda pair: pair[0])


def at(t_us: float) -> Line:
    """A timeline line's time column (a rig's wires' edges are dated alike)."""
    return [(f"{clock(t_us):>16}  ", "dim")]


def _story(events: list, level: int, unit: str = "counts") -> Iterator[tuple[int, Line]]:
    """The shown lines, dated: other events as they come, each stretch of folds sorted."""
    folds: list[Folded] = []
    stick = None  # the joystick move just shown: its line says the input 5 change it made
    for event in events:
        if isinstance(event, Folded):
            folds.append(event)
            continue
        if type(event) is ev.InputChanged and event.input == 5 and stick is not None \
                and stick.t == event.t:
            continue
        stick = event if type(event) is ev.JoystickMoved else None
        yield from _stretch(folds, level)
        folds = []
        line = event_line(event, unit)
        if line is not None:
            yield event.t, line
    yield from _stretch(folds, level)


def timeline(result: Result, level: int = 0) -> list[Line]:
    """The timeline at a verbosity: 0 the story, 1 with macro entries and exits, 2 all; in a
    rig of several, every controller's and the wires' edges merged by time, at one instant in
    the rig's order of controllers, each followed by the edges of the wires it drives (so an
    output change reads before the wire, and the wire before what it starts).

    The story and `-v` stop after TEXT_LIMIT lines; `-vv` shows every line of the
    recorded timeline. Either way the last line counts exactly the lines left out.
    """
    streams, copies_listed = [], 0
    for name, run in result.runs.items():
        streams.append(_named(result, name, run.record.timeline, level))
        if result.rig.several:
            edges, copies = _edges(result, name, run.record.timeline)
            streams.append(edges)
            copies_listed += copies
    merged = heapq.merge(*streams, key=lambda pair: pair[0])
    dated = list(islice(merged, TEXT_LIMIT if level < 2 else None))
    cut = sum(1 for _ in merged)  # what the text limit left out
    records = [run.record for run in result.runs.values()]
    # edges past the cap, but those of skipped passes: the fast-forward lines tell them
    dropped = result.edges_dropped - (result.edges_copied - copies_listed)
    hidden = cut + sum(_unlisted(rec, level) for rec in records) + dropped
    lines = [line for _, line in dated]
    if hidden:
        lines.append(_left_out(hidden, dated[-1][0] if dated else 0, bool(cut),
                               any(rec.dropped["timeline"] for rec in records), dropped))
    return lines


def _named(result: Result, name: str, events: list, level: int) -> Iterator[tuple[int, Line]]:
    """One controller's dated lines; in a rig of several, its name after the time and its
    wired inputs left out (the wires' edges show them)."""
    distance = unit(result.runs[name].machine.model)
    if not result.rig.several:
        yield from _story(events, level, distance)
        return
    wired = {w.target.number for w in result.rig.wires if w.target.controller == name}
    shown = [e for e in events if not (type(e) is ev.InputChanged and e.input in wired)]
    width = _width(result)
    for t, line in _story(shown, level, distance):
        yield t, _with_name(line, name, width)


def _width(result: Result) -> int:
    return max(len(c.name) for c in result.rig.controllers)


def _with_name(line: Line, name: str, width: int) -> Line:
    return line[:1] + [(f"{name:<{width}}  ", "bold blue")] + line[1:]


def _edges(result: Result, name: str, events: list) -> tuple[list[tuple[int, Line]], int]:
    """The edges of the wires `name` drives, dated, but those of passes its fast-forward
    lines skip (the JSON lists them: a timeline never goes back); and how many those were."""
    width = _width(result)
    skips = [(e.t, e.t_to) for e in events if type(e) is ev.FastForwarded]
    lines, copies, i = [], 0, 0
    for edge in result.edges:
        if edge.wire.source.controller != name:
            continue
        while i < len(skips) and skips[i][1] < edge.t:
            i += 1
        if i < len(skips) and skips[i][0] < edge.t:  # within (t, t_to]: a copy
            copies += 1
            continue
        lines.append((edge.t, at(edge.t) + [(f"{'':<{width}}  wire {_edge_text(edge)}",
                                             "cyan")]))
    return lines, copies


def _edge_text(edge: Edge) -> str:
    return f"{edge.wire.source} -> {edge.wire.target} {'ON' if edge.level else 'OFF'}"


def _unlisted(rec: Recorder, level: int) -> int:
    """The lines the entries past the recorder's cap would make at a verbosity."""
    folds = sum(n * _shown(kind, level) for kind, n in rec.unlisted.items())
    return rec.unlisted_events + folds + (rec.unlisted_polled if level == 1 else 0)


def _left_out(hidden: int, after_us: int, cut: bool, dropped: bool, edges: int) -> Line:
    """The closing line of a cut timeline: how many lines, after when, and where the rest is
    (`dropped`: a recorder stopped listing at its cap; `edges`: wire edges past theirs)."""
    where = [f"-vv shows {'more' if dropped or edges else 'every line'}"] if cut else []
    if dropped:
        where.append(f"the timeline keeps the first {record.TIMELINE_CAP:,} entries; "
                     "--vcd or --plot show the whole run")
    if edges:
        where.append(f"a run lists the first {record.CAP:,} wire edges; --vcd or --plot "
                     "show them all")
    return [(f"{'':>16}  ... {plural(hidden, 'more line')} after {clock(after_us)} "
             f"({'; '.join(where)})", "dim")]


def ending(run: Run) -> list[Line]:
    """The timeline's last line when the run stopped at --until with the program running."""
    if run.halted:
        return []
    return at(run.until_ms * 1000) + [(f"end of the run: {run.machine.chunk.label} "
                                        "still running", "bold")]


def summary(run: Run) -> list[Line]:
    """The closing block: how the run ended and the machine's final state."""
    m, rec, end = run.machine, run.record, run.until_ms * 1000
    if run.halted:
        how = f"the program ended at {clock(rec.ended_at or 0)}" if rec.ended_at is not None \
            else "no macro ran (no autostart macro 0)"
    else:
        how = f"still running {m.chunk.label} at the end"
    final = run.final()
    return [
        [],
        [("Summary", "bold"), (f": ran to {clock(end)}; {how}.", "")],
        [("  position ", ""), (f"{final['position']}", "bold"), (f", target {final['target']}, "
          f"velocity {final['velocity']}, LEDs ", "")] + lamps(final["outputs"]),
        [(f"  {plural(len(rec.reports) + rec.dropped['reports'], 'report')}, "
          f"{plural(len(rec.outputs) + rec.dropped['outputs'], 'LED change')}, ", ""),
         (plural(len(rec.hazards), "hazard"), "bold red" if rec.hazards else ""),
         (f", {len(rec.accepted)} accepted" if rec.accepted else "", "")],
    ]


def _endings(result: Result) -> list[Line]:
    """Each running controller's last line at --until (named in a rig of several)."""
    lines = [ending(run) for run in result.runs.values()]
    if result.rig.several:
        width = _width(result)
        lines = [_with_name(line, name, width) if line else line
                 for name, line in zip(result.runs, lines)]
    return lines


def _summaries(result: Result) -> list[Line]:
    """Each controller's summary (named in a rig of several), and the wires' count."""
    if not result.rig.several:
        return summary(result.only)
    lines: list[Line] = []
    for name, run in result.runs.items():
        block = summary(run)
        block[1] = [(f"{name}", "bold blue"), (" ", "")] + block[1]
        lines += block
    edges = len(result.edges) + result.edges_dropped
    return lines + [[], [(f"Wires: {plural(len(result.rig.wires), 'wire')}, "
                          f"{plural(edges, 'edge')}", "")]]


def _traces(result: Result) -> list[Line]:
    """Each controller's trace (under its name in a rig of several)."""
    if not result.rig.several:
        return trace(result.only.record, unit(result.only.machine.model))
    lines: list[Line] = []
    for name, run in result.runs.items():
        lines += [[(f"{name}:", "bold")]] + trace(run.record, unit(run.machine.model))
    return lines


def trace(record: Recorder, unit: str = "counts") -> list[Line]:
    """Executed instructions, with the fast-forward jumps between them."""
    skips = [e for e in record.timeline if isinstance(e, ev.FastForwarded)]
    merged = sorted(record.trace + skips, key=lambda e: e.t)  # stable: skips after their RP
    lines = [at(e.t) + [(e.text, "")] if isinstance(e, ev.Executed) else event_line(e, unit)
             for e in merged]
    if record.dropped["trace"]:
        lines.append([(f"... {record.dropped['trace']:,} more instructions", "dim")])
    return lines


def write_text(result: Result, stream: IO[str] | None = None, *, with_trace: bool = False,
               verbose: int = 0) -> None:
    """The timeline at a verbosity (or the trace) and the summary, for people."""
    body = _traces(result) if with_trace else timeline(result, verbose) + _endings(result)
    write_lines([header(result)] + [line for line in body if line] + _summaries(result), stream)


def header(result: Result) -> Line:
    """What was simulated, and for how long, with the unit: `--until 3` is 3 ms, not 3 s."""
    until = format_span(result.until_ms * 1000, digits=None)
    if not result.rig.several:
        return [(f"Simulating a {result.only.machine.model} from power-on until {until}",
                 "bold")]
    names = ", ".join(f"{c.name} ({c.model}, address {c.address})"
                      for c in result.rig.controllers)
    # the rig's name may come from its file's name: any characters (controllers' are words)
    return [(f"Simulating rig {printable(result.rig.name)}: {names}; from power-on until "
             f"{until}", "bold")]


def write_vcd_cut(path: str, limit_mb: float, cut_at: int, stream: IO[str] | None = None) -> None:
    """The warning for a VCD that stopped at its size limit (the run itself went on)."""
    write_lines([[(f"mercmac: warning: {printable(path)} stops at {clock(cut_at)}: it reached "
                   f"the --vcd-limit of {limit_mb:g} MB; raise --vcd-limit (0: no limit) or "
                   "shorten --until", "yellow")]], stream)


def write_scenario_passed(path: str, checked: int, stream: IO[str] | None = None) -> None:
    """The closing line of a scenario run in which every expectation held."""
    write_lines([[(f"scenario {printable(path)}: all {checked} expectations met", "bold green")]],
                stream)


def to_json(result: Result) -> str:
    """`sim --format json` (docs/simulator.md, "What sim writes"); a rig of several: one
    such object per controller, by name, and the wires' edges (capped like its lists, with
    the count left out under "truncated"; docs/rigs.md)."""
    if not result.rig.several:
        return jsontext.dumps(run_json(result.only))  # json.dumps(..., indent=2), faster
    out = {
        "rig": result.rig.name,
        "until_ms": result.until_ms,
        "controllers": {name: run_json(run) for name, run in result.runs.items()},
        "edges": [{"t_ms": ms(e.t), "wire": str(e.wire), "source": str(e.wire.source),
                   "target": str(e.wire.target), "level": e.level}
                  for e in result.edges[:record.CAP]],
    }
    if result.edges_dropped:
        out["truncated"] = {"edges": result.edges_dropped}
    return jsontext.dumps(out)


def run_json(run: Run) -> dict:
    """The object of `sim --format json` for one controller's run."""
    rec = run.record
    out = {
        "until_ms": run.until_ms,
        "halted": run.halted,
        "ended_ms": ms(rec.ended_at) if run.halted and rec.ended_at is not None else None,
        "final": run.final(),
        "reports": [{"t_ms": ms(r.t), "text": r.text} for r in rec.reports],
        "outputs": [{"t_ms": ms(o.t), "pattern": o.pattern} for o in rec.outputs],
        "hazards": [{"t_ms": ms(h.t), "rule": h.rule, "message": h.message,
                     **_source(h.where)} for h in rec.hazards],
        "events": [_event_json(e) for e in rec.events],
    }
    if rec.accepted:  # hazards the user accepts (--allow-hazard, expect[...]): not counted
        out["accepted_hazards"] = [{"t_ms": ms(h.t), "rule": h.rule, "message": h.message,
                                    **_source(h.where)} for h in rec.accepted]
    if rec.trace:  # --trace: the executed instructions, capped like the lists above
        out["trace"] = [{"t_ms": ms(e.t), "macro": e.where.slot, "line": e.where.line,
                         "instruction": e.text, "name": e.where.label}
                        for e in rec.trace[:JSON_CAP]]
    truncated = _truncated(rec)
    if truncated:
        out["truncated"] = truncated
    return out


JSON_CAP = record.CAP  # each JSON list keeps its first 10,000 entries


def _truncated(rec: Recorder) -> dict:
    """`truncated`: when any list was cut, the counts left out of reports, outputs and
    events (all three keys, as docs/simulator.md shows them), and of the trace when it was cut."""
    trace = rec.dropped["trace"] + max(len(rec.trace) - JSON_CAP, 0)
    counts = {key: rec.dropped[key] for key in ("reports", "outputs", "events")}
    if not (any(counts.values()) or trace):
        return {}
    return counts | ({"trace": trace} if trace else {})


def _source(where: ev.Where | None) -> dict:
    """The macro (label), its slot and the source line an event came from; nulls if none."""
    return {"macro": where.label if where else None, "slot": where.slot if where else None,
            "line": where.line if where else None}


def _event_json(event) -> dict:
    """One entry of the JSON `events`: its time, its kind, where it came from, its details.
    (One function per kind of event, found by its type: a run lists up to 10,000.)"""
    write = _EVENT_JSON.get(type(event))
    return write(event) if write else {"t_ms": ms(event.t), "kind": type(event).__name__}


def _move_json(e: ev.MoveStarted) -> dict:
    arrival = e.arrival
    return {"t_ms": ms(e.t), "kind": "move", **_source(e.where), "motion": e.kind,
            "target": e.target, "arrival_ms": None if arrival == math.inf else ms(arrival)}


def _ended_json(e: ev.MoveEnded) -> dict:
    kind = "arrive" if e.how is Ended.ARRIVED else "limit"
    return {"t_ms": ms(e.t), "kind": kind, "position": e.position}


_EVENT_JSON = {
    ev.InputChanged: lambda e: {"t_ms": ms(e.t), "kind": "press" if e.on else "release",
                                "input": e.input},
    ev.JoystickMoved: lambda e: {"t_ms": ms(e.t), "kind": "joystick", "deflection": e.deflection,
                                 "velocity": round(e.velocity, 3) + 0.0,  # never -0.0
                                 "jn": e.maximum, "table": e.table},
    ev.OutputsChanged: lambda e: {"t_ms": ms(e.t), "kind": "output", "pattern": e.pattern},
    ev.Reported: lambda e: {"t_ms": ms(e.t), "kind": "report", **_source(e.where),
                            "text": e.text},
    ev.HazardFound: lambda e: {"t_ms": ms(e.t), "kind": "hazard", **_source(e.where),
                               "rule": e.rule, "message": e.message,
                               **({"accepted": True} if e.accepted else {})},
    ev.MoveStarted: _move_json,
    ev.MoveEnded: _ended_json,
    ev.HomeDefined: lambda e: {"t_ms": ms(e.t), "kind": "home", **_source(e.where),
                               "position": e.position},
    ev.MacroEntered: lambda e: {"t_ms": ms(e.t), "kind": "macro-enter", "macro": e.label,
                                "slot": e.slot, "via": e.via},
    ev.MacroLeft: lambda e: {"t_ms": ms(e.t), "kind": "macro-exit", "macro": e.label,
                             "slot": e.slot, "why": e.why, "back_to": e.back_to,
                             "back_slot": e.back_slot},
    ev.ProgramEnded: lambda e: {"t_ms": ms(e.t), "kind": "program-end"},
    ev.FastForwarded: lambda e: {"t_ms": ms(e.t), "kind": "fast-forward", **_source(e.loop),
                                 "to_ms": ms(e.t_to), "passes": e.passes,
                                 "period_ms": ms(e.period)},
}


def live_status(t_us: float, pattern: int, inputs: list[bool], position: int, target: int,
                macro: str) -> str:
    """The one status line of `sim --interactive`, redrawn in place."""
    leds = "".join(ON if pattern >> i & 1 else OFF for i in range(4))
    buttons = " ".join(f"[{n}]" if inputs[n] else f" {n} " for n in range(1, 5))
    running = macro if macro == "direct mode" else f"running {macro}"
    return (f"{clock(t_us):>12}  LEDs {leds}  buttons {buttons}  position {position:>11}"
            f"  target {target:>11}  {running}")


def countdown_status(left_s: float, inputs: list[bool]) -> str:
    """The status line before power-on in `sim --interactive`: which inputs will be held."""
    held = " ".join(f"[{n}]" for n in range(1, 7) if inputs[n]) or "none"
    return (f"power-on in {format_clock(left_s * 1e6, places=1)}: keys 1-6 choose the buttons "
            f"held at power-on, Enter powers on now - held: {held}")


def reset_line(t_us: float) -> Line:
    """The line `r` leaves in the interactive box's log."""
    return at(t_us) + [("reset: power-on again (like RT); held buttons stay held", "bold")]
