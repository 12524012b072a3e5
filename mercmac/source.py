"""Source text and positions: what every diagnostic and instruction points at."""
from __future__ import annotations

import errno
import os
import re
import stat
import sys
from typing import NamedTuple

from mercmac.errors import InputError
from mercmac.outfile import kind

# The one definition of a line end in mercmac (docs/cli.md): LF, CRLF or a lone CR, mixed freely,
# as the LSP specification and editors count lines. Form feeds, vertical tabs, U+0085,
# U+2028 and U+2029 end no line (str.splitlines would split there; editors do not).
LINE_END = re.compile(r"\r\n|\r|\n")


def split_lines(text: str, keepends: bool = False) -> list[str]:
    """TEXT's lines without their ends; the last is what follows the last line end.
    With KEEPENDS, each line with its end, as str.splitlines(keepends=True) gives them."""
    if keepends:
        ends = [m.end() for m in LINE_END.finditer(text)]
        return [text[a:b] for a, b in zip([0, *ends], [*ends, len(text)]) if a < b]
    return LINE_END.split(text) if "\r" in text else text.split("\n")


def to_lf(text: str) -> str:
    """TEXT with every line end written LF: the same lines and columns (what the parser reads)."""
    return LINE_END.sub("\n", text) if "\r" in text else text


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
        """Line `number` (1-based), without its end (LINE_END)."""
        if self._lines is None:  # split once: a diagnostic per line must not rescan the file
            self._lines = split_lines(self.text)
        lines = self._lines
        return lines[number - 1] if 0 < number <= len(lines) else ""


# -- reading a file's bytes ----------------------------------------------------------------------

# The largest .mcm file read: 32 macros of 16 commands fit in a few kB, and the largest file a
# person keeps (comments, names, rigs) in well under a MB; the cap stops a device such as
# /dev/zero, or a wrong file, from filling the memory.
MAX_BYTES = 16 * 1024 * 1024


class SourceError(OSError):
    """A file mercmac does not read: not a regular file, or too large. An OSError, so that
    every `cannot read FILE: reason` place words it (`reason` reads `strerror`)."""

    def __init__(self, path: str, why: str):
        super().__init__(errno.EINVAL, why, path)


def read_bytes(path: str) -> bytes:
    """The bytes of a .mcm file ('-': standard input): a regular file only, at most MAX_BYTES.

    The file is opened without blocking (O_NONBLOCK), so that opening a FIFO with no writer
    cannot hang, and its kind is taken from what was opened (fstat), not from the name.
    """
    if path == "-":
        if sys.stdin is None:  # started with standard input closed (`<&-`)
            raise SourceError("-", "standard input is closed")
        return _capped(sys.stdin.buffer, "standard input")
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0)
                 | getattr(os, "O_BINARY", 0))
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise SourceError(path, f"it is {kind(st.st_mode)}, not a regular file")
        if st.st_size > MAX_BYTES:
            raise SourceError(path, _too_large(st.st_size))
        if hasattr(os, "O_NONBLOCK"):
            os.set_blocking(fd, True)
        f = open(fd, "rb")
    except BaseException:
        os.close(fd)
        raise
    with f:
        return _capped(f, path)


def _capped(f, name: str) -> bytes:
    """All of F, or SourceError once it holds more than MAX_BYTES (a file may grow, and
    standard input or a /proc file says no size beforehand)."""
    data = f.read(MAX_BYTES + 1)
    if len(data) > MAX_BYTES:
        raise SourceError(name, _too_large(None))
    return data


def _too_large(size: int | None) -> str:
    """'it is 20.5 MB: larger than mercmac reads (16 MB)'."""
    cap = f"mercmac reads ({MAX_BYTES // 2**20} MB)"
    if size is None:
        return f"it holds more than {cap}"
    return f"it is {size / 2**20:.1f} MB: larger than {cap}"


def refuse_larger(name: str, text: str) -> None:
    """SourceError when `text` is more (as UTF-8) than mercmac reads from a file: a file's
    text that an editor holds is taken as read_bytes takes the file."""
    # at most 4 bytes a character: a shorter text is not encoded (an editor's, at each key)
    size = len(text.encode("utf-8", "surrogatepass")) if len(text) > MAX_BYTES // 4 else 0
    if size > MAX_BYTES:
        raise SourceError(name, _too_large(size))


