"""Every position the language server sends or reads goes through one conversion
(mercmac.lsp.document), in the units the client chose.

The compiler counts characters (code points); an editor counts UTF-16 units unless it
offers UTF-8 or UTF-32 (`general.positionEncodings`). An emoji is one character and two
UTF-16 units (four UTF-8 bytes), and "Format Document" on a file whose last line held
one, without a final newline, cut the last character in two: `…// 🚀 go\\no`.

Hypothesis writes programs with astral characters, combining marks and other non-ASCII
text wherever text may stand (comments, a suppression comment that cannot be read, a
broken line), line ends LF, CRLF and CR, with and without a final newline. An editor's
model of the document (written here, independently, per encoding) then reads every range
the real `mercmac lsp` sends: diagnostics, formatting, definition, references, rename,
document symbols, code actions and hover ranges must cover exactly the text they name,
and positions the editor sends (hover, completion, code action ranges) are read alike.
"""
from __future__ import annotations

import json
import os
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

pytest.importorskip("pygls", reason="the lsp extra installs pygls")
from helpers.budgets import fuzz_budget  # noqa: E402
from helpers.lsp_wire import Server, frame, notification, request  # noqa: E402

from helpers.cli import cli  # noqa: E402
from mercmac.fmt import format_text  # noqa: E402
from mercmac.lsp.document import Document  # noqa: E402

BUDGET = settings(max_examples=fuzz_budget(25),
                  deadline=None, derandomize="MERCMAC_FUZZ_EXAMPLES" not in os.environ,
                  suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                         HealthCheck.function_scoped_fixture])
# Text that is not ASCII: astral (emoji, a CJK extension B ideograph, a musical symbol),
# combining marks, BMP letters and symbols.
ODD = ["\U0001f680", "\U0001f600", "\U00020000", "\U0001d11e", "e\u0301", "a\u0308\u0323",
       "\u00e4", "\u2122", "\u4e2d", "\u00b5s", " ", "go"]
ENCODINGS = ["utf-16", "utf-8", "utf-32"]
# A program where names, slots, a did-you-mean and a missing target stand; {0}, {1}, ...
# are where odd text goes (comments), and each line ends with a random line end.
LINES = [
    "// a jog box {0}",
    "const FINE = 160 // {1}",
    "const SLOW = 5000",
    "macro setup {{ SV SLOW, SA 100000, CP 1 }} // {2} mercmac: ignore[{3}]",
    "autostart {{",
    "    call setup",
    "    goto run",
    "}}",
    "macro run @5 {{  // {4}",
    "    every 20ms {{",
    "        when 1 {{ MR FINE, WF 1 }}",
    "        when 2 {{ MRR 5 }} // {5}",
    "    }}",
    "}}",
    "[MC11] XN1,EM5,EM12 // {6}",
    "[MC12] EM11,JN2000",
]
BROKEN = "    MR 5 {0} WS"  # a broken line: the parser reports the odd text


@st.composite
def documents(draw) -> str:
    """A program with odd text in its comments, random line ends, maybe a broken line,
    and a last line that holds odd text, maybe without a final newline."""
    odd = st.lists(st.sampled_from(ODD), max_size=4).map("".join)
    fills = [draw(odd) for _ in range(7)]
    fills[3] = draw(st.sampled_from(["MM015", "no-such-rule", "undefined-macro", ""]))
    lines = [line.format(*fills) for line in LINES]
    if draw(st.booleans()):
        lines.insert(draw(st.integers(5, 12)), BROKEN.format(draw(odd) or "\U0001f680"))
    lines.append("// end " + draw(odd) + draw(st.sampled_from(ODD)))
    ends = [draw(st.sampled_from(["\n", "\r\n", "\r"])) for _ in lines]
    last = draw(st.sampled_from(["", "\n", "\r\n", "\r"]))
    return "".join(line + end for line, end in zip(lines[:-1], ends)) + lines[-1] + last


