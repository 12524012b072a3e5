"""Random framing into a real `mercmac lsp` (the commands' fuzz
tests, for LSP framing).

Each example writes noise (frames with a wrong Content-Length, half headers, headers
that are not numbers, garbage bytes, good frames among them), in writes split at random
points, then one well-formed hover. The promises: the hover is answered, or the server
exits non-zero with a message; nothing waits forever (every wait is bounded), and no
traceback is printed. One server serves the examples while it lives.

`MERCMAC_FUZZ_EXAMPLES=2000 pytest tests/lsp/test_fuzz_lsp_framing.py` searches harder.
"""
from __future__ import annotations

import itertools
import json
import os
import time

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

pytest.importorskip("pygls", reason="the lsp extra installs pygls")
from helpers.budgets import fuzz_budget  # noqa: E402
from helpers.lsp_wire import INITIALIZE, OPEN, Server, frame, hover, notification  # noqa: E402

BUDGET = settings(
    max_examples=fuzz_budget(60),
    deadline=None,
    derandomize="MERCMAC_FUZZ_EXAMPLES" not in os.environ,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
HARMLESS = notification("$/mercmac/fuzz", {"text": "MR 5 // \u00e9\u2028\U0001f600"})
_BODY = json.dumps(HARMLESS).encode()
NUMBERS = st.one_of(st.integers(0, 2 * len(_BODY)), st.integers(0, 10 ** 12))


@st.composite
def noise(draw) -> bytes:
    """One piece of bad (or good) framing."""
    kind = draw(st.sampled_from(["length", "header", "half", "garbage", "good", "no header"]))
    if kind == "length":  # a body with a random Content-Length
        return b"Content-Length: %d\r\n\r\n" % draw(NUMBERS) + _BODY
    if kind == "header":  # a Content-Length that is no number, or no blank line after it
        value = draw(st.binary(max_size=12))
        end = draw(st.sampled_from([b"\r\n\r\n", b"\r\n", b"\n\n", b""]))
        return b"Content-Length: " + value + end + draw(st.sampled_from([_BODY, b""]))
    if kind == "half":  # a frame cut anywhere
        whole = frame(HARMLESS)
        return whole[:draw(st.integers(0, len(whole)))]
    if kind == "garbage":
        return draw(st.binary(max_size=300))
    if kind == "no header":
        return _BODY
    return frame(HARMLESS)


def _split(data: bytes, cuts: list[int]) -> list[bytes]:
    points = sorted({0, len(data), *(c % (len(data) + 1) for c in cuts)})
    return [data[a:b] for a, b in zip(points, points[1:])]


_ids = itertools.count(100)


@pytest.fixture(scope="module")
def servers():
    """The live server (a new one after one exits); each is checked when it ends."""
    alive: list[Server] = []
    yield alive
    for server in alive:
        server.close()
        _check_stderr(server)


def _started() -> Server:
    server = Server()
    server.write(frame(INITIALIZE))
    assert server.answer(1) is not None
    server.write(frame(notification("initialized", {})) + frame(OPEN))
    return server


def _check_stderr(server: Server) -> str:
    said = bytes(server.stderr).decode("utf-8", errors="replace")
    assert "Traceback" not in said and 'File "' not in said, said
    return said


@BUDGET
@given(pieces=st.lists(noise(), min_size=1, max_size=5),
       cuts=st.lists(st.integers(0, 10 ** 6), max_size=6), pause=st.booleans())
def test_random_framing_then_a_hover_is_answered_or_the_server_exits_saying_why(
        servers, pieces, cuts, pause):
    if not servers or servers[-1].process.poll() is not None:
        servers.append(_started())
    server, number = servers[-1], next(_ids)
    for part in _split(b"".join(pieces) + frame(hover(number)), cuts):
        server.write(part)
        if pause:
            time.sleep(0.002)  # let the server read what it has: a frame arrives in pieces
    answer = server.answer(number)
    if answer is None:  # it exited: non-zero, and said why
        assert server.close() != 0
        assert "mercmac: language server:" in _check_stderr(server)
    else:
        assert "MR" in answer["result"]["contents"]["value"], answer
