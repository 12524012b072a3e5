"""What the language server offers where, through the real `mercmac lsp`.

- Completion by context: it offered the same 135 items after `MR `, `target `, `every `,
  in a comment and at the top level.
- "Add target" was a quick fix at every position of every file without `target`; no rule
  reports a missing target, so it is a source action now.
- Raw `[MCnn]` blocks (five of the eight examples) had no definition, references or
  hover: `EM11` -> `[MC11]`, and a slot's references include the calls of the named
  macro the compiler put there. Keywords, `every` durations and `[MCnn]` headers hover.
- A block with a syntax error fell out of the outline.
- A rename the server refuses came back as -32603 "ValueError: ..." with a traceback on
  stderr; it is RequestFailed (-32803) with the reason.
"""
from __future__ import annotations


import pytest

from helpers.compiling import compile_text
from helpers.lsp_client import next_notification

pytest.importorskip("pytest_lsp", reason="the test extra installs pytest-lsp")
from lsprotocol import types as t  # noqa: E402  (pytest-lsp brings it)
from helpers.lsp_wire import INITIALIZE, Server, frame, notification, request  # noqa: E402
from pytest_lsp import LanguageClient  # noqa: E402  (the client: tests/lsp/conftest.py)

URI = "file:///nonexistent-lsp16/features.mcm"
WAIT_S = 30.0
PROGRAM = """\
// a jog box
const SLOW = 5000
const FINE = 160

macro setup { SV SLOW, SA 100000 }   // speeds
autostart {
    call setup
    every 20ms {
        when 1 { MR FINE, WF 1 }
        TT
    }
}
"""
RAW = """\
// Mercury(TM) Macro File
[MC00] EM11,EM12
[MC11] XN1,EM12
macro scan @12 { MR 5 }
macro jog { call scan }
"""



async def _open(client: LanguageClient, text: str) -> None:
    client.text_document_did_open(t.DidOpenTextDocumentParams(
        text_document=t.TextDocumentItem(uri=URI, language_id="mcm", version=1, text=text)))
    await next_notification(client, t.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS, WAIT_S)


def _position(text: str, marked: str, nth: int = 0) -> t.Position:
    """Where `|` stands in `marked`, a piece of `text` (its `nth` occurrence)."""
    at = -1
    for _ in range(nth + 1):
        at = text.index(marked.replace("|", ""), at + 1)
    at += marked.index("|")
    line = text.count("\n", 0, at)
    return t.Position(line, at - (text.rfind("\n", 0, at) + 1))


def _at(text: str, marked: str, nth: int = 0) -> dict:
    return dict(text_document=t.TextDocumentIdentifier(uri=URI),
                position=_position(text, marked, nth))


def _lines(text: str, rng: t.Range) -> str:
    """The text a one-line range covers."""
    assert rng.start.line == rng.end.line
    return text.split("\n")[rng.start.line][rng.start.character:rng.end.character]


# -- completion ----------------------------------------------------------------------------

MNEMONIC, STORED_ONLY = "MR", "RT"  # RT cannot be stored in a macro (MS176E §6.4 RT)
CONTEXTS = [
    # (what is typed, the cursor at |), what must be offered, what must not
    ("target |", {"C-663", "C-863"}, {"MR", "macro", "SLOW"}),
    ("    every |", {"20ms", "100ms", "1s", "SLOW"}, {"MR", "when", "setup"}),
    ("    call |", {"setup", "go"}, {"MR", "SLOW", "call"}),
    ("    MR |", {"SLOW", "FINE"}, {"MR", "when", "setup"}),
    ("    MR 5 // a note |", set(), {"MR", "SLOW", "when"}),
    ("// a comment at the top |", set(), {"macro", "MR"}),
    ("|", {"target", "const", "macro", "autostart"}, {"MR", "when", "call"}),
    ("    |", {"call", "goto", "when", "repeat", "every", "MR", "EM"},
     {"target", "const", "macro", STORED_ONLY}),
    ("    MR 5, |", {"MR", "when"}, {"macro"}),
    ("    when 1 { |", {"MR", "call"}, {"macro"}),
    ("    when |", {"not", "FINE"}, {"MR", "macro"}),
    ("    TT |", set(), {"MR", "SLOW"}),
    ("const X = |", set(), {"SLOW", "MR"}),
    ("[MC05] |", {"MR", "EM", "XN"}, {"when", "macro", "SLOW", STORED_ONLY}),
    ("[MC05] XN1,|", {"MR", "EM"}, {"when", "SLOW"}),
    ("[MC05] XN1,MR |", set(), {"SLOW", "MR"}),
]


