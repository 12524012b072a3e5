"""`mercmac lsp` driven as an editor drives it: pytest-lsp starts it as a subprocess and
talks LSP over stdio. The re-checker itself is compared with `compile_source`."""
from __future__ import annotations

import subprocess
import sys

import pytest

from helpers.paths import EXAMPLE_FILES, ROOT
from mercmac.compiler import compile_source
from mercmac.lsp.recheck import Rechecker, chunks
from mercmac.source import Source

pytest.importorskip("pytest_lsp", reason="the test extra installs pytest-lsp")
from lsprotocol import types as t  # noqa: E402  (pytest-lsp brings it)
from pytest_lsp import LanguageClient  # noqa: E402  (the client: tests/lsp/conftest.py)

sys.path.insert(0, str(ROOT / "benchmarks"))
from recheck_latency import full_program  # noqa: E402

URI = "file:///work/jog.mcm"
TEXT = """\
// a jog box
const SLOW = 5000
const FINE = 160

macro setup { SV SLOW, SA 100000, CP 1, WA 300, CP 0 }

autostart {
    call setup
    goto run
}

macro run {
    every 20ms {
        when 1 { MR FINE, WF 1 }
        when 2 { MR -9999999, WF 2, AB 1, CP 0 }
    }
}
"""



def _open(client: LanguageClient, text: str = TEXT) -> None:
    client.text_document_did_open(t.DidOpenTextDocumentParams(
        text_document=t.TextDocumentItem(uri=URI, language_id="mcm", version=1, text=text)))


async def _diagnostics(client: LanguageClient) -> list[t.Diagnostic]:
    await client.wait_for_notification(t.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)
    return client.diagnostics[URI]


def _at(line: int, character: int) -> dict:
    return dict(text_document=t.TextDocumentIdentifier(uri=URI),
                position=t.Position(line, character))


def _apply(text: str, edits: list[t.TextEdit]) -> str:
    lines = text.split("\n")
    offsets = [0]
    for line in lines:
        offsets.append(offsets[-1] + len(line) + 1)

    def index(p: t.Position) -> int:
        return offsets[p.line] + p.character

    for e in sorted(edits, key=lambda e: index(e.range.start), reverse=True):
        text = text[:index(e.range.start)] + e.new_text + text[index(e.range.end):]
    return text


@pytest.mark.asyncio
async def test_diagnostics_on_open_and_change_carry_the_rule(client: LanguageClient):
    _open(client)
    assert list(await _diagnostics(client)) == []  # this file checks clean
    broken = TEXT.replace("call setup", "call setpu").replace("SV SLOW", "SVV SLOW")
    client.text_document_did_change(t.DidChangeTextDocumentParams(
        text_document=t.VersionedTextDocumentIdentifier(uri=URI, version=2),
        content_changes=[t.TextDocumentContentChangeWholeDocument(text=broken)]))
    found = await _diagnostics(client)
    expected = compile_source(Source("jog.mcm", broken)).report.items
    assert sorted(d.code for d in found) == sorted(d.rule.code for d in expected)
    assert {d.data["rule"] for d in found} == {d.rule.name for d in expected}
    assert all(d.data["explain"].startswith(d.code) for d in found)  # `mercmac explain` text


@pytest.mark.asyncio
async def test_a_syntax_error_is_reported_as_check_reports_it(client: LanguageClient):
    text = TEXT.replace("SA 100000,", "SA 100000 CP 2,")
    _open(client, text)
    found = await _diagnostics(client)
    assert [d.code for d in found] == [d.rule.code for d in
                                       compile_source(Source("jog.mcm", text)).report.sorted()]
    assert found and found[0].code == "MM001"


@pytest.mark.asyncio
async def test_hover_on_a_mnemonic_a_macro_and_a_const(client: LanguageClient):
    _open(client)
    await _diagnostics(client)
    sv = await client.text_document_hover_async(t.HoverParams(**_at(4, 15)))  # SV
    assert "SV" in sv.contents.value and "range" in sv.contents.value
    assert "MS176E §6.4" in sv.contents.value and "C-663" in sv.contents.value
    run = await client.text_document_hover_async(t.HoverParams(**_at(8, 10)))  # goto run
    assert "macro run" in run.contents.value and "MD" in run.contents.value
    assert "MC" in run.contents.value
    fine = await client.text_document_hover_async(t.HoverParams(**_at(13, 23)))  # MR FINE
    assert "const FINE** = 160" in fine.contents.value


@pytest.mark.asyncio
async def test_hover_on_a_diagnostic_explains_its_rule(client: LanguageClient):
    _open(client, TEXT.replace("SV SLOW", "SV"))
    await _diagnostics(client)
    hover = await client.text_document_hover_async(t.HoverParams(**_at(4, 15)))
    assert "MM003" in hover.contents.value and "bad-argument" in hover.contents.value


@pytest.mark.asyncio
async def test_completion_of_mnemonics_keywords_macros_and_consts(client: LanguageClient):
    _open(client)
    await _diagnostics(client)
    result = await client.text_document_completion_async(t.CompletionParams(**_at(13, 17)))
    by_label = {i.label: i for i in result.items}
    assert {"MR", "EM", "when", "repeat"} <= set(by_label)  # a statement starts
    assert "EM takes a macro number 1-31" in by_label["EM"].detail
    after_mr = await client.text_document_completion_async(t.CompletionParams(**_at(13, 20)))
    assert {i.label for i in after_mr.items} == {"SLOW", "FINE"}
    after_call = await client.text_document_completion_async(t.CompletionParams(**_at(7, 9)))
    assert {i.label for i in after_call.items} == {"setup", "run"}


