"""Views of a file through the real `mercmac lsp`: semantic tokens, folding ranges,
signature help, a rig file's links to its programs and workspace symbols (docs/editors.md,
"The language server").

- Tokens come from the AST: a mnemonic is `function` + defaultLibrary, a macro `function`
  (declaration where defined), a const `variable` + readonly, a slot (`[MCnn]`, a pin, the
  number of `EMn`) `macro`, a number `number`; a raw line's tokens carry `raw`.
- Each feature answers on every example and on a broken file, with ranges inside the text.
"""
from __future__ import annotations

import itertools
import shutil
import sys
from pathlib import Path

import pytest

from helpers.lsp_client import next_notification
from helpers.paths import EXAMPLE_FILES, ROOT

pytest_lsp = pytest.importorskip("pytest_lsp", reason="the test extra installs pytest-lsp")
from lsprotocol import types as t  # noqa: E402  (pytest-lsp brings it)
from pytest_lsp import ClientServerConfig, LanguageClient  # noqa: E402

URI = "file:///nonexistent-lsp-views/views.mcm"
RASTER = ROOT / "examples" / "rigs" / "raster"
PROGRAM = """\
// a jog box
// two speeds
const SLOW = 5000
[MC11] XN1,EM12
macro scan @12 { MR 5 }
macro jog {
    call scan
    every 20ms {
        when 1 { MR SLOW, WF 1 }
        repeat 3 {
            TT
        }
    }
}
"""
_TYPING = itertools.count()  # a document per signature asked for
BROKEN = PROGRAM.replace("    call scan\n", "    call scan\n    MR ((( \n") + "autostart {\n  SV"


@pytest_lsp.fixture(config=ClientServerConfig(
    server_command=[sys.executable, "-m", "mercmac", "lsp", "--stdio"]))
async def client(lsp_client: LanguageClient):
    """A client that keeps the server's capabilities (the legend of its tokens)."""
    result = await lsp_client.initialize_session(
        t.InitializeParams(capabilities=t.ClientCapabilities()))
    lsp_client.server_capabilities = result.capabilities
    yield
    await lsp_client.shutdown_session()


async def _open(client: LanguageClient, text: str, uri: str = URI) -> None:
    waiting = next_notification(client, t.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)
    client.text_document_did_open(t.DidOpenTextDocumentParams(text_document=t.TextDocumentItem(
        uri=uri, language_id="toml" if uri.endswith(".toml") else "mcm", version=1, text=text)))
    await waiting


def _doc(uri: str = URI) -> t.TextDocumentIdentifier:
    return t.TextDocumentIdentifier(uri=uri)


async def _tokens(client: LanguageClient, uri: str = URI) -> list[tuple]:
    """(line, character, length, type, modifiers) of each token, positions made absolute."""
    legend = client.server_capabilities.semantic_tokens_provider.legend
    answer = await client.text_document_semantic_tokens_full_async(
        t.SemanticTokensParams(text_document=_doc(uri)))
    data = answer.data if answer else []
    found, line, character = [], 0, 0
    for i in range(0, len(data), 5):
        delta_line, delta_char, length, kind, bits = data[i:i + 5]
        line += delta_line
        character = character + delta_char if delta_line == 0 else delta_char
        found.append((line, character, length, legend.token_types[kind],
                      frozenset(m for n, m in enumerate(legend.token_modifiers) if bits >> n & 1)))
    return found


def _named(text: str, found: list[tuple]) -> set[tuple]:
    """(the text, type, modifiers) of each token."""
    lines = text.split("\n")
    return {(lines[line][at:at + length], kind, mods) for line, at, length, kind, mods in found}


def _units(text: str) -> int:
    return len(text.encode("utf-16-le")) // 2


def _inside(text: str, line: int, character: int) -> bool:
    lines = text.split("\n")
    return 0 <= line < len(lines) and 0 <= character <= _units(lines[line].rstrip("\r"))


# -- declared ------------------------------------------------------------------------------

@pytest.mark.asyncio
async def test_each_view_is_declared(client: LanguageClient):
    caps = client.server_capabilities
    legend = caps.semantic_tokens_provider.legend
    assert {"function", "variable", "macro", "number"} <= set(legend.token_types)
    assert {"declaration", "readonly", "defaultLibrary", "raw"} <= set(legend.token_modifiers)
    assert caps.semantic_tokens_provider.full
    assert caps.folding_range_provider
    assert set(caps.signature_help_provider.trigger_characters) == {" ", ","}
    assert caps.document_link_provider is not None
    assert caps.workspace_symbol_provider


# -- semantic tokens -----------------------------------------------------------------------