@pytest.mark.asyncio
@pytest.mark.parametrize("typed, offered, not_offered", CONTEXTS, ids=[c[0] for c in CONTEXTS])
async def test_completion_offers_what_may_stand_there(client: LanguageClient, typed, offered,
                                                      not_offered):
    block = typed.startswith("    ")
    line = typed.replace("|", "")
    text = PROGRAM + "macro go {\n" + line + "\n}\n" if block else PROGRAM + line + "\n"
    await _open(client, text)
    where = (PROGRAM + ("macro go {\n" if block else "")).count("\n")
    result = await client.text_document_completion_async(t.CompletionParams(
        text_document=t.TextDocumentIdentifier(uri=URI),
        position=t.Position(where, typed.index("|"))))
    labels = {i.label for i in result.items}
    assert offered <= labels, sorted(labels)[:20]
    assert not (not_offered & labels), not_offered & labels
    assert len(labels) < 135 or not offered


# -- code actions --------------------------------------------------------------------------

@pytest.mark.asyncio
async def test_add_target_is_a_source_action_not_a_quick_fix_everywhere(client: LanguageClient):
    await _open(client, PROGRAM)

    async def actions(only):
        return await client.text_document_code_action_async(t.CodeActionParams(
            text_document=t.TextDocumentIdentifier(uri=URI),
            range=t.Range(t.Position(8, 18), t.Position(8, 18)),
            context=t.CodeActionContext(diagnostics=[], only=only))) or []

    assert await actions([t.CodeActionKind.QuickFix]) == []  # the light bulb shows nothing
    offered = await actions([t.CodeActionKind.Source])
    assert {a.title for a in offered} == {"Add `target C-863`", "Add `target C-663`"}
    assert all(a.kind.startswith("source.") and a.kind != t.CodeActionKind.QuickFix
               for a in offered)
    assert all(a.kind != t.CodeActionKind.QuickFix for a in await actions(None))


# -- raw blocks: definition, references, hover -----------------------------------------------

@pytest.mark.asyncio
async def test_em_in_a_raw_line_goes_to_its_block(client: LanguageClient):
    await _open(client, RAW)
    found = await client.text_document_definition_async(t.DefinitionParams(
        **_at(RAW, "EM1|1")))
    assert [(loc.range.start.line, _lines(RAW, loc.range)) for loc in found] == [(2, "[MC11]")]
    pinned = await client.text_document_definition_async(t.DefinitionParams(
        **_at(RAW, "EM1|2")))
    assert [_lines(RAW, loc.range) for loc in pinned] == ["scan"]


@pytest.mark.asyncio
async def test_references_of_a_slot_are_its_ems_and_the_calls_of_the_macro_there(
        client: LanguageClient):
    await _open(client, RAW)
    for marked in ["EM1|2", "call sc|an", "macro sc|an"]:
        refs = await client.text_document_references_async(t.ReferenceParams(
            **_at(RAW, marked), context=t.ReferenceContext(include_declaration=True)))
        assert sorted((r.range.start.line, _lines(RAW, r.range)) for r in refs) == [
            (1, "EM12"), (2, "EM12"), (3, "scan"), (4, "scan")], marked
    header = await client.text_document_references_async(t.ReferenceParams(
        **_at(RAW, "[MC|11]"), context=t.ReferenceContext(include_declaration=False)))
    assert [(r.range.start.line, _lines(RAW, r.range)) for r in header] == [(1, "EM11")]


@pytest.mark.asyncio
async def test_references_follow_a_slot_the_compiler_allocated(client: LanguageClient):
    text = "macro auto { MR 1 }\nautostart { call auto }\n"
    slot = next(m.slot for m in compile_text(text).program.macros.values() if m.name == "auto")
    text += f"[MC30] EM{slot}\n"
    assert next(m.slot for m in compile_text(text).program.macros.values()
                if m.name == "auto") == slot
    await _open(client, text)
    refs = await client.text_document_references_async(t.ReferenceParams(
        **_at(text, "macro au|to"), context=t.ReferenceContext(include_declaration=False)))
    assert sorted(_lines(text, r.range) for r in refs) == [f"EM{slot}", "auto"]