class Editor:
    """An editor's copy of a document: lines end at LF, CRLF or CR; a position counts
    units of `encoding` (a UTF-16 surrogate pair is two, a UTF-8 byte one)."""

    def __init__(self, text: str, encoding: str):
        self.text, self.encoding = text, encoding
        self.lines, start, i = [], 0, 0  # (start, end) offsets, without the line end
        while i < len(text):
            if text[i] in "\r\n":
                self.lines.append((start, i))
                i += 2 if text.startswith("\r\n", i) else 1
                start = i
            else:
                i += 1
        self.lines.append((start, len(text)))

    def units(self, chars: str) -> int:
        if self.encoding == "utf-32":
            return len(chars)
        return len(chars.encode("utf-16-le")) // 2 if self.encoding == "utf-16" else \
            len(chars.encode("utf-8"))

    def offset(self, position: dict) -> int:
        start, end = self.lines[position["line"]]
        for i in range(start, end + 1):
            used = self.units(self.text[start:i])
            if used >= position["character"]:
                assert used == position["character"], f"{position} splits a character"
                return i
        raise AssertionError(f"{position} is past the end of its line")

    def position(self, offset: int) -> dict:
        number = max(n for n, (start, _) in enumerate(self.lines) if start <= offset)
        return {"line": number, "character": self.units(self.text[self.lines[number][0]:offset])}

    def covered(self, range_: dict) -> str:
        return self.text[self.offset(range_["start"]):self.offset(range_["end"])]

    def spanned(self, line: int, column: int, end_line: int, end_column: int) -> str:
        """The text of a compiler span (1-based, counting characters), clamped as LSP
        clamps a position past its line's end."""
        def at(number: int, col: int) -> int:
            if number > len(self.lines):
                return len(self.text)
            start, end = self.lines[number - 1]
            return min(start + col - 1, end)
        return self.text[at(line, column):at(end_line or line, end_column or column + 1)]

    def apply(self, edits: list[dict]) -> str:
        spans = [(self.offset(e["range"]["start"]), self.offset(e["range"]["end"]), e["newText"])
                 for e in edits]
        text = self.text
        for start, end, new in sorted(spans, key=lambda s: s[:2], reverse=True):
            text = text[:start] + new + text[end:]
        return text


class Session:
    """One real `mercmac lsp` for a test, a new document per example."""

    def __init__(self, encoding: str):
        self.server, self.number, self.encoding = Server(), 1, encoding
        offered = [] if encoding == "utf-16" else [encoding, "utf-16"]
        capabilities = {"general": {"positionEncodings": offered}} if offered else {}
        answer = self.ask("initialize", {"capabilities": capabilities})
        assert answer["capabilities"].get("positionEncoding", "utf-16") == encoding
        self.server.write(frame(notification("initialized", {})))

    def ask(self, method: str, params: dict):
        self.number += 1
        self.server.write(frame(request(self.number, method, params)))
        answer = self.server.answer(self.number)
        assert answer is not None and "error" not in answer, (method, answer)
        return answer["result"]

    def open(self, text: str) -> tuple[str, list[dict]]:
        self.number += 1
        uri = f"file:///nonexistent-lsp16/probe-{self.number}.mcm"
        self.server.write(frame(notification("textDocument/didOpen", {"textDocument": {
            "uri": uri, "languageId": "mcm", "version": 1, "text": text}})))
        published = self.server.wait(lambda m: m.get("method") == "textDocument/publishDiagnostics"
                                     and m["params"]["uri"] == uri, "diagnostics")
        return uri, published["params"]["diagnostics"]

    def at(self, uri: str, position: dict, **more) -> dict:
        return {"textDocument": {"uri": uri}, "position": position, **more}


@pytest.fixture(params=ENCODINGS)
def session(request):
    opened = Session(request.param)
    yield opened
    assert opened.server.close() == 0
    assert b"Traceback" not in opened.server.stderr


def _inside(editor: Editor, word: str, nth: int = 0) -> dict:
    """The position one character into the `nth` `word` of the text."""
    at = -1
    for _ in range(nth + 1):
        at = editor.text.index(word, at + 1)
    return editor.position(at + 1)


@BUDGET
@given(text=documents())
def test_every_range_sent_covers_the_text_it_names(session: Session, text: str, tmp_path):
    editor = Editor(text, session.encoding)
    uri, published = session.open(text)
    _diagnostics_cover_what_check_marks(editor, published, tmp_path)
    _formatting_gives_what_fmt_writes(session, editor, uri)
    _names_and_slots_are_found_where_they_stand(session, editor, uri)
    _symbols_select_their_names(session, editor, uri)
    _code_actions_edit_the_right_text(session, editor, uri)
    session.server.write(frame(notification("textDocument/didClose",
                                            {"textDocument": {"uri": uri}})))


def _diagnostics_cover_what_check_marks(editor: Editor, published: list[dict],
                                        folder: Path) -> None:
    path = folder / "probe.mcm"
    path.write_bytes(editor.text.encode("utf-8"))
    result = cli("check", "--format", "json", path)
    wanted = sorted((d["code"], d["line"] - 1, editor.spanned(
        d["line"], d["column"], d["end_line"], d["end_column"]))
        for d in json.loads(result.output)["diagnostics"])
    got = sorted((d["code"], d["range"]["start"]["line"], editor.covered(d["range"]))
                 for d in published)
    assert got == wanted


