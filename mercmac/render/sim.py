"""Simulation output: the timeline, the trace, the summary (text) and the JSON of SPEC §5."""
from __future__ import annotations

import json
import math
from typing import IO

from mercmac.commands import Mnemonic
from mercmac.render.console import Line, write_lines
from mercmac.vm import events as ev
from mercmac.vm import fastforward as ff
from mercmac.sim.record import Folded, Recorder
from mercmac.sim.simulate import Run

ON, OFF = "●", "○"
TEXT_LIMIT = 2000  # timeline lines shown as text; JSON keeps SPEC §5's 10,000


def ms(t_us: float) -> int | float:
    """Microseconds as a JSON number of milliseconds: an int when whole."""
    value = t_us / 1000
    return int(value) if value == int(value) else round(value, 3)


def clock(t_us: float) -> str:
    """'12.345 s' below 1000 s, else '3d 04:05:06.789'."""
    if t_us == math.inf:
        return "never"
    seconds = t_us / 1e6
    if seconds < 1000:
        return f"{seconds:.3f} s"
    days, rest = divmod(seconds, 86400)
    hours, rest = divmod(rest, 3600)
    minutes, secs = divmod(rest, 60)
    text = f"{int(hours):02d}:{int(minutes):02d}:{secs:06.3f}"
    return f"{int(days)}d {text}" if days else text


def lamps(pattern: int) -> Line:
    """The four LEDs, output 1 first, lit ones bold yellow."""
    return [(ON, "bold yellow") if pattern >> i & 1 else (OFF, "dim") for i in range(4)]


def _where(where: ev.Where | None) -> str:
    if where is None:
        return ""
    return f"  [{where.label}, line {where.line}]" if where.line else f"  [{where.label}]"


def event_line(event) -> Line | None:
    """One timeline entry as a styled line; None for what the timeline does not show."""
    match event:
        case ev.InputChanged(t, n, on):
            name = {5: "joystick", 6: "joystick button"}.get(n, f"button {n}")
            return _at(t) + [(f"{name} {'pressed' if on else 'released'}", "bold cyan")]
        case ev.OutputsChanged(t, pattern):
            return _at(t) + [("LEDs ", "")] + lamps(pattern)
        case ev.Reported(t, text, where):
            return _at(t) + [("report ", ""), (text, "bold"), (_where(where), "dim")]
        case ev.HazardFound(t, rule, message, where):
            return _at(t) + [(f"hazard {rule}: ", "bold red"), (message, "red"), (_where(where), "dim")]
        case ev.MoveStarted(t, kind, target, arrival, _, where):
            when = f"arrives {clock(arrival)}" if arrival > t else "no motion"
            return _at(t) + [(f"{kind} to {target} ({when})", "green"), (_where(where), "dim")]
        case ev.MoveEnded(t, how, position):
            text = "on target at" if how == "arrived" else "stopped by the limit switch at"
            return _at(t) + [(f"{text} {position}", "green" if how == "arrived" else "bold red")]
        case ev.HomeDefined(t, position, where):
            return _at(t) + [(f"home defined: position is now {position}", "green"), (_where(where), "dim")]
        case ev.ProgramEnded(t):
            return _at(t) + [("program ended: back in direct mode", "bold")]
        case ev.FastForwarded(t, t_to, passes, period, loop, shape):
            return _at(t) + [(f"fast-forward {passes:,} identical passes of {loop.label} "
                              f"({_span(period)}{_emitted(shape)} each) to {clock(t_to)}",
                              "magenta"), (_where(loop), "dim")]
        case Folded():
            return _folded(event)
    return None


def _span(t_us: int) -> str:
    """A pass's length: '22 ms' up to 10 s, then as a clock ('00:24:01.790')."""
    return f"{t_us / 1000:g} ms" if t_us < 10_000_000 else clock(t_us)


def _emitted(shape: tuple) -> str:
    """', 1 report, 2 LED changes': what each skipped pass emitted (counted in the summary)."""
    reports, changes = ff.count(shape, ff.REPORT), ff.count(shape, ff.OUTPUTS)
    parts = ([f"{reports:,} report{'s' * (reports != 1)}"] if reports else []) + \
        ([f"{changes:,} LED change{'s' * (changes != 1)}"] if changes else [])
    return "".join(f", {part}" for part in parts)