def read_source(path: str) -> Source:
    """Read a file (or '-' for standard input); OSError (SourceError included) propagates."""
    return Source("<stdin>" if path == "-" else path, decode(read_bytes(path)))


# -- bytes to text --------------------------------------------------------------------------------

class Encoding(str):
    """The codec a file was read with (a str, as `bytes.decode` takes it) and the byte-order
    mark it begins with: `write` gives back a text's bytes in the file's own encoding."""

    bom: bytes

    def __new__(cls, codec: str, bom: bytes = b"") -> Encoding:
        self = super().__new__(cls, codec)
        self.bom = bom
        return self

    def write(self, text: str) -> bytes:
        """TEXT as the file holds it: the BOM, then the text in the codec (strict)."""
        return self.bom + text.encode(self)

    def read(self, data: bytes, errors: str = "strict") -> str:
        """The text of DATA, its BOM left out."""
        return data[len(self.bom):].decode(self, errors)


class EncodingError(InputError):
    """Bytes that do not read in the file's encoding: writing the text back would change them."""


# Byte-order marks, longest first: the UTF-32 LE mark begins with the UTF-16 LE one. The
# UTF-8 mark is left to Python's utf-8-sig codec, which reads and writes it.
_BOMS = ((b"\xff\xfe\x00\x00", Encoding("utf-32-le", b"\xff\xfe\x00\x00")),
         (b"\x00\x00\xfe\xff", Encoding("utf-32-be", b"\x00\x00\xfe\xff")),
         (b"\xef\xbb\xbf", Encoding("utf-8-sig")),
         (b"\xff\xfe", Encoding("utf-16-le", b"\xff\xfe")),
         (b"\xfe\xff", Encoding("utf-16-be", b"\xfe\xff")))


def encoding_of(data: bytes) -> Encoding:
    """A .mcm file's encoding: UTF-8, else Windows-1252; UTF-16/32 when a BOM or the NULs
    say so.

    MMCRun is a Windows program and writes the '(TM)' sign of its header
    comment (MS176E §3.8.6, Example 4) as the single byte 0x99. Notepad may
    save "Unicode" (UTF-16 LE with a BOM). Whatever is left with NUL
    characters is not text; the parser says so.
    """
    for bom, encoding in _BOMS:
        if data.startswith(bom):
            return encoding
    if b"\x00" in data[:4096]:
        codec = _utf16_without_bom(data[:4096])
        if codec:
            return Encoding(codec)
    try:
        data.decode("utf-8")
    except UnicodeDecodeError:
        return Encoding("cp1252")
    return Encoding("utf-8")


def decode(data: bytes) -> str:
    """Text of a .mcm file to check: a byte that does not read becomes U+FFFD (see
    `encoding_of`); `decode_exact` is for text that is written back."""
    return encoding_of(data).read(data, errors="replace")


def decode_exact(data: bytes) -> tuple[str, Encoding]:
    """A file's text and encoding such that `encoding.write(text) == data`, or EncodingError
    naming the first byte that does not read (`fmt` never writes U+FFFD back)."""
    encoding = encoding_of(data)
    try:
        text = encoding.read(data)
    except UnicodeDecodeError as e:
        raise EncodingError(_undecodable(encoding, e)) from None
    if encoding.write(text) != data:  # every codec above round-trips; a guard, not a case
        raise EncodingError(f"its bytes do not read back the same as {_codec_name(encoding)}")
    return text, encoding


def _undecodable(encoding: Encoding, e: UnicodeDecodeError) -> str:
    """'byte 0x81 at line 3, column 9 is not Windows-1252 (nor UTF-8): character maps to
    <undefined>'."""
    before = split_lines(e.object[:e.start].decode(encoding, errors="replace"))
    bad = e.object[e.start:e.end]
    what = " ".join(f"0x{b:02X}" for b in bad)
    noun, verb = ("byte", "is") if len(bad) == 1 else ("bytes", "are")
    return (f"{noun} {what} at line {len(before)}, column {len(before[-1]) + 1} {verb} not "
            f"{_codec_name(encoding)}: {e.reason}")


def _codec_name(encoding: Encoding) -> str:
    """'Windows-1252', 'UTF-16-BE', ..., as a person names them."""
    return {"utf-8-sig": "UTF-8 (the file begins with a UTF-8 byte-order mark)",
            "cp1252": "Windows-1252 (nor UTF-8)"}.get(encoding, encoding.upper())


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
