"""What was flashed where: one JSON record per verified flash, beside the backups.

`flash` records the source file, its build output and the controller (port, address,
model, firmware); `pull` and `decompile` look a controller's macros up here first, so
that a program mercmac flashed comes back with its names and comments. A record
matches when the controller holds exactly the recorded build (the same slots, each
with the same macro as the controller stores it, mdtext.normal) and its source still
builds to that with this mercmac. Every file is checked against the Record's field
types when read; one that is no record is skipped and named (Shelf.skipped).
"""
from __future__ import annotations

import dataclasses
import datetime as _dt
import json
import os
import types
import typing
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import NamedTuple

from mercmac import mdtext, outfile
from mercmac.source import SourceError, read_bytes
from mercmac.upload import backup

FORMAT = 1  # the "format" of a record file; records of other formats are skipped
# A record is a few KB (the source and its build); one over a megabyte is no record of
# ours. What is read at all is capped by source.read_bytes.
MAX_BYTES = 1_000_000
# A path as the system names it: a byte that is not UTF-8 stands as U+DC80-U+DCFF (Python's
# surrogateescape, os.fsdecode), which JSON carries as a \udcXX escape. Other text of a
# record holds no lone surrogate: no file or terminal could take it.
PathText = typing.Annotated[str, "surrogateescape"]


@dataclass(frozen=True, slots=True)
class Record:
    """One verified flash: when, where, from which file, and the macros it left.

    The field types are the schema a record file is checked against when read (_fits).
    """

    time: str  # ISO 8601 with the UTC offset, to the second
    port: PathText
    address: int
    model: str | None
    firmware: str
    file: PathText  # the source's absolute path ('<stdin>' for standard input)
    source: str  # its whole text, as flashed
    build: list[str]  # the MD lines, slot order, macro 0 last (`mercmac build`)
    backup: PathText | None = None  # the backup of what the controller held before
    # A controller flashed as part of a rig (mercmac.upload.rig): the rig file's absolute
    # path, the rig's name and this controller's name in it, so that `pull --rig` gives the
    # names back. Records of single flashes (and of older mercmacs) have none.
    rig: PathText | None = None
    rig_name: str | None = None
    controller: str | None = None

    @property
    def name(self) -> str:
        return os.path.basename(self.file) or self.file

    @property
    def macros(self) -> dict[int, str]:
        """The build as slot -> stored line."""
        return {slot: body for slot, body in map(mdtext.split_md, self.build) if slot is not None}

    @property
    def when(self) -> _dt.datetime:
        """The record's time; ValueError when it is no ISO 8601 time. A `Z` for UTC is read
        on every Python (fromisoformat takes it from 3.11 on; on 3.10 it is written +00:00)."""
        time = self.time[:-1] + "+00:00" if self.time[-1:] in ("Z", "z") else self.time
        return _dt.datetime.fromisoformat(time)


class Skipped(NamedTuple):
    """A file in the history folder that is no record, or the folder itself, unreadable."""

    path: Path
    why: str
    folder: bool = False


class Shelf(NamedTuple):
    """What the history folder holds: the records, newest first, and what was skipped."""

    records: list[Record]
    skipped: list[Skipped]


class Recalled(NamedTuple):
    """A record whose source gives back what the controller holds; or, when the newest
    record of that build no longer builds to it, that record (`stale`) and why."""

    record: Record | None
    stale: Record | None = None
    why: str = ""


def folder() -> Path:
    """Where the records are: `history` in the per-user data directory ($MERCMAC_DATA_DIR)."""
    return backup.data_dir() / "history"


class InRig(NamedTuple):
    """Where a flashed controller belongs: the rig file, the rig's name, its own name."""

    file: str
    name: str
    controller: str


def record(*, port: str, address: int, model: str | None, firmware: str, file: str,
           source: str, build: list[str], backup_path: Path | None = None,
           when: _dt.datetime | None = None, rig: InRig | None = None) -> Path:
    """Write one record, whole or not at all; outfile.OutputError when it cannot be written."""
    when = (when or _dt.datetime.now()).astimezone()
    shown = file if file.startswith("<") else os.path.abspath(file)
    entry = Record(when.isoformat(timespec="seconds"), port, address, model, firmware, shown,
                   source, list(build), str(backup_path) if backup_path else None,
                   *((os.path.abspath(rig.file), rig.name, rig.controller) if rig else ()))
    fields = asdict(entry)
    if rig is None:  # a single flash's record stays readable by mercmacs without rigs
        for name in _RIG_FIELDS:
            del fields[name]
    path = _new_path(when, port, address)
    outfile.write_text(path, json.dumps({"format": FORMAT, **fields}, indent=1) + "\n",
                       make_parents=True)
    return path