def _folded(fold: Folded) -> Line:
    e = fold.event
    if isinstance(e, ev.MacroEntered):
        text = f"enter {e.label}" + (f" ({e.via})" if e.via != Mnemonic.EM else "")
    else:
        back = f", back to {e.back_to}" if e.back_to else ""
        why = "ends" if e.why == "end" else e.why if e.why == "stopped" else f"exits on {e.why}"
        text = f"{e.label} {why}{back}"
    if fold.count > 1:
        text += f"  x{fold.count:,} until {clock(fold.last_t)}"
    return _at(e.t) + [(text, "blue")]


def _at(t_us: float) -> Line:
    return [(f"{clock(t_us):>16}  ", "dim")]


def timeline(record: Recorder) -> list[Line]:
    lines = [line for line in map(event_line, record.timeline) if line is not None]
    hidden = max(len(lines) - TEXT_LIMIT, 0) + record.dropped["timeline"]
    lines = lines[:TEXT_LIMIT]
    if hidden:
        lines.append([(f"{'':>16}  ... {hidden:,} more events (see --format json)", "dim")])
    return lines


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
        [(f"  {len(rec.reports) + rec.dropped['reports']:,} reports, "
          f"{len(rec.outputs) + rec.dropped['outputs']:,} LED changes, ", ""),
         (f"{len(rec.hazards)} hazards", "bold red" if rec.hazards else "")],
    ]


def trace(record: Recorder) -> list[Line]:
    """Executed instructions, with the fast-forward jumps between them."""
    skips = [e for e in record.timeline if isinstance(e, ev.FastForwarded)]
    merged = sorted(record.trace + skips, key=lambda e: e.t)  # stable: skips after their RP
    lines = [_at(e.t) + [(e.text, "")] if isinstance(e, ev.Executed) else event_line(e)
             for e in merged]
    if record.dropped["trace"]:
        lines.append([(f"... {record.dropped['trace']:,} more instructions", "dim")])
    return lines


def write_text(run: Run, stream: IO[str] | None = None, *, with_trace: bool = False) -> None:
    """The timeline (or trace) and the summary, for people."""
    body = trace(run.record) if with_trace else timeline(run.record)
    write_lines(body + summary(run), stream)


def write_vcd_cut(path: str, limit_mb: float, cut_at: int, stream: IO[str] | None = None) -> None:
    """The warning for a VCD that stopped at its size limit (the run itself went on)."""
    write_lines([[(f"mercmac: warning: {path} stops at {clock(cut_at)}: it reached the "
                   f"--vcd-limit of {limit_mb:g} MB; raise --vcd-limit (0: no limit) or "
                   "shorten --until", "yellow")]], stream)


def write_scenario_passed(path: str, checked: int, stream: IO[str] | None = None) -> None:
    """The closing line of a scenario run in which every expectation held."""
    write_lines([[(f"scenario {path}: all {checked} expectations met", "bold green")]], stream)


def to_json(run: Run) -> str:
    """SPEC §5 `sim --format json`."""
    rec = run.record
    out = {
        "until_ms": run.until_ms,
        "halted": run.halted,
        "ended_ms": ms(rec.ended_at) if run.halted and rec.ended_at is not None else None,
        "final": run.final(),
        "reports": [{"t_ms": ms(r.t), "text": r.text} for r in rec.reports],
        "outputs": [{"t_ms": ms(o.t), "pattern": o.pattern} for o in rec.outputs],
        "hazards": [{"t_ms": ms(h.t), "rule": h.rule, "message": h.message,
                     "macro": h.where.label if h.where else None,
                     "slot": h.where.slot if h.where else None,
                     "line": h.where.line if h.where else None} for h in rec.hazards],
    }
    if rec.dropped["reports"] or rec.dropped["outputs"]:
        out["truncated"] = {"reports": rec.dropped["reports"], "outputs": rec.dropped["outputs"]}
    if rec.trace:
        out["trace"] = [{"t_ms": ms(e.t), "macro": e.where.slot, "line": e.where.line,
                         "instruction": e.text} for e in rec.trace]
    return json.dumps(out, indent=2)


def live_status(t_us: float, pattern: int, inputs: list[bool], position: int, target: int,
                macro: str) -> str:
    """The one status line of `sim --interactive`, redrawn in place."""
    leds = "".join(ON if pattern >> i & 1 else OFF for i in range(4))
    buttons = " ".join(f"[{n}]" if inputs[n] else f" {n} " for n in range(1, 5))
    return (f"{clock(t_us):>12}  LEDs {leds}  buttons {buttons}  position {position:>11}"
            f"  target {target:>11}  {macro}")