F, V, M, N = "function", "variable", "macro", "number"
DECL, RO, LIB, RAW = "declaration", "readonly", "defaultLibrary", "raw"


@pytest.mark.asyncio
async def test_tokens_say_what_each_word_is(client: LanguageClient):
    await _open(client, PROGRAM)
    found = await _tokens(client)
    named = _named(PROGRAM, found)
    assert {("SLOW", V, frozenset({RO, DECL})), ("SLOW", V, frozenset({RO})),
            ("[MC11]", M, frozenset({DECL, RAW})), ("XN", F, frozenset({LIB, RAW})),
            ("1", N, frozenset({RAW})), ("EM", F, frozenset({LIB, RAW})),
            ("12", M, frozenset({RAW})), ("scan", F, frozenset({DECL})), ("12", M, frozenset()),
            ("MR", F, frozenset({LIB})), ("5", N, frozenset()), ("jog", F, frozenset({DECL})),
            ("scan", F, frozenset()), ("20ms", N, frozenset()), ("3", N, frozenset()),
            ("TT", F, frozenset({LIB}))} <= named
    assert not {word for word, *_ in named} & {"macro", "call", "every", "when", "const"}
    starts = [(line, at) for line, at, *_ in found]
    assert starts == sorted(set(starts))


@pytest.mark.asyncio
async def test_tokens_of_a_broken_file_are_those_of_what_parses(client: LanguageClient):
    await _open(client, BROKEN)
    named = _named(BROKEN, await _tokens(client))
    assert {("SLOW", V, frozenset({RO, DECL})), ("scan", F, frozenset({DECL})),
            ("TT", F, frozenset({LIB}))} <= named


@pytest.mark.asyncio
async def test_a_rig_file_has_no_tokens(client: LanguageClient, tmp_path: Path):
    rig = tmp_path / "a.rig.toml"
    rig.write_text('[controllers.x]\naddress = 0\nmodel = "C-863"\nprogram = "x.mcm"\n')
    await _open(client, rig.read_text(), rig.as_uri())
    assert await _tokens(client, rig.as_uri()) == []


# -- folding -------------------------------------------------------------------------------

@pytest.mark.asyncio
async def test_blocks_and_comment_runs_fold(client: LanguageClient):
    await _open(client, PROGRAM)
    ranges = await client.text_document_folding_range_async(
        t.FoldingRangeParams(text_document=_doc()))
    found = {(r.start_line, r.end_line, r.kind) for r in ranges}
    # the comment run, `macro jog`, `every`, `repeat`; one-line blocks do not fold
    assert found == {(0, 1, t.FoldingRangeKind.Comment), (5, 12, None), (7, 11, None),
                     (9, 10, None)}


# -- signature help ------------------------------------------------------------------------

async def _signature(client: LanguageClient, text: str, typed: str) -> t.SignatureHelp | None:
    """Signature help at the end of `typed`, a line added to a block of `text` (a document
    of its own: one test asks several times)."""
    whole = text + "macro typing {\n" + typed + "\n}\n"
    uri = URI.replace("views", f"typing-{next(_TYPING)}")
    await _open(client, whole, uri)
    return await client.text_document_signature_help_async(t.SignatureHelpParams(
        text_document=_doc(uri), position=t.Position(whole.count("\n") - 2, len(typed))))


@pytest.mark.asyncio
@pytest.mark.parametrize("typed", ["    MR ", "    MR -5", "    SV SLOW, MR ", "    when 1 { MR "])
async def test_signature_of_the_command_typed(client: LanguageClient, typed):
    (said,) = (await _signature(client, PROGRAM, typed)).signatures
    assert said.label == "MR n" and said.parameters[0].label == "n"
    assert "Move relative" in said.documentation.value  # the hover's words
    argument = said.parameters[0].documentation.value
    assert "-999999999..999999999 counts (C-863) or steps (C-663)" in argument


@pytest.mark.asyncio
async def test_signature_follows_the_files_model(client: LanguageClient):
    async def said(text, typed):
        (found,) = (await _signature(client, text, typed)).signatures
        return found.label, found.parameters[0].documentation.value

    label, argument = await said("target C-663\n", "    DC ")
    assert "after power-on on the C-663: 200" in argument
    label, argument = await said("target C-663\n", "    SV ")
    assert "steps/s (C-663)" in argument and "counts" not in argument
    label, argument = await said("", "    DP ")  # no model: both, where the command is
    assert label == "DP [n]" and "after power-on on the C-863: 35" in argument


@pytest.mark.asyncio
@pytest.mark.parametrize("typed", ["    MR 5, ", "    TT ", "    MR 5 // a ", "    call ",
                                   "    XX "])
