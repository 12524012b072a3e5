"""`mercmac history` as a table for people or JSON for programs, and what `pull` and
`decompile` say about a record. Every text a record holds is escaped as `check` escapes
file names (names.printable): a name with a newline or an ESC sequence stays one cell."""
from __future__ import annotations

import json

from mercmac.names import printable
from mercmac.render.console import Line

COLUMNS = ("time", "port", "address", "model", "firmware", "file", "macros")


def table_lines(records) -> list[Line]:
    """One row per flash, newest first as given; the controllers of one rig flash under a
    line that names the rig; a note when there are none."""
    if not records:
        return [[("no flashes recorded yet: `mercmac flash` records each verified upload", "")]]
    groups = rig_groups(records)
    rows = [COLUMNS] + [_row(r) for group in groups for r in group]
    widths = [max(len(row[i]) for row in rows) for i in range(len(COLUMNS))]
    out, rows_left = [_cells(rows[0], widths, "bold")], iter(rows[1:])
    for group in groups:
        if group[0].rig is not None:
            out.append([(_rig_heading(group), "bold")])
        out += [_cells(next(rows_left), widths, "") for _ in group]
    return out


def rig_groups(records) -> list[list]:
    """The records in runs: the controllers of one rig flash together (the same rig file
    and port, each controller once), every other record alone."""
    groups: list[list] = []
    for r in records:
        last = groups[-1] if groups else None
        if (r.rig is not None and last and last[0].rig == r.rig and last[0].port == r.port
                and r.controller not in {x.controller for x in last}):
            last.append(r)
        else:
            groups.append([r])
    return groups


def _rig_heading(group) -> str:
    """'rig raster (/home/me/raster.rig.toml): 2 controllers'"""
    first = group[0]
    count = f"{len(group)} controller{'s' * (len(group) != 1)}"
    return f"rig {printable(first.rig_name or '?')} ({printable(first.rig)}): {count}"


def _cells(row: tuple[str, ...], widths: list[int], style: str) -> Line:
    return [("  ".join(cell.ljust(w) for cell, w in zip(row, widths)).rstrip(), style)]


def to_json(records) -> str:
    """{"flashes": [{time, port, address, model, firmware, file, macros: {slot: line}, backup,
    rig}]}; `rig` is {file, name, controller} for a controller flashed as part of a rig."""
    return json.dumps({"flashes": [{
        "time": r.time, "port": r.port, "address": r.address, "model": r.model,
        "firmware": r.firmware, "file": r.file,
        "macros": {str(slot): line for slot, line in sorted(r.macros.items())},
        "backup": r.backup,
        "rig": None if r.rig is None else {"file": r.rig, "name": r.rig_name,
                                           "controller": r.controller}} for r in records]},
        indent=2)


def skipped_lines(skipped) -> list[Line]:
    """One warning per history file that is no record, naming it and why."""
    return [[("warning: ", "bold yellow"),
             (f"{'cannot read the history folder' if s.folder else 'skipped the history file'} "
              f"{printable(str(s.path))}: {printable(s.why)}", "")] for s in skipped]


def label(record) -> str:
    """'four-modes.mcm, flashed 2026-11-22 10:41 from /home/me/four-modes.mcm'; a rig's
    'x.mcm (x of rig raster), flashed ...'."""
    rig = "" if record.rig is None else \
        f" ({printable(record.controller or '?')} of rig {printable(record.rig_name or '?')})"
    return (f"{printable(record.name)}{rig}, flashed {record.when.strftime('%Y-%m-%d %H:%M')} "
            f"from {printable(record.file)}")


def stale_text(recalled, instead: str) -> str:
    """Why a record of exactly this build is not given back, and what is given instead."""
    return (f"the recorded source of {label(recalled.stale)} no longer builds to what the "
            f"controller holds ({recalled.why}): {instead}")


def _row(r) -> tuple[str, ...]:
    """A record's cells; a rig's controller indented under its rig, its name before its file."""
    file = printable(r.file) if r.controller is None else \
        f"{printable(r.controller)}: {printable(r.file)}"
    indent = "  " if r.rig is not None else ""
    return (indent + r.when.strftime("%Y-%m-%d %H:%M:%S"), printable(r.port), str(r.address),
            printable(r.model or "?"), printable(r.firmware), file, str(len(r.macros)))
