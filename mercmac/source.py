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


class Source:
    """A file's text, its name as given by the user, and its lines."""

    __slots__ = ("name", "text", "_lines")

    def __init__(self, name: str, text: str):
        self.name, self.text = name, text
        self._lines: list[str] | None = None

    def __repr__(self) -> str:
        return f"Source({self.name!r}, {len(self.text)} characters)"

    def line(self, number: int) -> str:
        """Line `number` (1-based) as the parser counts lines: split at LF only."""
        if self._lines is None:  # split once: a diagnostic per line must not rescan the file
            self._lines = self.text.split("\n")
        lines = self._lines
        return lines[number - 1].removesuffix("\r") if 0 < number <= len(lines) else ""


# Byte-order marks, longest first: the UTF-32 LE mark begins with the UTF-16 LE one.
_BOMS = ((b"\xff\xfe\x00\x00", "utf-32-le"), (b"\x00\x00\xfe\xff", "utf-32-be"),
         (b"\xef\xbb\xbf", "utf-8"), (b"\xff\xfe", "utf-16-le"), (b"\xfe\xff", "utf-16-be"))


def decode(data: bytes) -> str:
    """Text of a .mcm file: UTF-8, else Windows-1252; UTF-16/32 when a BOM or the NULs say so.

    MMCRun is a Windows program and writes the '(TM)' sign of its header
    comment (MS176E §3.8.6, Example 4) as the single byte 0x99. Notepad may
    save "Unicode" (UTF-16 LE with a BOM). Whatever is left with NUL
    characters is not text; the parser says so.
    """
    for bom, codec in _BOMS:
        if data.startswith(bom):
            return data[len(bom):].decode(codec, errors="replace")
    if b"\x00" in data[:4096]:
        codec = _utf16_without_bom(data[:4096])
        if codec:
            return data.decode(codec, errors="replace")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        return data.decode("cp1252", errors="replace")


def _utf16_without_bom(head: bytes) -> str | None:
    """'utf-16-le' or '-be' when most bytes at odd (even) places are NUL and none at the
    others, as in mostly-ASCII text saved as UTF-16 without a BOM."""
    half = len(head) // 2
    if half < 2:
        return None
    even, odd = head[0::2].count(0) / half, head[1::2].count(0) / half
    if odd > 0.6 and even == 0:
        return "utf-16-le"
    if even > 0.6 and odd == 0:
        return "utf-16-be"
    return None


def read_source(path: str) -> Source:
    """Read a file (or '-' for standard input); OSError propagates to the CLI."""
    if path == "-":
        import sys

        return Source("<stdin>", decode(sys.stdin.buffer.read()))
    with open(path, "rb") as f:
        return Source(path, decode(f.read()))
