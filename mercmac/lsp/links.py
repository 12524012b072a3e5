"""The programs a rig file names: where each controller's `program = "..."` value stands
in the rig file's text, and the file it means (document links; workspace symbols read
those programs too).

The path is the one the rig reader takes (mercmac.rig.load.program_path: relative to the
rig file, a .mcm in its folder or below; docs/rigs.md, "The rig file"); a path it refuses,
or a file that is not there, names nothing. The values are read from the TOML even when
the rig has other errors: a rig being written still links to its programs.
"""
from __future__ import annotations

import os
import re
from typing import NamedTuple

from mercmac.rig.load import program_path
from mercmac.rig.locate import locate
from mercmac.source import Source, Span

_VALUE = re.compile(r"""[ \t]*=[ \t]*("(?:[^"\\]|\\.)*"|'[^']*')""")


class Program(NamedTuple):
    """A controller's program: the span of its path in the rig file (inside the quotes)
    and the file's path."""

    controller: str
    span: Span
    path: str


def programs(source: Source) -> list[Program]:
    """The programs that the rig file `source` (its name the rig file's path) names and
    that exist, in the file's order."""
    from mercmac import tomlfile

    try:
        controllers = tomlfile.loads(source.text).get("controllers")
    except tomlfile.TomlError:
        return []
    if not isinstance(controllers, dict):
        return []
    places = locate(source.text)
    found = []
    for name, entry in controllers.items():
        written = entry.get("program") if isinstance(entry, dict) else None
        key = places.keys.get(("controllers", name, "program"))
        path = program_path(source.name, written) if isinstance(written, str) else None
        span = key and _value_span(source.line(key.line), key)
        if span and path and os.path.isfile(path):
            found.append(Program(name, span, path))
    return found


def _value_span(line: str, key: Span) -> Span | None:
    """The span inside the quotes of the string after `key =` on its line."""
    value = _VALUE.match(line, key.end_column - 1)
    if value is None:
        return None
    return Span(key.line, value.start(1) + 2, key.line, value.end(1))
