"""The uploader's text: identification, progress, the flash summary, dry runs, pull, scan, ports.

Plain lines when the output is not a terminal (logs, CI); a rich progress bar
and colour on a terminal (render/console.py decides, NO_COLOR honoured).
"""
from __future__ import annotations

import sys
from typing import IO

from mercmac.render.console import Line, rich_console, use_colour, write_lines

_FATE_STYLE = {"written": "bold green", "erased": "bold yellow", "re-written last": "green",
               "unchanged": "dim", "kept (not in file)": "yellow"}


def identity_lines(port: str, address: int, identity, warning: str | None = None) -> list[Line]:
    """'C-863, firmware 2.30, at address 0 on /dev/ttyUSB0' and what we had to do."""
    v = identity.version
    lines: list[Line] = [[("controller: ", "bold"), (f"{v.name}, firmware {v.firmware}", "cyan"),
                          (f", at address {address} on {port}", "")]]
    if identity.stopped_macro:
        lines.append([("note: ", "bold yellow"), ("a macro was running; it was stopped", "")])
    if warning:
        lines.append([("warning: ", "bold yellow"), (warning, "")])
    return lines


class FlashProgress:
    """Receives flasher events: a rich progress bar on a terminal, one line each otherwise."""

    def __init__(self, stream: IO[str] | None = None):
        self.stream = stream or sys.stdout
        self._progress = self._task = None

    def __enter__(self) -> "FlashProgress":
        if use_colour(self.stream):
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn

            # no refresh thread: it would keep redrawing the bar over the message of a
            # Ctrl-C that cut `stop` short; the bar is redrawn on each event instead
            self._progress = Progress(TextColumn("[bold]{task.description:<28}"), BarColumn(),
                                      MofNCompleteColumn(), console=rich_console(self.stream),
                                      transient=True, auto_refresh=False)
            self._progress.start()
        return self

    def __exit__(self, *exc) -> None:
        if self._progress:
            self._progress.stop()

    def __call__(self, event) -> None:
        if self._progress is None:
            if event.kind != "step":
                write_lines([_event_line(event)], self.stream)
            return
        if event.kind in ("step", "verified"):
            if self._task is None:
                self._task = self._progress.add_task(event.text, total=event.total)
            self._progress.update(self._task, description=event.text, completed=event.done,
                                  refresh=True)
        else:
            from rich.text import Text

            self._progress.console.print(Text.assemble(*_event_line(event)))


def _event_line(event) -> Line:
    style = {"retry": "bold yellow", "repair": "bold yellow", "backup": "bold"}.get(event.kind, "")
    if event.kind == "verified":
        return [(f"[{event.done}/{event.total}] ", "dim"), (event.text, "")]
    return [(event.text, style)]


def flash_summary(result, port: str) -> list[Line]:
    """The slot table and the outcome line."""
    plan = result.plan
    rows = [(f"MC{slot:02d}", _name(plan.names.get(slot), slot), fate.value)
            for slot, fate in sorted(plan.fates.items())]
    lines = table(("slot", "macro", "result"), rows, style_of=lambda row: _FATE_STYLE.get(row[2], ""))
    if result.dry_run:
        lines.append([("dry run: ", "bold yellow"), (f"nothing written ({_tally(plan)})", "")])
        return lines
    lines.append([("ok: ", "bold green"), (_outcome(plan), "")])
    if result.retried or result.repaired:
        again = ", ".join(f"MC{s:02d}" for s in result.retried + result.repaired)
        lines.append([("note: ", "bold yellow"), (f"needed a second write: {again} (check the cable)", "")])
    lines.append([("backup: ", "bold"), (str(result.backup), "")])
    if result.reset:
        lines.append([("reset: ", "bold"), ("RT sent, macro 0 is starting", "")])
    elif 0 in plan.after and not plan.changes_nothing:
        lines.append([("", ""), ("macro 0 runs at the next power-on (or use --reset)", "dim")])
    return lines


def completed_text(result) -> str:
    """The outcome of a finished flash in plain words, for a Ctrl-C while it is being shown."""
    if result.dry_run:
        return f"dry run complete, nothing was written ({_tally(result.plan)})"
    reset = "; RT was sent, macro 0 is starting" if result.reset else ""
    return f"the flash had finished: {_outcome(result.plan)}{reset}\n  backup: {result.backup}"


def _outcome(plan) -> str:
    if plan.changes_nothing:
        return "nothing to write: the controller already holds this program"
    return f"flashed and verified: {_tally(plan)}"


def _tally(plan) -> str:
    """'2 written, 1 unchanged': how many slots met each fate."""
    counts: dict[str, int] = {}
    for fate in plan.fates.values():
        counts[fate.value] = counts.get(fate.value, 0) + 1
    return ", ".join(f"{n} {what}" for what, n in counts.items()) or "no macros"


def dry_run_lines(result, address: int, baud: int) -> list[Line]:
    """Every byte a real flash would now send, and what for."""
    from mercmac.upload.protocol import show

    if result.plan.changes_nothing:
        return [[("nothing to send: ", "bold"), ("the controller already holds this program", "")]]
    wire = result.wire(address)
    lines: list[Line] = [[("bytes a flash would send after the read-back:", "bold")]]
    for data, purpose in wire:
        lines.append([("  -> ", "dim"), (f"{show(data):<64}", "cyan"), (f" {purpose}", "dim")])
    total = sum(len(data) for data, _ in wire)
    lines.append([("", ""), (f"{total} bytes out, {total * 10 / baud:.2f} s at {baud} baud", "dim")])
    return lines


def pulled_lines(pulled, port: str, address: int, output: str | None) -> list[Line]:
    v = pulled.identity.version
    where = f" into {output}" if output else ""
    return [[("read ", ""), (f"{len(pulled.macros)} macros", "bold"),
             (f" from the {v.name} (firmware {v.firmware}) at address {address} on {port}{where}", "")]]


def scan_lines(found, port: str) -> list[Line]:
    if not found:
        return [[("no controller answered", "bold yellow"), (f" on {port} at addresses 0-15", "")]]
    rows = [(str(f.address), f.model, f.version.firmware if f.version else "?", f.note)
            for f in found]
    lines = table(("address", "model", "firmware", "note"), rows)
    if not any(f.status for f in found):
        lines.append([("no controller answered like a Mercury", "bold yellow"),
                      (f" on {port}: garbled replies come from a baud rate other than the "
                       f"controllers' (check --baud)", "")])
    return lines


def ports_lines(ports) -> list[Line]:
    if not ports:
        return [[("no serial ports found", "bold yellow")]]
    rows = [(p.device, f"{p.vid:04X}:{p.pid:04X}" if p.vid is not None else "-",
             p.description, f"likely Mercury ({p.mercury})" if p.mercury else "") for p in ports]
    return table(("port", "usb id", "description", ""), rows,
                 style_of=lambda row: "bold green" if row[3] else "")


def table(header: tuple[str, ...], rows: list[tuple[str, ...]], style_of=lambda row: "") -> list[Line]:
    """Left-aligned columns; the same Lines in plain text and through rich."""
    widths = [max(len(str(c)) for c in col) for col in zip(header, *rows)]
    fmt = lambda row: "  ".join(f"{str(c):<{w}}" for c, w in zip(row, widths)).rstrip()  # noqa: E731
    return [[(fmt(header), "bold")]] + [[(fmt(row), style_of(row))] for row in rows]


def _name(name: str | None, slot: int) -> str:
    tag = f"MC{slot:02d}"
    if not name or name == tag:
        return "-"
    return name.replace(f" ({tag})", "")
