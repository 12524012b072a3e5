"""A real `mercmac lsp` process fed raw bytes, for the framing tests.

The client side frames and reads messages itself (LSP "Base Protocol"), so that a test can
also write what no client library would: a wrong Content-Length, half a header, garbage.
Every wait is bounded: a server that hangs fails the test instead of hanging it.
"""
from __future__ import annotations

import json
import os
import queue
import subprocess
import sys
import threading
from typing import Callable


WAIT_S = 30.0  # generous: the machine may be busy; a hang still ends the test
URI = "file:///work/wire.mcm"
TEXT = "macro a {\n    MR 5, WS 10\n}\n"


def frame(message: dict, length: int | None = None) -> bytes:
    body = json.dumps(message).encode()
    return b"Content-Length: %d\r\n\r\n" % (len(body) if length is None else length) + body


def request(number: int, method: str, params: dict | None = None) -> dict:
    return {"jsonrpc": "2.0", "id": number, "method": method, "params": params or {}}


def notification(method: str, params: dict) -> dict:
    return {"jsonrpc": "2.0", "method": method, "params": params}


INITIALIZE = request(1, "initialize", {"capabilities": {}})
OPEN = notification("textDocument/didOpen", {"textDocument": {
    "uri": URI, "languageId": "mcm", "version": 1, "text": TEXT}})


def hover(number: int) -> dict:
    """A hover on `MR` of TEXT: its answer names the command."""
    return request(number, "textDocument/hover", {"textDocument": {"uri": URI},
                                                  "position": {"line": 1, "character": 5}})


class Server:
    """`mercmac lsp` as a subprocess; `answer(id)` waits for the response to a request."""

    def __init__(self):
        self.process = subprocess.Popen(
            [sys.executable, "-m", "mercmac", "lsp"], stdin=subprocess.PIPE,
            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        self.messages: queue.Queue = queue.Queue()
        self.stderr = bytearray()
        threading.Thread(target=self._read, daemon=True).start()
        self._stderr_reader = threading.Thread(
            target=lambda: self.stderr.extend(self.process.stderr.read()), daemon=True)
        self._stderr_reader.start()

    def write(self, data: bytes) -> None:
        self.process.stdin.write(data)
        self.process.stdin.flush()

    def answer(self, number: int) -> dict | None:
        """The response to request `number`; None when the server exits first."""
        return self.wait(lambda m: m.get("id") == number and "method" not in m, f"request {number}")

    def wait(self, wanted: Callable[[dict], bool], what: str,
             wait_s: float = WAIT_S) -> dict | None:
        """The first message that is `wanted`; None when the server exits first."""
        while True:
            try:
                message = self.messages.get(timeout=wait_s)
            except queue.Empty:
                raise AssertionError(f"nothing for {what} in {wait_s:.0f} s: "
                                     "the server hangs") from None
            if message is None or wanted(message):
                return message

    def close(self) -> int:
        """Close stdin and wait for the exit code (killed after WAIT_S); `stderr` is then
        complete (on a busy machine the reader may not have run yet when the process ends)."""
        try:
            self.process.stdin.close()
        except BrokenPipeError:
            pass
        try:
            return self.process.wait(timeout=WAIT_S)
        finally:
            self.process.kill()
            self.process.wait()
            self._stderr_reader.join(WAIT_S)

    def _read(self) -> None:
        data = bytearray()
        fd = self.process.stdout.fileno()
        while chunk := os.read(fd, 65536):
            data += chunk
            while (end := data.find(b"\r\n\r\n")) >= 0:
                length = int(data[:end].split(b"Content-Length:")[1].split(b"\r\n")[0])
                if len(data) < end + 4 + length:
                    break
                self.messages.put(json.loads(data[end + 4:end + 4 + length]))
                del data[:end + 4 + length]
        self.messages.put(None)