async def test_no_signature_outside_an_argument(client: LanguageClient, typed):
    assert await _signature(client, PROGRAM, typed) is None


# -- a rig's links -------------------------------------------------------------------------

@pytest.fixture
def rig(tmp_path) -> Path:
    folder = tmp_path / "raster"
    shutil.copytree(RASTER, folder)
    return folder / "raster.rig.toml"


async def _links(client: LanguageClient, rig: Path, text: str) -> list[t.DocumentLink]:
    await _open(client, text, rig.as_uri())
    return await client.text_document_document_link_async(
        t.DocumentLinkParams(text_document=_doc(rig.as_uri())))


@pytest.mark.asyncio
async def test_a_rigs_programs_link_to_their_files(client: LanguageClient, rig: Path):
    text = rig.read_text(encoding="utf-8")
    found = await _links(client, rig, text)
    programs = [(rig.parent / name).as_uri() for name in ("x.mcm", "y.mcm")]
    assert [link.target for link in found] == programs
    lines = text.split("\n")
    assert [lines[link.range.start.line][link.range.start.character:link.range.end.character]
            for link in found] == ["x.mcm", "y.mcm"]


@pytest.mark.asyncio
async def test_no_link_to_a_missing_file_or_out_of_the_rigs_folder(client: LanguageClient,
                                                                   rig: Path):
    (rig.parent / "y.mcm").unlink()
    (rig.parent.parent / "out.mcm").write_text("macro out { TT }\n")
    text = rig.read_text(encoding="utf-8").replace('"x.mcm"', '"../out.mcm"')
    assert not await _links(client, rig, text)


# -- workspace symbols ---------------------------------------------------------------------

@pytest.mark.asyncio
async def test_workspace_symbols_of_open_files_and_a_rigs_programs(client: LanguageClient,
                                                                   rig: Path):
    await _open(client, rig.read_text(encoding="utf-8"), rig.as_uri())
    await _open(client, PROGRAM)
    found = await client.workspace_symbol_async(t.WorkspaceSymbolParams(query=""))
    where = {(s.name, s.location.uri) for s in found}
    x_uri = (rig.parent / "x.mcm").as_uri()
    assert {("SLOW", URI), ("scan", URI), ("jog", URI), ("next_row", x_uri),
            ("LINE", x_uri), ("idle", x_uri)} <= where
    x_lines = (rig.parent / "x.mcm").read_text(encoding="utf-8").split("\n")
    for s in found:
        if s.location.uri == x_uri:
            r = s.location.range
            assert x_lines[r.start.line][r.start.character:r.end.character] == s.name
    kinds = {s.name: s.kind for s in found}
    assert kinds["scan"] == t.SymbolKind.Function and kinds["SLOW"] == t.SymbolKind.Constant


@pytest.mark.asyncio
async def test_a_query_keeps_names_with_its_letters_in_order(client: LanguageClient, rig: Path):
    await _open(client, rig.read_text(encoding="utf-8"), rig.as_uri())
    await _open(client, PROGRAM)
    found = await client.workspace_symbol_async(t.WorkspaceSymbolParams(query="nXr"))
    assert {s.name for s in found} == {"next_row"}
    found = await client.workspace_symbol_async(t.WorkspaceSymbolParams(query="sc"))
    assert {s.name for s in found} == {"scan"}


# -- every example, and a broken file ------------------------------------------------------

def _cut(text: str) -> str:
    """The first half of `text` and a line that does not parse."""
    return text[:len(text) // 2] + "\nmacro ((( {\n  MR"


@pytest.mark.asyncio
@pytest.mark.parametrize("broken", [False, True], ids=["whole", "broken"])
@pytest.mark.parametrize("path", EXAMPLE_FILES, ids=lambda p: p.stem)
async def test_every_view_answers_on_every_example(client: LanguageClient, path: Path, broken):
    text = path.read_text(encoding="utf-8")
    text = _cut(text) if broken else text
    await _open(client, text)
    for line, at, length, *_ in await _tokens(client):
        assert length > 0 and _inside(text, line, at) and _inside(text, line, at + length)
    ranges = await client.text_document_folding_range_async(
        t.FoldingRangeParams(text_document=_doc()))
    assert all(0 <= r.start_line < r.end_line < len(text.split("\n")) for r in ranges)
    for line, content in enumerate(text.split("\n")):
        for at in range(0, len(content) + 1, 3):
            await client.text_document_signature_help_async(t.SignatureHelpParams(
                text_document=_doc(), position=t.Position(line, at)))
    for s in await client.workspace_symbol_async(t.WorkspaceSymbolParams(query="")):
        r = s.location.range
        assert _inside(text, r.start.line, r.start.character)
        assert _inside(text, r.end.line, r.end.character)
