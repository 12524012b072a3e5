"""The language server's copy of a document stays the editor's.

An editor ends lines at LF, CRLF and CR only (LSP specification, "Text Documents"); pygls
also ended them at \\f, \\v, \\x1c-\\x1e, U+0085, U+2028 and U+2029, so an edit sent for one
line landed on another, and "Format Document" then moved it into another macro. Here an
editor-side model of the document (its own small implementation of LSP positions and
edits, UTF-16 units) drives the real `mercmac lsp` through pytest-lsp: after incremental
changes, formatting must give exactly what `mercmac fmt` writes for the editor's text, and
diagnostics must point at the editor's lines.
"""
from __future__ import annotations

import random
import re

import pytest
from click.testing import CliRunner

from helpers.paths import EXAMPLE_FILES, FOUR_MODES
from mercmac.cli import main as cli
from mercmac.compiler import compile_source
from mercmac.lsp.recheck import Rechecker
from mercmac.source import Source

pytest.importorskip("pytest_lsp", reason="the test extra installs pytest-lsp")
from lsprotocol import types as t  # noqa: E402  (pytest-lsp brings it)
from pytest_lsp import LanguageClient  # noqa: E402  (the client: tests/lsp/conftest.py)

URI = "file:///work/pages.mcm"


class Editor:
    """An editor's copy of a document: lines end at LF, CRLF or CR; a position's character
    counts UTF-16 code units and, past the end of its line, means the end of the line."""

    def __init__(self, text: str):
        self.text = text

    def _lines(self) -> list[tuple[int, int]]:
        """(start, end) offsets of each line, without its line end."""
        out, start, i = [], 0, 0
        while i < len(self.text):
            if self.text[i] in "\r\n":
                out.append((start, i))
                i += 2 if self.text.startswith("\r\n", i) else 1
                start = i
            else:
                i += 1
        return out + [(start, len(self.text))]

    def offset(self, position: t.Position) -> int:
        lines = self._lines()
        if position.line >= len(lines):
            return len(self.text)
        start, end = lines[position.line]
        units = 0
        for i in range(start, end):
            if units >= position.character:
                return i
            units += 2 if ord(self.text[i]) > 0xFFFF else 1
        return end

    def position(self, offset: int) -> t.Position:
        for number, (start, end) in reversed(list(enumerate(self._lines()))):
            if start <= offset:
                units = sum(2 if ord(c) > 0xFFFF else 1 for c in self.text[start:offset])
                return t.Position(number, units)
        raise AssertionError(offset)

    def replace(self, start: int, end: int, new: str) -> t.TextDocumentContentChangePartial:
        """Edit the text as a user does; the change the editor sends for it."""
        change = t.TextDocumentContentChangePartial(
            range=t.Range(self.position(start), self.position(end)), text=new)
        self.text = self.text[:start] + new + self.text[end:]
        return change

    def apply(self, edits: list[t.TextEdit]) -> None:
        """A server's edits, all against this version: the last one first."""
        spans = [(self.offset(e.range.start), self.offset(e.range.end), e.new_text) for e in edits]
        for start, end, new in sorted(spans, key=lambda s: s[:2], reverse=True):
            self.text = self.text[:start] + new + self.text[end:]


def _document(mark: str, end: str = "\n") -> str:
    return end.join([
        "// pages of a jog box",
        "macro a {",
        f"    MR   5   // page{mark}break",
        f"    MR 6 // two{mark}{mark}marks",
        "}",
        "macro b { MR 7 }",
        "macro c {",
        "    MR 8",
        "}",
        "",
    ])


MARKS = {"form feed": "\f", "vertical tab": "\v", "x1c": "\x1c", "x1d": "\x1d", "x1e": "\x1e",
         "NEL": "\x85", "line separator": "\u2028", "paragraph separator": "\u2029"}
DOCUMENTS = {name: _document(mark) for name, mark in MARKS.items()}
DOCUMENTS |= {
    "CR only": _document("", "\r"),
    "CR only with a form feed": _document("\f", "\r"),
    "CRLF with a line separator": _document("\u2028", "\r\n"),
    "mixed, a CR last": "macro a {\r\n    MR  5 // x\f\r}\nmacro b { MR 7 }\r"
                        "macro c {\n    MR 8\r}\r",
    "mixed, astral": "macro a {\r\n    MR  5 // 😀\u2028\r}\nmacro b { MR 7 }\r"
                     "macro c {\n    MR 8\n}\r",
}


def _fmt(tmp_path, text: str) -> str:
    """What `mercmac fmt FILE` writes for `text` saved as UTF-8."""
    path = tmp_path / "pages.mcm"
    path.write_bytes(text.encode("utf-8"))
    result = CliRunner().invoke(cli, ["fmt", str(path)])
    assert result.exit_code == 0, result.output
    return path.read_bytes().decode("utf-8")



def _open(client: LanguageClient, text: str) -> None:
    client.text_document_did_open(t.DidOpenTextDocumentParams(
        text_document=t.TextDocumentItem(uri=URI, language_id="mcm", version=1, text=text)))