_RIG_FIELDS = ("rig", "rig_name", "controller")


def read() -> Shelf:
    """Every readable record, newest first, and the files skipped with the reason."""
    where = folder()
    try:
        with os.scandir(where) as entries:
            paths = sorted((Path(e.path) for e in entries if e.name.endswith(".json")),
                           reverse=True)
    except FileNotFoundError:
        return Shelf([], [])  # nothing flashed yet
    except OSError as e:
        why = "it is not a folder" if isinstance(e, NotADirectoryError) else outfile.reason(e)
        return Shelf([], [Skipped(where, why, folder=True)])
    found, skipped = [], []
    for path in paths:
        try:
            found.append(_load(path))
        except _Unreadable as e:
            skipped.append(Skipped(path, str(e)))
    return Shelf(sorted(found, key=lambda r: r.when, reverse=True), skipped)


def records() -> list[Record]:
    """Every readable record, newest first; unreadable or foreign files are left out."""
    return read().records


def recall(macros: dict[int, str], records: list[Record], *, port: str | None = None,
           address: int | None = None) -> Recalled:
    """The newest of `records` whose build is exactly `macros` (one made on this port and
    address preferred) and whose source still builds to them with this mercmac."""
    wanted = _normal(macros)
    if not wanted:
        return Recalled(None)
    matches = [r for r in records if _normal(r.macros) == wanted]
    matches.sort(key=lambda r: (r.port, r.address) != (port, address))  # stable: newest first
    stale = None
    for found in matches:
        why = _rebuilds(found, wanted)
        if not why:
            return Recalled(found)
        stale = stale or Recalled(None, found, why)
    return stale or Recalled(None)


def lookup(macros: dict[int, str], *, port: str | None = None,
           address: int | None = None) -> Record | None:
    """The record `recall` finds among all readable records; None when none fits."""
    return recall(macros, records(), port=port, address=address).record


def built(found: Record):
    """The recorded source compiled today as `flash` built it: with its own `target`,
    else the controller's model (a compiler Compilation)."""
    from mercmac.compiler import compile_source
    from mercmac.source import Source

    source = Source(found.file, found.source)
    compiled = compile_source(source)
    if compiled.program is not None and compiled.program.target is None and found.model:
        compiled = compile_source(source, found.model)
    return compiled


def _rebuilds(found: Record, wanted: dict[int, str]) -> str:
    """'' when the recorded source builds to `wanted` today, as `flash` built it; else why
    not, in a few words."""
    compiled = built(found)
    if compiled.program is None or compiled.report.has_errors:
        return "it has errors with this mercmac"
    if not builds_to(compiled.program, wanted):
        return "this mercmac lowers it to other macros"
    return ""


def builds_to(program, macros: dict[int, str]) -> bool:
    """Whether a compiled Program builds to exactly `macros` (slot -> line), each macro as
    the controller stores it."""
    lines = {slot: body for slot, body in map(mdtext.split_md, program.md_lines())}
    return _normal(lines) == _normal(macros)


def _normal(macros: dict[int, str]) -> dict[int, str]:
    """Slot -> the macro as the controller stores it; empty slots left out."""
    kept = {slot: mdtext.normal(text) for slot, text in macros.items()}
    return {slot: text for slot, text in kept.items() if text}


# -- reading one record ----------------------------------------------------------------------------

class _Unreadable(Exception):
    """A history file that is no record; the message says why."""


def _load(path: Path) -> Record:
    """The record in PATH; _Unreadable with the reason when it is none."""
    try:
        data = json.loads(_text(path))
    except RecursionError:
        raise _Unreadable("its JSON is nested too deeply") from None
    except ValueError as e:  # json.JSONDecodeError, and ints past Python's digit limit
        raise _Unreadable(f"it is not JSON ({e})") from None
    if not isinstance(data, dict):
        raise _Unreadable(f"it holds {_json_kind(data)}, not a JSON object")
    if not (_fits(data.get("format"), int) and data["format"] == FORMAT):  # not 1.0, not true
        said = data.get("format")
        said = f"format {said}" if _fits(said, int) else f"{_json_kind(said)} as its format"
        raise _Unreadable(f"it has {said}; this mercmac reads format {FORMAT}")
    fields = {k: v for k, v in data.items() if k != "format"}
    _check_fields(fields)
    entry = Record(**fields)
    try:
        when = entry.when
    except ValueError:
        raise _Unreadable(f"its time {entry.time[:40]!r} is not an ISO 8601 time") from None
    if when.utcoffset() is None:
        raise _Unreadable(f"its time {entry.time[:40]!r} has no UTC offset")
    return entry