def _formatting_gives_what_fmt_writes(session: Session, editor: Editor, uri: str) -> None:
    edits = session.ask("textDocument/formatting", {
        "textDocument": {"uri": uri}, "options": {"tabSize": 4, "insertSpaces": True}})
    try:
        formatted = format_text(editor.text)
    except Exception:  # fmt refuses a file with syntax errors; so does the server
        assert edits is None
        return
    assert editor.apply(edits or []) == formatted


def _names_and_slots_are_found_where_they_stand(session: Session, editor: Editor,
                                                uri: str) -> None:
    for word, nth, definition in [("setup", 1, "setup"), ("FINE", 1, "FINE"),
                                  ("EM12", 0, "[MC12]"), ("EM5", 0, "run")]:
        at = _inside(editor, word, nth)
        found = session.ask("textDocument/definition", session.at(uri, at))
        assert [editor.covered(loc["range"]) for loc in found] == [definition]
        refs = session.ask("textDocument/references", session.at(
            uri, at, context={"includeDeclaration": True}))
        assert definition in {editor.covered(loc["range"]) for loc in refs}
        hover = session.ask("textDocument/hover", session.at(uri, at))
        assert editor.covered(hover["range"]) == word
    edit = session.ask("textDocument/rename", session.at(uri, _inside(editor, "FINE"),
                                                         newName="STEP"))
    assert [editor.covered(e["range"]) for e in edit["changes"][uri]] == ["FINE", "FINE"]


def _symbols_select_their_names(session: Session, editor: Editor, uri: str) -> None:
    symbols = session.ask("textDocument/documentSymbol", {"textDocument": {"uri": uri}})
    names = {s["name"]: editor.covered(s["selectionRange"]) for s in symbols}
    assert names["setup"] == "setup" and names["FINE"] == "FINE" and names["run"] == "run"
    assert names["MC11"] == "[MC11]"
    for s in symbols:
        editor.covered(s["range"])  # every position falls between characters


def _code_actions_edit_the_right_text(session: Session, editor: Editor, uri: str) -> None:
    everything = {"start": {"line": 0, "character": 0}, "end": editor.position(len(editor.text))}
    actions = session.ask("textDocument/codeAction", {
        "textDocument": {"uri": uri}, "range": everything, "context": {"diagnostics": []}})
    replace = [a for a in actions if a["title"].startswith("Replace with")]
    assert [editor.covered(e["range"]) for a in replace
            for e in a["edit"]["changes"][uri]] == ["MRR"]
    target = next(a for a in actions if a["title"] == "Add `target C-863`")
    added = Editor(editor.apply(target["edit"]["changes"][uri]), editor.encoding)
    assert added.text.split("target C-863")[0] == editor.text[:editor.lines[1][0]]


@pytest.mark.parametrize("encoding", ENCODINGS)
def test_positions_in_a_comment_after_astral_characters_are_read_in_the_clients_units(
        encoding):
    text = "macro a { MR 5 } // \U0001f680\U0001f680 MR\r\nmacro b { MR 6 }"
    session = Session(encoding)
    try:
        editor = Editor(text, encoding)
        uri, _ = session.open(text)
        in_comment = editor.position(text.index(" MR\r") + 3)
        assert session.ask("textDocument/hover", session.at(uri, in_comment)) is None
        completion = session.ask("textDocument/completion", session.at(uri, in_comment))
        assert completion["items"] == []
        on_mr = session.ask("textDocument/hover", session.at(uri, _inside(editor, "MR 6")))
        assert editor.covered(on_mr["range"]) == "MR"
    finally:
        assert session.server.close() == 0


@BUDGET
@given(text=documents(), encoding=st.sampled_from(ENCODINGS))
def test_the_conversion_round_trips_every_character_boundary(text: str, encoding: str):
    from pygls.workspace.position_codec import PositionCodec

    document = Document("file:///x.mcm", text, position_codec=PositionCodec(encoding))
    editor = Editor(text, encoding)
    for number, (start, end) in enumerate(editor.lines, 1):
        for index in range(start, end + 1):
            column = index - start + 1
            position = document.position(number, column)
            assert json.loads(json.dumps({"line": position.line, "character": position.character})) \
                == editor.position(index)
            assert document.spot(position) == (number, column)
            assert document.offset_at(position) == index
    assert document.position(len(editor.lines) + 1, 1) == document.end()


@pytest.mark.parametrize("encoding", ENCODINGS)
def test_a_syntax_error_after_astral_characters_is_marked_whole(encoding):
    text = "macro a {\r\n    MR 5 \U0001f680\U0001f680 WS\r\n}\rmacro b { MRR 7 } // \u00e4\U0001f600"
    session = Session(encoding)
    try:
        editor = Editor(text, encoding)
        _, published = session.open(text)
        marked = {editor.covered(d["range"]) for d in published}
        assert "\U0001f680" in marked and "MRR" in marked, marked
    finally:
        assert session.server.close() == 0
