"""A rig's simulation for people and programs (`sim RIG`, docs/rigs.md).

The text is one timeline of every controller, merged by time, each line carrying the
controller's name, with the wires' edges between them; then each controller's summary
(render/sim.py draws each line and each summary). A wired input's change is the wire's
edge, shown once as the wire, not as a button. The JSON holds one `sim --format json` object
per controller (docs/simulator.md, "What sim writes") and the wires' edges.
"""
from __future__ import annotations

import heapq
import json
from itertools import islice
from typing import IO, Iterator

from mercmac.names import printable
from mercmac.render import jsontext
from mercmac.render import sim as one
from mercmac.render.console import Line, write_lines
from mercmac.sim.record import CAP
from mercmac.sim.rig import Edge, RigRun
from mercmac.timespec import format_span
from mercmac.vm import events as ev


def write_text(result: RigRun, stream: IO[str] | None = None, *, verbose: int = 0,
               with_trace: bool = False) -> None:
    """The merged timeline at a verbosity (or each controller's trace), then the summaries."""
    body = _traces(result) if with_trace else timeline(result, verbose)
    write_lines([header(result)] + body + _summaries(result), stream)


def header(result: RigRun) -> Line:
    until = format_span(result.until_ms * 1000, digits=None)
    names = ", ".join(f"{c.name} ({c.model}, address {c.address})"
                      for c in result.rig.controllers)
    # the rig's name may come from its file's name: any characters (controllers' are words)
    return [(f"Simulating rig {printable(result.rig.name)}: {names}; from power-on until {until}",
             "bold")]


def timeline(result: RigRun, level: int = 0) -> list[Line]:
    """Every controller's timeline and the wires' edges, merged by time; at one instant in
    the rig's order of controllers, each followed by the edges of the wires it drives (so
    an output change reads before the wire, and the wire before what it starts)."""
    width = max(len(c.name) for c in result.rig.controllers)
    streams = []
    for name, run in result.runs.items():
        streams.append(_named(name, run.record.timeline, _wired(result, name), level, width))
        driven = [e for e in result.edges if e.wire.source.controller == name]
        streams.append(_edges(driven, width))
    merged = heapq.merge(*streams, key=lambda pair: pair[0])
    limit = one.TEXT_LIMIT if level < 2 else None
    lines = [line for _, line in islice(merged, limit)]
    hidden = sum(1 for _ in merged) + result.edges_dropped
    if hidden:
        lines.append([(f"{'':>16}  ... {one.plural(hidden, 'more line')} "
                       f"({'-vv shows more; ' if level < 2 else ''}"
                       "--plot or --vcd show the whole run)", "dim")])
    endings = [_ending(name, run, width) for name, run in result.runs.items()]
    return lines + [line for line in endings if line]


def _wired(result: RigRun, name: str) -> set[int]:
    return {w.target.number for w in result.rig.wires if w.target.controller == name}


def _named(name: str, events: list, wired: set[int], level: int,
           width: int) -> Iterator[tuple[int, Line]]:
    """One controller's dated lines, its name after the time; its wired inputs left out (the
    wires' edges show them)."""
    shown = [e for e in events if not (type(e) is ev.InputChanged and e.input in wired)]
    for t, line in one.dated_lines(shown, level):
        yield t, _with_name(line, name, width)


def _with_name(line: Line, name: str, width: int) -> Line:
    return line[:1] + [(f"{name:<{width}}  ", "bold blue")] + line[1:]


def _edges(edges: list[Edge], width: int) -> Iterator[tuple[int, Line]]:
    for edge in edges:
        t = edge.t
        text = f"{edge.wire.source} -> {edge.wire.target} {'ON' if edge.level else 'OFF'}"
        yield t, one.at(t) + [(f"{'':<{width}}  wire {text}", "cyan")]


def _ending(name: str, run, width: int) -> Line:
    line = one.ending(run)
    return _with_name(line, name, width) if line else []


def _traces(result: RigRun) -> list[Line]:
    lines: list[Line] = []
    for name, run in result.runs.items():
        lines += [[(f"{name}:", "bold")]] + one.trace(run.record)
    return lines


def _summaries(result: RigRun) -> list[Line]:
    lines: list[Line] = []
    for name, run in result.runs.items():
        block = one.summary(run)
        block[1] = [(f"{name}", "bold blue"), (" ", "")] + block[1]
        lines += block
    wires = len(result.edges) + result.edges_dropped
    lines += [[], [(f"Wires: {one.plural(len(result.rig.wires), 'wire')}, "
                    f"{one.plural(wires, 'edge')}", "")]]
    return lines


def to_json(result: RigRun) -> str:
    """One `sim --format json` object per controller, by name, and the wires' edges (capped like
    its lists, with the count left out under "truncated")."""
    out = {
        "rig": result.rig.name,
        "until_ms": result.until_ms,
        "controllers": {name: one.run_json(run) for name, run in result.runs.items()},
        "edges": [{"t_ms": one.ms(e.t), "wire": str(e.wire),
                   "source": str(e.wire.source), "target": str(e.wire.target),
                   "level": e.level} for e in result.edges[:CAP]],
    }
    if result.edges_dropped:
        out["truncated"] = {"edges": result.edges_dropped}
    return jsontext.dumps(out)  # json.dumps(..., indent=2), faster