def _change(client: LanguageClient, version: int, *changes) -> None:
    client.text_document_did_change(t.DidChangeTextDocumentParams(
        text_document=t.VersionedTextDocumentIdentifier(uri=URI, version=version),
        content_changes=list(changes)))


async def _format(client: LanguageClient) -> list[t.TextEdit]:
    return await client.text_document_formatting_async(t.DocumentFormattingParams(
        text_document=t.TextDocumentIdentifier(uri=URI),
        options=t.FormattingOptions(tab_size=4, insert_spaces=True))) or []


@pytest.mark.asyncio
@pytest.mark.parametrize("name", DOCUMENTS)
async def test_edits_then_format_document_give_what_fmt_writes(client: LanguageClient, name,
                                                                tmp_path):
    editor = Editor(DOCUMENTS[name])
    _open(client, editor.text)
    text = editor.text
    at = text.index("MR 7")  # macro b, below the marked lines
    first = editor.replace(at, at + len("MR 7"), "MR 77, WS 1")
    at = editor.text.index("MR 8")  # macro c, one change with two edits in it
    second = editor.replace(at + 3, at + 4, "88")
    at = editor.text.index("macro c")
    third = editor.replace(at, at, "macro d { MR 9 }\n")
    _change(client, 2, first)
    _change(client, 3, second, third)
    editor.apply(await _format(client))
    assert editor.text == _fmt(tmp_path, text.replace("MR 7", "MR 77, WS 1").replace(
        "MR 8", "MR 88").replace("macro c", "macro d { MR 9 }\nmacro c"))


@pytest.mark.asyncio
@pytest.mark.parametrize("name", ["CR only", "CR only with a form feed", "mixed, a CR last"])
async def test_format_document_replaces_the_whole_text_once(client: LanguageClient, name,
                                                            tmp_path):
    editor = Editor(DOCUMENTS[name])
    _open(client, editor.text)
    editor.apply(await _format(client))
    assert editor.text == _fmt(tmp_path, DOCUMENTS[name])
    assert editor.text.count("macro b") == 1


@pytest.mark.asyncio
@pytest.mark.parametrize("name", ["form feed", "NEL", "CR only", "CR only with a form feed",
                                  "mixed, a CR last", "mixed, astral"])
async def test_diagnostics_point_at_the_editors_lines(client: LanguageClient, name):
    text = DOCUMENTS[name].replace("MR 7", "MRR 7").replace("MR 8", "XX 8")
    editor = Editor(text)
    _open(client, text)
    await client.wait_for_notification(t.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)
    found = {(d.range.start.line, d.range.start.character) for d in client.diagnostics[URI]}
    wanted = [editor.position(text.index(word)) for word in ("MRR", "XX")]
    assert {(p.line, p.character) for p in wanted} <= found


def _line_ends_mixed(text: str, seed: int) -> str:
    """`text` with each line end LF, CRLF or CR at random."""
    rng = random.Random(seed)
    return "".join(line + rng.choice(["\n", "\r\n", "\r"]) for line in text.split("\n"))


@pytest.mark.parametrize("path", EXAMPLE_FILES[:6], ids=lambda p: p.name)
def test_the_recheck_counts_lines_as_the_compiler_does_with_mixed_line_ends(path):
    text = _line_ends_mixed(path.read_bytes().decode("utf-8", errors="replace"), len(path.name))
    checker = Rechecker("x")
    lines = re.findall(r"[^\r\n]*(?:\r\n|\r|\n)|[^\r\n]+$", text)  # with their ends
    for i in range(-1, len(lines)):
        edited = text if i < 0 else "".join(lines[:i] + lines[i + 1:])
        mine, theirs = checker.check(edited).compilation, compile_source(Source("x", edited))
        assert mine.report.items == theirs.report.items
        assert mine.program == theirs.program


@pytest.mark.asyncio
@pytest.mark.parametrize("end", ["\r", "\r\n", "\n"], ids=["CR", "CRLF", "LF"])
async def test_add_target_goes_below_the_leading_comments_with_the_files_line_end(
        client: LanguageClient, end):
    text = end.join(["// a jog box", "// for the bench", "", "macro a { MR 5 }", ""])
    editor = Editor(text)
    _open(client, text)
    await client.wait_for_notification(t.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)
    actions = await client.text_document_code_action_async(t.CodeActionParams(
        text_document=t.TextDocumentIdentifier(uri=URI),
        range=t.Range(t.Position(0, 0), t.Position(4, 0)),
        context=t.CodeActionContext(diagnostics=[])))
    editor.apply(next(a for a in actions if a.title == "Add `target C-863`").edit.changes[URI])
    assert editor.text == text.replace(f"{end}macro", f"{end}target C-863{end}macro")


def test_typing_in_a_comment_keeps_the_findings_and_takes_the_new_text():
    text = (FOUR_MODES).read_text(encoding="utf-8")
    at = text.index("//") + 2
    checker = Rechecker("x")
    for typed in ["", " n", " no", " not", " note", " note\r// more"]:
        edited = text[:at] + typed + text[at:]
        mine, theirs = checker.check(edited).compilation, compile_source(Source("x", edited))
        assert mine.source.text == edited
        assert mine.report.items == theirs.report.items and mine.program == theirs.program
