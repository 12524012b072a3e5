"""Reading a rig file: NAME.rig.toml -> a Rig, or the diagnostics of what is wrong with the
file itself (MR001 rig-file, MR003 rig-wire), each at its line and column.

The file is read as settings and scenarios are (mercmac.tomlfile): a regular file, at most
mercmac.source.MAX_BYTES, UTF-8 with an optional byte-order mark. A key mercmac does not
know is an error, not passed over: a misspelled `adress` must not leave a default.
"""
from __future__ import annotations

import os
import re
from typing import Any, NamedTuple

from mercmac.commands import MODELS
from mercmac.diagnostics import Report
from mercmac.rig import SUFFIX, is_rig_path  # noqa: F401 (is_rig_path: read here too)
from mercmac.rig.locate import Places, locate
from mercmac.rig.model import NAME_MAX, Controller, Line, LineKind, Rig, Wire
from mercmac.source import Source, Span, read_bytes
from mercmac.suggest import did_you_mean

TOP_KEYS = ("name", "box", "box_buttons", "wires", "joystick", "controllers")
CONTROLLER_KEYS = ("address", "model", "program")
BRANCHES = ("X", "Y", "Z")  # C-819.20 (X, Y through the Y-cable) and C-819.30 (X, Y, Z), §3.6
BUTTONS = (1, 2, 3, 4)  # the C-170.PB box: button n on input n (MS176E §4.5.1)
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
# ASCII only (re.ASCII): `\d` and `\w` would take `x.out١` (an Arabic-Indic one) too
_WIRE = re.compile(r"\s*(\w+)\.(in|out)(\d+)\s*(?:->|→)\s*(\w+)\.(in|out)(\d+)\s*\Z", re.ASCII)
PROGRAM_SUFFIX = ".mcm"  # in any case, as mercmac.files takes `PROG.MCM`


class RigFile(NamedTuple):
    """A rig file as read: its text, the rig (None when the file has errors), what is wrong
    with the file, and where its keys stand."""

    source: Source
    rig: Rig | None
    report: Report
    places: Places


def read_rig(path: str) -> RigFile:
    """The rig in the file at `path`; OSError when it cannot be read at all."""
    from mercmac import tomlfile

    data = read_bytes(path)
    try:
        text = tomlfile.decode(data)
    except tomlfile.TomlError as e:
        source = Source(path, data.decode("utf-8", errors="replace"))
        return _refused(source, Span(e.line or 1, e.column or 1), e.why)
    return parse_rig(Source(path, text))


def parse_rig(source: Source) -> RigFile:
    """The rig that `source` (a rig file's text) describes."""
    from mercmac import tomlfile

    try:
        table = tomlfile.loads(source.text)
    except tomlfile.TomlError as e:
        return _refused(source, Span(e.line or 1, e.column or 1), e.why)
    reader = _Reader(source, locate(source.text))
    rig = reader.rig(table)
    return RigFile(source, None if reader.report.has_errors else rig, reader.report,
                   reader.places)


def _refused(source: Source, span: Span, error: str) -> RigFile:
    report = Report(source.name)
    report.add("rig-file", span, "toml", error=error)
    return RigFile(source, None, report, Places({}, {}))


