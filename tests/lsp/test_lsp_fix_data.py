"""The language server's quick fixes are the diagnostics' Fix data, the edits
`check --fix` makes, not a "did you mean" read back from the message: the quoted name
was searched for in the statement, and found inside the keyword before it."""
from __future__ import annotations


import pytest

pytest.importorskip("pytest_lsp", reason="the test extra installs pytest-lsp")
from lsprotocol import types as t  # noqa: E402  (pytest-lsp brings it)
from pytest_lsp import LanguageClient  # noqa: E402  (the client: tests/lsp/conftest.py)

from mercmac.compiler import checking, fixing  # noqa: E402
from mercmac.source import Source  # noqa: E402

URI = "file:///work/fix.mcm"



async def _actions(client: LanguageClient, text: str) -> list[t.CodeAction]:
    client.text_document_did_open(t.DidOpenTextDocumentParams(
        text_document=t.TextDocumentItem(uri=URI, language_id="mcm", version=1, text=text)))
    await client.wait_for_notification(t.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)
    everything = t.Range(t.Position(0, 0), t.Position(len(text.split("\n")), 0))
    return await client.text_document_code_action_async(t.CodeActionParams(
        text_document=t.TextDocumentIdentifier(uri=URI), range=everything,
        context=t.CodeActionContext(diagnostics=client.diagnostics[URI]))) or []


def _apply(text: str, edit: t.TextEdit) -> str:
    """An ASCII text with one edit made; a position past a line's end is that end, as
    editors take it."""
    lines = text.split("\n")
    starts = [sum(len(line) + 1 for line in lines[:n]) for n in range(len(lines))]

    def index(p: t.Position) -> int:
        line = min(p.line, len(lines) - 1)
        return starts[line] + min(p.character, len(lines[line]))

    return text[:index(edit.range.start)] + edit.new_text + text[index(edit.range.end):]


@pytest.mark.asyncio
async def test_the_quick_fix_replaces_the_name_not_the_same_letters_in_the_keyword(
        client: LanguageClient):
    text = "macro cab { TP }\nautostart { call ca }\n"
    (action,) = [a for a in await _actions(client, text) if a.kind == t.CodeActionKind.QuickFix]
    assert action.title == "Replace with 'cab'"
    fixed = _apply(text, action.edit.changes[URI][0])
    assert fixed == "macro cab { TP }\nautostart { call cab }\n"
    assert fixed == fixing.fix(Source("x", text), checking.choice_for(None)).after


@pytest.mark.asyncio
async def test_the_target_of_a_document_of_one_comment_goes_on_a_line_of_its_own(
        client: LanguageClient):
    text = "// only a comment"
    actions = await _actions(client, text)
    add = next(a for a in actions if a.title == "Add `target C-863`")
    assert _apply(text, add.edit.changes[URI][0]) == "// only a comment\ntarget C-863\n"


@pytest.mark.asyncio
async def test_every_fix_is_offered_and_each_but_the_safe_says_what_it_is(
        client: LanguageClient):
    """A safe fix is preferred; a guess (another command) and a suggestion that `check --fix`
    never makes are offered too, their titles saying so (docs/editors.md)."""
    text = "macro scan { TP }\nautostart { call scna, XM 1, LED 2 }\n"
    actions = [a for a in await _actions(client, text) if a.kind == t.CodeActionKind.QuickFix]
    offered = {a.title: a.is_preferred for a in actions}
    assert offered == {
        "Replace with 'scan'": True,
        "Replace with 'XF' (unsafe: a guess, check what it changes)": False,
        "Replace with 'CN' (suggestion: check --fix never makes it)": False,
    }
