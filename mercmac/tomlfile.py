"""Reading a TOML file: the one reader of settings (mercmac.config), scenarios
(mercmac.sim.scenario) and rig files (mercmac.rig.load), with one set of guards.

    path --read_text: a regular file, capped, UTF-8 (or UTF-16 with its mark)--> text
         --loads: tomllib (tomli on Python 3.10), every failure a TomlError with its place--> table

Only a regular file is read, and at most mercmac.source.MAX_BYTES of it (read_bytes: a FIFO or
a link to /dev/zero is named, not waited on). TOML 1.0 files are UTF-8; a leading UTF-8
byte-order mark is read past, as ruff and Cargo read one (Windows editors write it), and a
file that starts with a UTF-16 mark (Notepad's "Unicode") says which text it is. Line ends
are LF, CRLF or a lone CR, read alike (docs/cli.md). Each caller words a TomlError its own way.

tomllib is imported when a file is read, never at import: `check` of .mcm files starts
without it (benchmarks/check_latency.py).
"""
from __future__ import annotations

import codecs
import re
from typing import NamedTuple

# tomllib words each syntax error "... (at line 3, column 7)" or "(at end of document)"
_AT = re.compile(r"\s*\(at (?:line (\d+), column (\d+)|end of document)\)")
# a decimal integer longer than int() converts (sys.get_int_max_str_digits(): 4300 digits)
_LONG_NUMBER = re.compile(r"[0-9][0-9_]{4300,}")
_UTF16_MARKS = (codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)


class TomlError(ValueError):
    """Why a text is no TOML that mercmac reads, in words that stand alone after the file's
    name; `line` and `column` (1-based) say where, when that is known."""

    def __init__(self, why: str, line: int | None = None, column: int | None = None):
        super().__init__(why)
        self.why, self.line, self.column = why, line, column


class TomlFile(NamedTuple):
    """A TOML file's text (line ends as written) and its table."""

    text: str
    table: dict


def read(path: str) -> TomlFile:
    """The TOML file at `path`: OSError (mercmac.source.SourceError included) when it
    cannot be read; TomlError when it is not TOML."""
    text = read_text(path)
    return TomlFile(text, loads(text))


def read_text(path: str) -> str:
    """The text of the TOML file at `path`; OSError when it cannot be read, TomlError when
    its bytes are not text."""
    from mercmac.source import read_bytes

    return decode(read_bytes(path))


def decode(data: bytes) -> str:
    """The text of a TOML file's bytes: UTF-8 with or without a byte-order mark, or UTF-16
    after its mark; TomlError at the first byte that does not read."""
    utf16 = data.startswith(_UTF16_MARKS)
    try:
        return data.decode("utf-16" if utf16 else "utf-8-sig")  # either drops its mark
    except UnicodeDecodeError as e:
        line = data[:e.start].count(b"\n") + 1
        if utf16:
            raise TomlError("not UTF-16 text, though it starts with a UTF-16 byte-order mark "
                            f"(byte {e.start}): TOML files are UTF-8") from None
        raise TomlError(f"byte 0x{data[e.start]:02X} at line {line} is not UTF-8, and TOML "
                        "files are UTF-8", line, 1) from None


def loads(text: str) -> dict:
    """The table that `text` holds; TomlError, with its place where known, when it is no
    TOML or more than mercmac reads."""
    from mercmac.source import to_lf

    tomllib = _tomllib()
    text = to_lf(text)  # a lone CR ends a line too (docs/cli.md), as in every other file read
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        at, why = _AT.search(str(e)), f"not valid TOML: {_AT.sub('', str(e))}"
        if at and at.group(1):
            raise TomlError(why, int(at.group(1)), int(at.group(2))) from None
        lines = text.split("\n")  # at the end of the document: its last line, past its end
        raise TomlError(why, len(lines), len(lines[-1]) + 1) from None
    except ValueError:  # int() refuses more digits than sys.get_int_max_str_digits()
        raise _too_long(text) from None
    except RecursionError:  # tomllib reads nested arrays and inline tables by recursion
        raise TomlError("arrays or tables nested too deeply to read") from None


def _too_long(text: str) -> TomlError:
    """The TomlError for a number of too many digits, at the first such number."""
    found = _LONG_NUMBER.search(text)
    where = (None, None) if found is None else _place(text, found.start())
    return TomlError("a number has far too many digits to read", *where)


def _place(text: str, offset: int) -> tuple[int, int]:
    """The 1-based line and column of `offset` in `text` (LF line ends)."""
    line_start = text.rfind("\n", 0, offset) + 1
    return text.count("\n", 0, offset) + 1, offset - line_start + 1


def _tomllib():
    """tomllib, or on Python 3.10 (which has none) the tomli it grew from (pyproject.toml
    depends on tomli there)."""
    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10
        import tomli as tomllib
    return tomllib

