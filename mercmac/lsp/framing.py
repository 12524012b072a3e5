"""LSP messages on a byte stream: `Content-Length: N` headers, a blank line, N bytes of JSON
(LSP specification, "Base Protocol"), read so that a bad frame costs that frame only.

pygls reads a header line at a time and trusts Content-Length: a length too small or too
big, one that is not a number or none at all put it out of step with the stream for good,
and the server, still running, answered nothing more. Here a frame that is
wrong is said once and skipped, and reading starts again at the next `Content-Length:`.
"""
from __future__ import annotations

import asyncio
import io
import json
import os
import re
import threading
from typing import BinaryIO, Callable, NamedTuple

HEADER = b"Content-Length:"
_HEADERS_END = b"\r\n\r\n"
# An RFC 7230 header field: a token, a colon, a value (spaces around it do not count).
_FIELD = re.compile(rb"([!#$%&'*+.^_`|~0-9A-Za-z-]+):[ \t]*(.*?)[ \t]*")
_FIELD_START = re.compile(rb"[!#$%&'*+.^_`|~0-9A-Za-z-]+(:|\Z)")  # a header being written
_LENGTH = re.compile(rb"[0-9]{1,10}")
# A header line cannot stand in JSON text (a raw CR/LF is not allowed in a string, and
# `Content-Length` outside one is not JSON), so one inside a body says its length was wrong.
_HEADER_LINE = re.compile(rb"Content-Length:[ \t]*[0-9]+[ \t]*\r\n")
# Header bytes before the blank line: LSP's two headers take under 100; past this it is
# garbage, and a bound keeps the search for the next header linear in what is skipped.
MAX_HEADERS = 1024
MAX_BODY = 256 * 1024 * 1024  # a 64 MB document escaped as JSON fits, with room


class Frame(NamedTuple):
    """What the stream gave: a message, or why bytes were skipped."""

    message: dict | None
    problem: str | None = None


class Frames:
    """Cuts a byte stream into messages; `feed` bytes as they come."""

    def __init__(self):
        self.buffer = bytearray()
        self.skipping = False  # between a bad frame and the next header: say it once
        self.scanned = 0  # how far a partial body was searched for a header line

    def feed(self, data: bytes) -> list[Frame]:
        """The messages (and problems) that `data` completes, in order."""
        self.buffer += data
        out: list[Frame] = []
        while (frame := self._next()) is not None:
            if frame.message is not None or not self.skipping:
                out.append(frame)
            self.skipping = frame.message is None
        return out

    def leftover(self) -> str | None:
        """What is wrong with the bytes left when the stream ends, if anything."""
        if not bytes(self.buffer).strip():
            return None
        return f"the input ended inside a message ({len(self.buffer):,} bytes left over)"

    def _next(self) -> Frame | None:
        """One message or problem from the front of the buffer; None until more bytes come."""
        buffer = self.buffer
        if not buffer:
            return None
        if not _FIELD_START.match(buffer):
            return self._skip(1, f"no message header at {_quote(bytes(buffer[:20]))}")
        end = buffer.find(_HEADERS_END, 0, MAX_HEADERS + len(_HEADERS_END))
        if end < 0:
            if len(buffer) <= MAX_HEADERS:
                return None  # the rest of the headers is on its way
            # No header that starts here or up to MAX_HEADERS before the end can end in time.
            return self._skip(len(buffer) - MAX_HEADERS,
                              f"more than {MAX_HEADERS:,} bytes of headers without a blank line")
        length, problem = _length(bytes(buffer[:end]))
        if problem:
            return self._skip(1, problem)
        return self._body(end + len(_HEADERS_END), length)

    def _body(self, start: int, length: int) -> Frame | None:
        """The message whose body starts at `start`, or a skip when its length is wrong."""
        buffer, stop = self.buffer, start + length
        if len(buffer) < stop:
            found = _HEADER_LINE.search(buffer, max(start, self.scanned - 32))
            self.scanned = len(buffer)
            if found is None:
                return None
            return self._skip(start, f"Content-Length {length:,} is more than the message "
                                     "(another header came before its end)")
        try:
            message = json.loads(bytes(buffer[start:stop]))
        except (ValueError, RecursionError):  # UnicodeDecodeError is a ValueError
            message = None
        if not isinstance(message, dict):
            return self._skip(start, f"the {length:,} bytes after the header are not a JSON "
                                     "object: the Content-Length may be wrong")
        del buffer[:stop]
        self.scanned = 0
        return Frame(message)

    def _skip(self, start: int, problem: str) -> Frame:
        """Drop the bytes before the next `Content-Length:` from `start` on (all but what
        may be the beginning of one when there is none yet)."""
        found = self.buffer.find(HEADER, start)
        cut = found if found >= 0 else max(start, len(self.buffer) - len(HEADER) + 1)
        del self.buffer[:cut]
        self.scanned = 0
        return Frame(None, f"bad input: {problem}; skipping to the next Content-Length header")


def _length(headers: bytes) -> tuple[int, str | None]:
    """The Content-Length of a header block, or what is wrong with the block."""
    lengths = []
    for line in headers.split(b"\r\n"):
        field = _FIELD.fullmatch(line)
        if field is None:
            return 0, f"not a header line: {_quote(line)}"
        if field[1].lower() == b"content-length":
            lengths.append(field[2])
    if len(lengths) != 1:
        return 0, "no Content-Length header" if not lengths else "two Content-Length headers"
    if not _LENGTH.fullmatch(lengths[0]):
        return 0, f"Content-Length {_quote(lengths[0])} is not a number of bytes"
    length = int(lengths[0])
    if length > MAX_BODY:
        return 0, f"Content-Length {length:,} is more than a message may have ({MAX_BODY:,})"
    return length, None


def _quote(data: bytes) -> str:
    shown = data[:40].decode("ascii", errors="backslashreplace")
    return repr(shown + ("..." if len(data) > 40 else ""))


async def serve(stream: BinaryIO, deliver: Callable[[dict], None],
                warn: Callable[[str], None]) -> str | None:
    """Give each message of `stream` to `deliver` and each problem to `warn`, until the
    stream ends; then what is wrong with the bytes left over, if anything. The bytes are
    read on a thread, so that they keep coming while a long check runs (and the edits of
    a burst are then applied in one go, mercmac.lsp.server)."""
    loop = asyncio.get_running_loop()
    frames, ended = Frames(), loop.create_future()

    def received(data: bytes) -> None:
        if not data and not ended.done():  # done: cancelled by the client's `exit`
            ended.set_result(frames.leftover())
        for frame in frames.feed(data):
            if frame.message is None:
                warn(frame.problem)
            else:
                deliver(frame.message)

    def pump() -> None:
        data = b"-"
        while data:
            data = _read(stream)
            try:
                loop.call_soon_threadsafe(received, data)
            except RuntimeError:  # the loop is closed: the server has exited
                return

    threading.Thread(target=pump, name="mercmac-lsp-stdin", daemon=True).start()
    return await ended


def _read(stream: BinaryIO) -> bytes:
    """What the stream has now (at most 64 kB), b"" at its end. A file is read through its
    descriptor: a thread blocked in a buffered read holds the buffer's lock, and the
    interpreter, closing stdin at exit, would abort on it."""
    try:
        return os.read(stream.fileno(), 65536)
    except (AttributeError, io.UnsupportedOperation):  # no descriptor (a test's BytesIO)
        return stream.read(65536)
    except (OSError, ValueError):  # closed under us: as good as ended
        return b""
