"""`mercmac history` as a table for people or JSON for programs, and what `pull` and
`decompile` say about a record. Every text a record holds is escaped as `check` escapes
file names (report.printable): a name with a newline or an ESC sequence stays one cell."""
from __future__ import annotations

import json

from mercmac.render.console import Line
from mercmac.render.report import printable

COLUMNS = ("time", "port", "address", "model", "firmware", "file", "macros")


def table_lines(records) -> list[Line]:
    """One row per flash, newest first as given; a note when there are none."""
    if not records:
        return [[("no flashes recorded yet: `mercmac flash` records each verified upload", "")]]
    rows = [COLUMNS] + [_row(r) for r in records]
    widths = [max(len(row[i]) for row in rows) for i in range(len(COLUMNS))]
    out = []
    for n, row in enumerate(rows):
        text = "  ".join(cell.ljust(w) for cell, w in zip(row, widths)).rstrip()
        out.append([(text, "bold" if n == 0 else "")])
    return out


def to_json(records) -> str:
    """{"flashes": [{time, port, address, model, firmware, file, macros: {slot: line}, backup}]}"""
    return json.dumps({"flashes": [{
        "time": r.time, "port": r.port, "address": r.address, "model": r.model,
        "firmware": r.firmware, "file": r.file,
        "macros": {str(slot): line for slot, line in sorted(r.macros.items())},
        "backup": r.backup} for r in records]}, indent=2)


def skipped_lines(skipped) -> list[Line]:
    """One warning per history file that is no record, naming it and why."""
    return [[("warning: ", "bold yellow"),
             (f"{'cannot read the history folder' if s.folder else 'skipped the history file'} "
              f"{printable(str(s.path))}: {printable(s.why)}", "")] for s in skipped]


def label(record) -> str:
    """'four-modes.mcm, flashed 2026-11-22 10:41 from /home/me/four-modes.mcm'."""
    return (f"{printable(record.name)}, flashed {record.when.strftime('%Y-%m-%d %H:%M')} "
            f"from {printable(record.file)}")


def stale_text(recalled, instead: str) -> str:
    """Why a record of exactly this build is not given back, and what is given instead."""
    return (f"the recorded source of {label(recalled.stale)} no longer builds to what the "
            f"controller holds ({recalled.why}): {instead}")


def _row(r) -> tuple[str, ...]:
    return (r.when.strftime("%Y-%m-%d %H:%M:%S"), printable(r.port), str(r.address),
            printable(r.model or "?"), printable(r.firmware), printable(r.file),
            str(len(r.macros)))
