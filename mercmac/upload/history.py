"""What was flashed where: one JSON record per verified flash, beside the backups.

`flash` records the source file, its build output and the controller (port, address,
model, firmware); `pull` and `decompile` look a controller's macros up here first, so
that a program mercmac flashed comes back with its names and comments. A record
matches when the controller holds exactly the recorded build: the same slots, each
with the same macro as the controller stores it (mdtext.normal).
"""
from __future__ import annotations

import datetime as _dt
import json
import os
from dataclasses import asdict, dataclass
from pathlib import Path

from mercmac import mdtext, outfile
from mercmac.upload import backup

FORMAT = 1  # the "format" of a record file; records of other formats are skipped


@dataclass(frozen=True, slots=True)
class Record:
    """One verified flash: when, where, from which file, and the macros it left."""

    time: str  # ISO 8601 with the UTC offset, to the second
    port: str
    address: int
    model: str | None
    firmware: str
    file: str  # the source's absolute path ('<stdin>' for standard input)
    source: str  # its whole text, as flashed
    build: list[str]  # the MD lines, slot order, macro 0 last (`mercmac build`)
    backup: str | None = None  # the backup of what the controller held before

    @property
    def name(self) -> str:
        return os.path.basename(self.file) or self.file

    @property
    def macros(self) -> dict[int, str]:
        """The build as slot -> stored line."""
        return {slot: body for slot, body in map(mdtext.split_md, self.build) if slot is not None}

    @property
    def when(self) -> _dt.datetime:
        return _dt.datetime.fromisoformat(self.time)

    @property
    def label(self) -> str:
        """'four-modes.mcm, flashed 2026-11-22 10:41 from /home/me/four-modes.mcm'."""
        return f"{self.name}, flashed {self.when.strftime('%Y-%m-%d %H:%M')} from {self.file}"


def folder() -> Path:
    """Where the records are: `history` in the per-user data directory ($MERCMAC_DATA_DIR)."""
    return backup.data_dir() / "history"


def record(*, port: str, address: int, model: str | None, firmware: str, file: str,
           source: str, build: list[str], backup_path: Path | None = None,
           when: _dt.datetime | None = None) -> Path:
    """Write one record, whole or not at all; outfile.OutputError when it cannot be written."""
    when = (when or _dt.datetime.now()).astimezone()
    shown = file if file.startswith("<") else os.path.abspath(file)
    entry = Record(when.isoformat(timespec="seconds"), port, address, model, firmware, shown,
                   source, list(build), str(backup_path) if backup_path else None)
    path = _new_path(when, port, address)
    outfile.write_text(path, json.dumps({"format": FORMAT, **asdict(entry)}, indent=1) + "\n",
                       make_parents=True)
    return path


def records() -> list[Record]:
    """Every readable record, newest first; unreadable or foreign files are skipped."""
    try:
        paths = sorted(folder().glob("*.json"), reverse=True)
    except OSError:
        return []
    found = [r for r in map(_load, paths) if r is not None]
    return sorted(found, key=lambda r: r.when, reverse=True)


def lookup(macros: dict[int, str], *, port: str | None = None,
           address: int | None = None) -> Record | None:
    """The newest record whose build is exactly `macros`; one made on this port and address
    is preferred. None when nothing matches (or there are no macros)."""
    wanted = _normal(macros)
    if not wanted:
        return None
    matches = [r for r in records() if _normal(r.macros) == wanted]
    here = [r for r in matches if (r.port, r.address) == (port, address)]
    return (here or matches or [None])[0]


def _normal(macros: dict[int, str]) -> dict[int, str]:
    """Slot -> the macro as the controller stores it; empty slots left out."""
    kept = {slot: mdtext.normal(text) for slot, text in macros.items()}
    return {slot: text for slot, text in kept.items() if text}


def _load(path: Path) -> Record | None:
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
        if not isinstance(data, dict) or data.pop("format", None) != FORMAT:
            return None
        entry = Record(**data)
        entry.when  # a time that does not read is no record
        if not (isinstance(entry.build, list) and all(isinstance(x, str) for x in entry.build)):
            return None
        return entry
    except (OSError, ValueError, TypeError, UnicodeDecodeError):
        return None


def _new_path(when: _dt.datetime, port: str, address: int) -> Path:
    stem = f"{when.strftime('%Y%m%d-%H%M%S-%f')}-{backup._port_tag(port)}-addr{address}"
    path, n = folder() / f"{stem}.json", 1
    while path.exists():
        n += 1
        path = folder() / f"{stem}-{n}.json"
    return path