class _Reader:
    """Reads the TOML table of one rig file into a Rig, reporting what it cannot take."""

    def __init__(self, source: Source, places: Places):
        self.source, self.places = source, places
        self.report = Report(source.name)
        self.folder = os.path.dirname(os.path.abspath(source.name))

    def rig(self, table: dict) -> Rig:
        self._known(table, TOP_KEYS, ())
        tables = self._typed(table, "controllers", dict, "a table", {})
        controllers = self._controllers(tables)
        names = {name for name in tables if is_name(name)}  # also those with errors
        return Rig(os.path.abspath(self.source.name), self._name(table), controllers,
                   box=self._box(table, names), box_buttons=self._buttons(table),
                   joystick=self._joystick(table, names), wires=self._wires(table, names))

    # -- the parts --------------------------------------------------------------------------

    def _name(self, table: dict) -> str:
        """The rig's `name`, a name as a controller's is: `flash --backup DIR/` and `pull
        --rig` put it in file names, so '../x' or '/abs' would write outside the folder."""
        stem = os.path.basename(self.source.name)
        default = stem[:-len(SUFFIX)] if is_rig_path(stem) else stem
        name = self._typed(table, "name", str, "a string", default)
        if name is not default and not is_name(name):
            self.report.add("rig-file", self.places.of("name"), "rig-name", name=_shown(name),
                            longest=NAME_MAX)
            return default
        return name

    def _controllers(self, tables: dict) -> tuple[Controller, ...]:
        if not tables and not self.report.has_errors:
            self.report.add("rig-file", self.places.of("controllers"), "empty")
        found = []
        for name, entry in tables.items():
            path = ("controllers", name)
            if not is_name(name):
                self.report.add("rig-file", self.places.of(*path), "name", name=_shown(name),
                                longest=NAME_MAX)
            elif not isinstance(entry, dict):
                self._wrong(path, "a table: [controllers.NAME] with address, model, program")
            else:
                found.append(self._controller(name, entry))
        return tuple(c for c in found if c is not None)

    def _controller(self, name: str, entry: dict) -> Controller | None:
        path = ("controllers", name)
        self._known(entry, CONTROLLER_KEYS, path)
        where = f"in [controllers.{name}]"
        address = self._required(entry, path, "address", int, "a whole number 0-15", where)
        model = self._required(entry, path, "model", str, " or ".join(MODELS), where)
        program = self._required(entry, path, "program", str, "a .mcm path", where)
        if isinstance(model, str) and model.upper() not in MODELS:
            self._wrong(path + ("model",), " or ".join(MODELS))
        if program is not None:
            program = self._program(program, path + ("program",), name)
        if None in (address, model, program):
            return None
        return Controller(name, address, model.upper(), program, self.places.of(*path))

    def _program(self, program: str, path: tuple[str, ...], name: str) -> str | None:
        """The program's path, when it is a .mcm file in the rig's folder or below it
        (docs/rigs.md, "The rig file"); else None, reported at the key without a word of the
        file (never opened: a rig from elsewhere must not make `check` print /etc/passwd or
        ~/.aws/credentials)."""
        why = _why_refused(self.folder, program)
        if why is not None:
            self.report.add("rig-file", self.places.of(*path), "program", controller=name,
                            why=why)
            return None
        return os.path.join(self.folder, program)

    def _box(self, table: dict, names: set[str]) -> str | None:
        box = self._typed(table, "box", str, "a controller's name", None)
        return self._named(box, ("box",), "box", names)

    def _buttons(self, table: dict) -> tuple[int, ...]:
        buttons = self._typed(table, "box_buttons", list, "a list of buttons 1-4", list(BUTTONS))
        span = self.places.of("box_buttons")
        if "box_buttons" in table and "box" not in table:  # buttons of a box that is not there
            self.report.add("rig-file", span, "buttons-without-box")
        for i, button in enumerate(buttons):
            if type(button) is not int or button not in BUTTONS:
                self.report.add("rig-file", span, "button", button=_shown(repr(button)))
            elif button in buttons[:i]:
                self.report.add("rig-file", span, "button-twice", button=button)
        return tuple(dict.fromkeys(b for b in buttons if b in BUTTONS and type(b) is int))

    def _joystick(self, table: dict, names: set[str]) -> dict[str, str]:
        branches = self._typed(table, "joystick", dict, "a table of branches X, Y, Z", {})
        found = {}
        for branch, name in branches.items():
            path = ("joystick", branch)
            if branch not in BRANCHES:
                self.report.add("rig-file", self.places.of(*path), "branch", branch=branch)
            elif not isinstance(name, str):
                self._wrong(path, "a controller's name")
            elif self._named(name, path, f"joystick branch {branch}", names):
                found[branch] = name
        return found

    def _wires(self, table: dict, names: set[str]) -> tuple[Wire, ...]:
        texts = self._typed(table, "wires", list, 'a list of "x.out1 -> y.in1" strings', [])
        wires = (self._wire(text, self.places.string(("wires",), i), names)
                 for i, text in enumerate(texts))
        return tuple(w for w in wires if w is not None)

    def _wire(self, text: Any, span: Span, names: set[str]) -> Wire | None:
        parsed = _WIRE.match(text) if isinstance(text, str) else None
        if parsed is None:
            self.report.add("rig-wire", span, "syntax", text=_shown(repr(text)))
            return None
        where = f"the wire '{_shown(text.strip())}'"
        ends = [self._line(*parsed.group(1, 2, 3), span, where, names),
                self._line(*parsed.group(4, 5, 6), span, where, names)]
        if None in ends:
            return None
        wire = Wire(ends[0], ends[1], span)
        if (ends[0].kind, ends[1].kind) != (LineKind.OUT, LineKind.IN):
            self.report.add("rig-wire", span, "direction", wire=_shown(text.strip()))
        elif ends[0].controller == ends[1].controller:
            self.report.add("rig-wire", span, "loop", wire=str(wire))
        else:
            return wire
        return None

    def _line(self, name: str, kind: str, digits: str, span: Span, where: str,
              names: set[str]) -> Line | None:
        number = digits.lstrip("0")
        if not (len(number) == 1 and 1 <= int(number) <= 4):  # never int() of 5,000 digits
            self.report.add("rig-wire", span, "line", line=_shown(f"{name}.{kind}{digits}"),
                            kind=kind + "put")
        elif self._named(name, ("wires",), where, names, span):
            return Line(name, LineKind(kind), int(number), span)
        return None

    # -- keys and types -------------------------------------------------------------------

    def _named(self, name: str | None, path, where: str, names: set[str],
               span: Span | None = None) -> str | None:
        """`name` if it is a controller of the rig; else None, reported."""
        if name is None or name in names:
            return name
        said = did_you_mean(name, sorted(names)) if is_name(name) else ""
        self.report.add("rig-file", span or self.places.of(*path), "unknown-controller",
                        where=where, name=_shown(name), hint=f"; {said}" if said else "")
        return None

    def _known(self, table: dict, keys: tuple[str, ...], path: tuple[str, ...]) -> None:
        where = f"in [{'.'.join(path)}]" if path else "at the top of the rig file"
        for key in table:
            if key not in keys:
                said = did_you_mean(key, keys)
                self.report.add("rig-file", self.places.of(*path, key), "unknown", key=key,
                                where=where, keys=", ".join(keys), hint=f"{said} " if said else "")

    def _typed(self, table: dict, key: str, kind: type, expects: str, default):
        value = table.get(key, default)
        if value is default or (isinstance(value, kind) and type(value) is not bool):
            return value
        self._wrong((key,), expects)
        return default

    def _required(self, entry: dict, path, key: str, kind: type, expects: str, where: str):
        if key not in entry:
            self.report.add("rig-file", self.places.of(*path), "missing", key=key, where=where)
            return None
        if not isinstance(entry[key], kind) or type(entry[key]) is bool:
            self._wrong(path + (key,), expects)
            return None
        return entry[key]

    def _wrong(self, path: tuple[str, ...], expects: str) -> None:
        where = f"in [{'.'.join(path[:-1])}]" if len(path) > 1 else "at the top"
        self.report.add("rig-file", self.places.of(*path), "type", key=path[-1], where=where,
                        expects=expects)