@pytest.mark.asyncio
async def test_hover_on_a_raw_em_and_a_header_says_what_the_slot_holds_and_who_calls_it(
        client: LanguageClient):
    await _open(client, RAW)
    em = await client.text_document_hover_async(t.HoverParams(**_at(RAW, "EM1|1")))
    assert "MD11,XN1,EM12" in em.contents.value and "called by: MC00" in em.contents.value
    assert _lines(RAW, em.range) == "EM11"
    header = await client.text_document_hover_async(t.HoverParams(**_at(RAW, "[MC1|1]")))
    assert "MD11,XN1,EM12" in header.contents.value and "MC00" in header.contents.value
    scan = await client.text_document_hover_async(t.HoverParams(**_at(RAW, "EM1|2", 1)))
    assert "scan (MC12)" in scan.contents.value
    assert "called by: jog (MC01), MC11, MC00" in scan.contents.value


@pytest.mark.asyncio
async def test_hover_on_keywords_and_durations(client: LanguageClient):
    text = "target C-863\n" + PROGRAM.replace(
        "autostart {", "autostart {\n    repeat 2 { goto x }\n    when not 1 and 2 { TT }", 1
    ).replace("macro setup", "macro x {}\nmacro setup") + "// every repeat\n"
    await _open(client, text)
    for word in ["target", "const", "macro", "autostart", "call", "goto", "when", "repeat",
                 "every", "not", "and"]:
        marked = f"{word[0]}|{word[1:]}"
        hover = await client.text_document_hover_async(t.HoverParams(**_at(text, marked)))
        assert hover is not None and f"{word} " in hover.contents.value.split(":")[0], word
        assert _lines(text, hover.range) == word
    in_comment = await client.text_document_hover_async(t.HoverParams(**_at(text, "every r|epeat")))
    assert in_comment is None
    every = await client.text_document_hover_async(t.HoverParams(**_at(text, "2|0ms")))
    assert "20 ms = `WA20`" in every.contents.value
    assert "polls 50 times a second" in every.contents.value
    assert _lines(text, every.range) == "20ms"


# -- outline -----------------------------------------------------------------------------------

@pytest.mark.asyncio
async def test_a_block_with_a_syntax_error_stays_in_the_outline(client: LanguageClient):
    text = PROGRAM + "macro scan {\n    MR 5 6 7\n    WS 10\n}\nmacro after { TT }\n"
    await _open(client, text)
    assert client.diagnostics[URI]  # the broken line is reported
    found = await client.text_document_document_symbol_async(t.DocumentSymbolParams(
        text_document=t.TextDocumentIdentifier(uri=URI)))
    names = [s.name for s in found]
    assert {"scan", "after", "setup", "autostart", "SLOW"} <= set(names), names
    scan = next(s for s in found if s.name == "scan")
    assert _lines(text, scan.selection_range) == "scan"


# -- rename refusals -----------------------------------------------------------------------------

@pytest.mark.parametrize("new, reason", [("2fast", "'2fast' is not a name"),
                                         ("every", "'every' is not a name"),
                                         ("FINE", "a const named 'FINE' exists already")])
def test_a_refused_rename_is_request_failed_with_the_reason_and_no_traceback(new, reason):
    server = Server()
    try:
        server.write(frame(INITIALIZE))
        assert server.answer(1) is not None
        server.write(frame(notification("textDocument/didOpen", {"textDocument": {
            "uri": URI, "languageId": "mcm", "version": 1, "text": PROGRAM}})))
        where = _position(PROGRAM, "const SL|OW")
        server.write(frame(request(2, "textDocument/rename", {
            "textDocument": {"uri": URI}, "newName": new,
            "position": {"line": where.line, "character": where.character}})))
        answer = server.answer(2)
        assert answer["error"]["code"] == -32803  # RequestFailed (LSP 3.17)
        assert reason in answer["error"]["message"]
        assert "ValueError" not in answer["error"]["message"] and not answer["error"].get("data")
    finally:
        assert server.close() == 0
    assert b"Traceback" not in server.stderr and b"Error" not in server.stderr, \
        server.stderr.decode()
