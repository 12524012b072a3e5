"""A bad frame costs that frame only.

pygls trusted Content-Length: after one too small, too big, not a number or missing, the
server kept running and answered nothing more. Each kind of framing error is written raw
into a real `mercmac lsp`; the next well-formed request must be answered, the problem said
on stderr in one line, and no traceback printed.
"""
from __future__ import annotations

import json

import pytest

pytest.importorskip("pygls", reason="the lsp extra installs pygls")
from helpers.lsp_wire import INITIALIZE, OPEN, Server, frame, hover, notification  # noqa: E402

_BODY = json.dumps(hover(7)).encode()
BAD = {
    "Content-Length too small": b"Content-Length: 10\r\n\r\n" + _BODY,
    "Content-Length too big": b"Content-Length: 999\r\n\r\n" + _BODY,
    "Content-Length zero": b"Content-Length: 0\r\n\r\n" + _BODY,
    "Content-Length not a number": b"Content-Length: abc\r\n\r\n" + _BODY,
    "Content-Length negative": b"Content-Length: -5\r\n\r\n" + _BODY,
    "Content-Length of 40 digits": b"Content-Length: " + b"9" * 40 + b"\r\n\r\n" + _BODY,
    "no Content-Length": b"Content-Type: application/json\r\n\r\n" + _BODY,
    "no header at all": _BODY,
    "two Content-Length headers": b"Content-Length: 5\r\n" + frame(hover(7)),
    "half a header": b"Content-Len",
    "a header without its blank line": b"Content-Length: 20\r\n",
    "garbage bytes": bytes(range(256)) * 3,
    "not a JSON object": frame([1, 2, 3]),  # type: ignore[arg-type]
    "not JSON-RPC": frame({"hello": "world"}),
    "bad UTF-8": b"Content-Length: 4\r\n\r\n\xff\xfe\xfd\xfc",
}


def _said_without_traceback(server: Server) -> list[str]:
    """The lines the server wrote on stderr, none of them from a traceback."""
    text = bytes(server.stderr).decode("utf-8", errors="replace")
    assert "Traceback" not in text and 'File "' not in text
    return text.splitlines()


@pytest.mark.parametrize("name", BAD)
def test_after_a_bad_frame_the_next_request_is_answered(name):
    server = Server()
    try:
        server.write(BAD[name] + frame(INITIALIZE))
        answer = server.answer(1)
        assert answer is not None and "capabilities" in answer["result"], answer
        server.write(frame(notification("initialized", {})) + frame(OPEN))
        server.write(BAD[name] + frame(hover(2)))
        answer = server.answer(2)
        assert answer is not None and "MR" in answer["result"]["contents"]["value"]
    finally:
        server.close()
    said = _said_without_traceback(server)
    assert all(line.startswith("mercmac: language server: ") for line in said)
    assert len([line for line in said if "bad input" in line or "JSON-RPC" in line]) == 2


@pytest.mark.parametrize("cut", [5, 30], ids=["in the header", "in the body"])
def test_input_that_ends_inside_a_message_exits_1_with_a_message(cut):
    server = Server()
    try:
        server.write(frame(INITIALIZE))
        assert server.answer(1) is not None
        server.write(frame(hover(2))[:cut])
    finally:
        code = server.close()
    assert code == 1
    said = _said_without_traceback(server)
    assert said[-1].startswith("mercmac: language server: the input ended inside a message")


def test_a_request_with_bad_params_is_answered_with_an_error():
    server = Server()
    try:
        server.write(frame(INITIALIZE))
        assert server.answer(1) is not None
        server.write(frame({"jsonrpc": "2.0", "id": 2, "method": "textDocument/hover",
                            "params": {"position": "nowhere"}}))
        answer = server.answer(2)
        assert answer is not None and answer["error"]["code"] == -32602  # Invalid Params
    finally:
        server.close()
    assert "Invalid Params" in _said_without_traceback(server)[-1]


def test_a_cancel_of_an_answered_request_is_not_logged():
    """Editors cancel requests the server has answered already (VS Code does it on every
    fast typist's hover): nothing went wrong, so the log the user opens stays quiet."""
    server = Server()
    try:
        server.write(frame(INITIALIZE))
        assert server.answer(1) is not None
        server.write(frame(notification("initialized", {})) + frame(OPEN) + frame(hover(2)))
        assert server.answer(2) is not None
        server.write(frame(notification("$/cancelRequest", {"id": 2})) + frame(hover(3)))
        assert server.answer(3) is not None
    finally:
        server.close()
    assert _said_without_traceback(server) == []
