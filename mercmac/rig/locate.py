"""Where things stand in a rig file's text: tomllib gives values, not positions, so the
keys, table headers and the strings of arrays (the wires) are found here, line by line,
to give every rig diagnostic a line and column.

A small reader of the TOML a person writes: `[a.b]` headers, `key = value` lines, arrays
over several lines. What it cannot place (an inline table's insides) falls back to the
nearest key or header it could.
"""
from __future__ import annotations

import re
from typing import NamedTuple

from mercmac.source import Span, split_lines

Path = tuple[str, ...]

# One token of a line: a string (basic or literal), a comment, or an array bracket.
_TOKEN = re.compile(r'("(?:[^"\\]|\\.)*"|\'[^\']*\')|(#.*)|(\[)|(\])')
_HEADER = re.compile(r"\s*\[\s*([^\[\]#]+?)\s*\]\s*(?:#.*)?$")
_KEY = re.compile(r"\s*((?:[A-Za-z0-9_-]+|\"[^\"]*\"|'[^']*')(?:\s*\.\s*(?:[A-Za-z0-9_-]+|\"[^\"]*\"|'[^']*'))*)\s*=")
_PART = re.compile(r"[A-Za-z0-9_-]+|\"[^\"]*\"|'[^']*'")


class Places(NamedTuple):
    """Spans of what the file holds: a key or header by its dotted path, and the strings of
    an array by the array's path."""

    keys: dict[Path, Span]
    strings: dict[Path, list[Span]]

    def of(self, *path: str) -> Span:
        """The span of the key (or header) at `path`, else of the nearest enclosing one."""
        for n in range(len(path), 0, -1):
            if path[:n] in self.keys:
                return self.keys[path[:n]]
        return Span(1, 1, 1, 1)

    def string(self, path: Path, index: int) -> Span:
        """The span of the `index`th string of the array at `path` (its key if not found)."""
        found = self.strings.get(path, [])
        return found[index] if index < len(found) else self.of(*path)


def locate(text: str) -> Places:
    """The places of the keys, headers and array strings in TOML `text`."""
    places = Places({}, {})
    table: Path = ()
    array: Path | None = None
    depth = 0
    for number, line in enumerate(split_lines(text), 1):
        if array is None:
            table, array, depth, start = _statement(places, table, number, line)
        else:
            start = 0
        if array is not None:
            depth = _array_strings(places, array, number, line, start, depth)
            array = array if depth > 0 else None
    return places


def _statement(places: Places, table: Path, number: int, line: str):
    """Read a header or `key =` line; (table, array path or None, depth, column after `=`)."""
    header = _HEADER.match(line)
    if header:
        path = _parts(header.group(1))
        places.keys.setdefault(path, _span(number, line, header.start(1), header.end(1)))
        return path, None, 0, 0
    key = _KEY.match(line)
    if not key:
        return table, None, 0, 0
    path = table + _parts(key.group(1))
    places.keys.setdefault(path, _span(number, line, key.start(1), key.end(1)))
    rest = line[key.end():].lstrip()
    if rest.startswith("["):
        return table, path, 0, len(line) - len(rest)
    return table, None, 0, 0


def _array_strings(places: Places, path: Path, number: int, line: str, start: int,
                   depth: int) -> int:
    """Note the strings of an array's line from column `start`; the bracket depth after it."""
    for token in _TOKEN.finditer(line, start):
        string, comment, opening, closing = token.groups()
        if comment:
            break
        if string and depth == 1:
            places.strings.setdefault(path, []).append(
                _span(number, line, token.start(), token.end()))
        depth += 1 if opening else -1 if closing else 0
        if depth == 0:
            break
    return depth


def _parts(dotted: str) -> Path:
    return tuple(p.strip("\"'") for p in _PART.findall(dotted))


def _span(number: int, line: str, start: int, end: int) -> Span:
    return Span(number, start + 1, number, end + 1)