@pytest.mark.asyncio
async def test_definition_and_references(client: LanguageClient):
    _open(client)
    await _diagnostics(client)
    found = await client.text_document_definition_async(t.DefinitionParams(**_at(7, 10)))
    assert [(loc.range.start.line, loc.range.start.character) for loc in found] == [(4, 6)]
    refs = await client.text_document_references_async(t.ReferenceParams(
        **_at(1, 7), context=t.ReferenceContext(include_declaration=True)))  # SLOW
    assert sorted(r.range.start.line for r in refs) == [1, 4]


@pytest.mark.asyncio
async def test_rename_a_macro_and_a_const(client: LanguageClient):
    _open(client)
    await _diagnostics(client)
    edit = await client.text_document_rename_async(t.RenameParams(**_at(11, 7), new_name="go"))
    renamed = _apply(TEXT, edit.changes[URI])
    assert "macro go {" in renamed and "goto go" in renamed and "run" not in renamed
    edit = await client.text_document_rename_async(t.RenameParams(**_at(13, 24), new_name="STEP"))
    renamed = _apply(TEXT, edit.changes[URI])
    assert renamed.count("STEP") == 2 and "FINE" not in renamed
    assert compile_source(Source("x", renamed)).report.items == []


@pytest.mark.asyncio
async def test_document_symbols_list_macros_with_their_slots(client: LanguageClient):
    _open(client)
    await _diagnostics(client)
    found = await client.text_document_document_symbol_async(t.DocumentSymbolParams(
        text_document=t.TextDocumentIdentifier(uri=URI)))
    by_name = {s.name: s for s in found}
    assert {"SLOW", "FINE", "setup", "autostart", "run"} <= set(by_name)
    program = compile_source(Source("x", TEXT)).program
    assert by_name["autostart"].detail == "MC00"
    run = [m for m in program.macros.values() if m.name.split(".")[0] == "run"]
    assert len(by_name["run"].children) == len(run) > 1  # its every and when blocks


@pytest.mark.asyncio
async def test_formatting_goes_through_mercmac_fmt(client: LanguageClient):
    from mercmac.lsp.edits import formatter

    format_text = formatter()
    if format_text is None:
        pytest.skip("no mercmac fmt (format_text) in this tree yet")
    text = TEXT.replace("SV SLOW, SA", "SV   SLOW,SA")
    _open(client, text)
    await _diagnostics(client)
    edits = await client.text_document_formatting_async(t.DocumentFormattingParams(
        text_document=t.TextDocumentIdentifier(uri=URI),
        options=t.FormattingOptions(tab_size=4, insert_spaces=True)))
    assert _apply(text, edits or []) == format_text(text)


@pytest.mark.asyncio
async def test_code_actions_did_you_mean_and_target(client: LanguageClient):
    text = TEXT.replace("call setup", "call setpu").replace("SV SLOW", "SVV SLOW")
    _open(client, text)
    found = await _diagnostics(client)
    whole = t.Range(t.Position(0, 0), t.Position(20, 0))
    actions = await client.text_document_code_action_async(t.CodeActionParams(
        text_document=t.TextDocumentIdentifier(uri=URI), range=whole,
        context=t.CodeActionContext(diagnostics=found)))
    titles = [a.title for a in actions]
    assert "Replace with 'setup'" in titles and "Add `target C-863`" in titles
    fixed = text
    for a in actions:
        if a.title.startswith("Replace"):
            fixed = _apply(fixed, a.edit.changes[URI])
    assert "call setup" in fixed and "SVV" not in fixed
    target = next(a for a in actions if a.title == "Add `target C-863`")
    with_target = _apply(TEXT, target.edit.changes[URI])
    assert with_target.split("\n")[1] == "target C-863"
    assert compile_source(Source("x", with_target)).report.items == []


@pytest.mark.slow
@pytest.mark.parametrize("path", EXAMPLE_FILES + ["full"],
                         ids=lambda p: getattr(p, "name", p))
def test_the_recheck_equals_compile_source_after_every_line_deletion(path):
    text = full_program() if path == "full" else Source("x", path.read_bytes().decode(
        "utf-8", errors="replace")).text
    checker = Rechecker("x")
    lines = text.split("\n")
    for i in range(-1, len(lines)):
        edited = text if i < 0 else "\n".join(lines[:i] + lines[i + 1:])
        assert "".join(chunk for _, chunk in chunks(edited)) == edited
        mine, theirs = checker.check(edited).compilation, compile_source(Source("x", edited))
        assert mine.report.items == theirs.report.items
        assert mine.program == theirs.program


def test_the_benchmark_program_fills_all_32_slots():
    result = compile_source(Source("full", full_program()))
    assert len(result.program.macros) == 32 and not result.report.has_errors


def test_without_pygls_lsp_says_which_extra_and_exits_2():
    hide = "import sys; sys.modules['pygls'] = None; from mercmac.cli import main; main()"
    result = subprocess.run([sys.executable, "-c", hide, "lsp"], capture_output=True, text=True,
                            stdin=subprocess.DEVNULL, cwd=ROOT)
    assert result.returncode == 2
    assert "the language server needs the lsp extra: pip install 'mercmac[lsp]'" in result.stderr
    assert "Traceback" not in result.stderr
