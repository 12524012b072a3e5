"""Source text and positions: what every diagnostic and instruction points at."""
from __future__ import annotations

from typing import NamedTuple


class Span(NamedTuple):
    """A 1-based line/column range in one source file."""

    line: int
    column: int
    end_line: int = 0
    end_column: int = 0

    def __str__(self) -> str:
        return f"{self.line}:{self.column}"


class Source(NamedTuple):
    """A file's text, its name as given by the user, and its lines."""

    name: str
    text: str

    def line(self, number: int) -> str:
        lines = self.text.splitlines()
        return lines[number - 1] if 0 < number <= len(lines) else ""


def decode(data: bytes) -> str:
    """Text of a .mcm file: UTF-8 (with or without BOM), else Windows-1252.

    MMCRun is a Windows program and writes the '(TM)' sign of its header
    comment (MS176E §3.8.6, Example 4) as the single byte 0x99.
    """
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError:
        return data.decode("cp1252", errors="replace")


def read_source(path: str) -> Source:
    """Read a file (or '-' for standard input); OSError propagates to the CLI."""
    if path == "-":
        import sys

        return Source("<stdin>", decode(sys.stdin.buffer.read()))
    with open(path, "rb") as f:
        return Source(path, decode(f.read()))
