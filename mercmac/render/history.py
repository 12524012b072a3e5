"""`mercmac history` as a table for people or JSON for programs."""
from __future__ import annotations

import json

from mercmac.render.console import Line

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


def _row(r) -> tuple[str, ...]:
    return (r.when.strftime("%Y-%m-%d %H:%M:%S"), r.port, str(r.address), r.model or "?",
            r.firmware, r.file, str(len(r.macros)))