def _text(path: Path) -> str:
    """The text of PATH if it is a regular file of at most MAX_BYTES in UTF-8; else _Unreadable.
    Read as a .mcm file is (source.read_bytes): opened without blocking, so that a FIFO
    cannot hold it up, and only when it is a regular file (not /dev/zero behind a link)."""
    try:
        data = read_bytes(str(path))
    except SourceError as e:
        raise _Unreadable(outfile.reason(e)) from None
    except OSError as e:
        raise _Unreadable(f"it cannot be read: {outfile.reason(e)}") from None
    if len(data) > MAX_BYTES:
        raise _Unreadable(f"it is {len(data):,} bytes: larger than a record may be "
                          f"({MAX_BYTES:,} bytes)")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise _Unreadable(f"it is not UTF-8 text (byte 0x{data[e.start]:02x} at offset "
                          f"{e.start})") from None


def _check_fields(data: dict) -> None:
    """_Unreadable unless `data` has each field of Record, of its declared type, and no other."""
    hints = typing.get_type_hints(Record, include_extras=True)
    for field in dataclasses.fields(Record):
        if field.name not in data:
            if field.default is dataclasses.MISSING:
                raise _Unreadable(f"it has no {field.name!r}")
        elif not _fits(data[field.name], hints[field.name]):
            raise _Unreadable(f"its {field.name!r} is {_said(data[field.name], hints[field.name])}"
                              f", not {_words(hints[field.name])}")
    unknown = sorted(set(data) - set(hints))
    if unknown:
        raise _Unreadable(f"it has a field no record has: {unknown[0][:40]!r}")


def _fits(value, hint) -> bool:
    """Whether a JSON value is of the type a field declares (str, PathText, int, X | None,
    list[X])."""
    args = typing.get_args(hint)
    if typing.get_origin(hint) is typing.Annotated:  # PathText
        return isinstance(value, str) and _unicode(value, args[1])
    if typing.get_origin(hint) in (typing.Union, types.UnionType):
        return any(_fits(value, arg) for arg in args)
    if typing.get_origin(hint) is list:
        return isinstance(value, list) and all(_fits(item, args[0]) for item in value)
    if hint is type(None):
        return value is None
    if hint is str:  # JSON's \ud800 escapes make strings no file can hold (nor a terminal show)
        return isinstance(value, str) and _unicode(value)
    return isinstance(value, hint) and not (hint is int and isinstance(value, bool))


def _unicode(text: str, errors: str = "strict") -> bool:
    try:
        text.encode("utf-8", errors)
    except UnicodeEncodeError:
        return False
    return True


_KIND_WORDS = {str: "text", int: "a whole number", float: "a number", bool: "true or false",
               list: "a list", dict: "an object", type(None): "null"}


def _words(hint) -> str:
    """'text', 'text or null', 'a list of text': a field's type in words."""
    args = typing.get_args(hint)
    if typing.get_origin(hint) is typing.Annotated:
        return _words(args[0])
    if typing.get_origin(hint) in (typing.Union, types.UnionType):
        return " or ".join(_words(arg) for arg in args)
    if typing.get_origin(hint) is list:
        return f"a list of {_words(args[0]).removeprefix('a ')}"
    return _KIND_WORDS[hint]


def _json_kind(value) -> str:
    return _KIND_WORDS.get(type(value), "something else")


def _said(value, hint) -> str:
    """What a value that does not fit `hint` is: 'null', 'a list holding a whole number'."""
    if typing.get_origin(hint) is list and isinstance(value, list):
        wrong = next(item for item in value if not _fits(item, typing.get_args(hint)[0]))
        return f"a list holding {_said(wrong, typing.get_args(hint)[0])}"
    if isinstance(value, str):
        return "text with a lone surrogate (\\ud800-\\udfff)"
    return _json_kind(value)


def _new_path(when: _dt.datetime, port: str, address: int) -> Path:
    stem = f"{when.strftime('%Y%m%d-%H%M%S-%f')}-{backup.port_tag(port)}-addr{address}"
    path, n = folder() / f"{stem}.json", 1
    while path.exists():
        n += 1
        path = folder() / f"{stem}-{n}.json"
    return path