def is_name(name: str) -> bool:
    """Whether `name` may name a controller: an identifier of ASCII letters, digits and '_',
    at most NAME_MAX characters."""
    return len(name) <= NAME_MAX and _NAME.match(name) is not None


def _why_refused(folder: str, program: str) -> str | None:
    """Why `program` (as the rig file writes it) is no .mcm file in `folder` or below it;
    None when it is one. Links are followed by name only (realpath reads no file): a link
    that stays in the folder is taken, one that leads out of it is not."""
    if "\0" in program:
        return "it holds a NUL character, which no file name has"
    if os.path.isabs(program) or os.path.splitdrive(program)[0]:
        return "it is an absolute path"
    path = os.path.join(folder, program)
    real, home = os.path.realpath(path), os.path.realpath(folder)
    if os.path.commonpath([real, home]) != home:
        return "it leads out of the rig file's folder"
    if not program.lower().endswith(PROGRAM_SUFFIX):
        return "it does not end in .mcm"
    if not real.lower().endswith(PROGRAM_SUFFIX):
        return "it is a link to a file that does not end in .mcm"
    return None


def program_path(rig_path: str, program: str) -> str | None:
    """The file that the rig file at `rig_path` names by `program` (a controller's value),
    as the reader takes it (_why_refused); None for a path the reader refuses."""
    folder = os.path.dirname(os.path.abspath(rig_path))
    return None if _why_refused(folder, program) is not None else os.path.join(folder, program)


def _shown(text: str, most: int = 60) -> str:
    """`text`, cut to its first `most` characters (a 5,000-digit wire is said, not echoed)."""
    return text if len(text) <= most else text[:most] + "…"
