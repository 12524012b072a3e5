"""What the controller will hold, shown in the editor through the real `mercmac lsp`.

- Inlay hints: the slot budget on the first line, after each macro header its slot, after
  each `when`, `repeat`, `every` and inlined `call` the hidden slots lowering gave it.
- The MD lines of a macro as `mercmac build` writes them: in its hover, with the command
  count against the 16-command limit, and in the "build" code lens that copies them.
- Each diagnostic's code links to the rule's `mercmac explain` text (docs/rules.md), and
  its hover says the summary, not the whole story.
- Format Document on a rig file formats its programs (one workspace edit) and says so.
"""
from __future__ import annotations

import asyncio
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from helpers.lsp_client import next_notification
from helpers.paths import ROOT

pytest.importorskip("pytest_lsp", reason="the test extra installs pytest-lsp")
import pytest_lsp  # noqa: E402
from lsprotocol import types as t  # noqa: E402  (pytest-lsp brings it)
from pytest_lsp import ClientServerConfig, LanguageClient  # noqa: E402

WAIT_S = 30.0
PROGRAM = """\
target C-863
const FAR = 5000

macro scan {
  MR FAR, WS 100
  call jog
  MR 10
}

macro jog {
  every 20ms {
    when 1 { MR 100, WS 10 }   // forward
    when 2 { MR -100, WS 10 }
  }
}

autostart {
  call scan
}
"""
RASTER = ROOT / "examples" / "rigs" / "raster"


@pytest_lsp.fixture(config=ClientServerConfig(
    server_command=[sys.executable, "-m", "mercmac", "lsp", "--stdio"]))
async def client(lsp_client: LanguageClient):
    """A client that applies workspace edits, as editors do (the edits are kept)."""
    lsp_client.applied = []

    @lsp_client.feature(t.WORKSPACE_APPLY_EDIT)
    def apply_edit(params: t.ApplyWorkspaceEditParams):
        lsp_client.applied.append(params)
        return t.ApplyWorkspaceEditResult(applied=True)

    await lsp_client.initialize_session(t.InitializeParams(capabilities=t.ClientCapabilities(
        workspace=t.WorkspaceClientCapabilities(apply_edit=True))))
    yield
    await lsp_client.shutdown_session()


async def _open(client: LanguageClient, path: Path, text: str, language: str = "mcm"):
    waiting = next_notification(client, t.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS, WAIT_S)
    client.text_document_did_open(t.DidOpenTextDocumentParams(text_document=t.TextDocumentItem(
        uri=path.as_uri(), language_id=language, version=1, text=text)))
    return await waiting


def _build(path: Path) -> list[str]:
    """What `mercmac build` writes for the file."""
    done = subprocess.run([sys.executable, "-m", "mercmac", "build", str(path)],
                          capture_output=True, text=True, check=True)
    return done.stdout.splitlines()


async def _hints(client: LanguageClient, path: Path, lines: int) -> list[t.InlayHint]:
    return await client.text_document_inlay_hint_async(t.InlayHintParams(
        text_document=t.TextDocumentIdentifier(uri=path.as_uri()),
        range=t.Range(t.Position(0, 0), t.Position(lines, 0))))


@pytest.mark.asyncio
async def test_inlay_hints_show_each_slot_and_the_budget(client: LanguageClient, tmp_path):
    path = tmp_path / "scan.mcm"
    path.write_text(PROGRAM, encoding="utf-8")
    await _open(client, path, PROGRAM)
    hints = await _hints(client, path, PROGRAM.count("\n"))
    lines = PROGRAM.split("\n")
    placed = {(h.position.line + 1, h.label) for h in hints}
    built = _build(path)
    assert (1, f"{len(built)} of 32 slots") in placed
    assert (4, "MC01") in placed and (10, "MC02") in placed and (17, "MC00") in placed
    # jog's `every` is copied into scan by the call (inlined): its hidden slots show at the call
    call = next(h for h in hints if h.position.line + 1 == 6)
    assert call.label.count("MC") == 3
    # each of jog's own `when` blocks is a slot, shown at the end of its code, before a comment
    when = next(h for h in hints if h.position.line + 1 == 12)
    assert when.position.character == lines[11].index("}") + 1
    # every slot the file builds shows somewhere, and only those
    shown = {s.strip() for _, label in placed if "slots" not in label for s in label.split(",")}
    assert shown == {f"MC{int(line.split(',')[0][2:]):02d}" for line in built}
    budget = next(h for h in hints if h.position.line == 0)
    assert "free: MC" in budget.tooltip.value
    assert budget.position.character == len(lines[0])  # after the line, a comment included


@pytest.mark.asyncio
async def test_no_hints_for_a_file_that_does_not_parse(client: LanguageClient, tmp_path):
    path = tmp_path / "broken.mcm"
    text = "macro scan { MR 5\n"
    await _open(client, path, text)
    assert not await _hints(client, path, 2)


@pytest.mark.asyncio
async def test_the_build_lens_and_the_hover_hold_the_md_lines_build_writes(
        client: LanguageClient, tmp_path):
    path = tmp_path / "scan.mcm"
    path.write_text(PROGRAM, encoding="utf-8")
    await _open(client, path, PROGRAM)
    lenses = await client.text_document_code_lens_async(t.CodeLensParams(
        text_document=t.TextDocumentIdentifier(uri=path.as_uri())))
    by_line = {lens.range.start.line + 1: lens.command for lens in lenses
               if lens.command.command != "mercmac.simulate"}
    assert sorted(by_line) == [4, 10, 17]
    (run,) = [lens for lens in lenses if lens.command.command == "mercmac.simulate"]
    assert run.range.start.line + 1 == 17 and list(run.command.arguments) == [{"uri": path.as_uri()}]
    assert run.command.title.startswith("▶ simulate")
    built = _build(path)
    copied = [line for command in by_line.values() for line in command.arguments[0]["lines"]]
    assert sorted(copied) == sorted(built)  # every line once, exactly as build writes it
    assert all(c.command == "mercmac.copyBuild" for c in by_line.values())
    assert by_line[17].arguments[0] == {"macro": "autostart", "lines": [built[-1]]}
    assert "1 of 16 commands" in by_line[17].title
    hover = await client.text_document_hover_async(t.HoverParams(
        text_document=t.TextDocumentIdentifier(uri=path.as_uri()), position=t.Position(9, 7)))
    text = hover.contents.value
    jog = by_line[10].arguments[0]["lines"]
    assert all(line in text for line in jog)
    assert "MC02: 5 of 16 commands" in text


@pytest.mark.asyncio
async def test_with_errors_the_lens_says_build_writes_nothing(client: LanguageClient, tmp_path):
    path = tmp_path / "typo.mcm"
    text = "macro scan { MR 5, MX 1 }\nautostart { call scan }\n"
    await _open(client, path, text)
    lenses = await client.text_document_code_lens_async(t.CodeLensParams(
        text_document=t.TextDocumentIdentifier(uri=path.as_uri())))
    assert [(lens.command.title, lens.command.command) for lens in lenses] == [
        ("simulate: not while the file has 1 error", ""),
        ("build: MC01, not built while the file has 1 error", ""),
        ("build: MC00, not built while the file has 1 error", "")]
    hover = await client.text_document_hover_async(t.HoverParams(
        text_document=t.TextDocumentIdentifier(uri=path.as_uri()), position=t.Position(1, 18)))
    assert "`mercmac build` writes nothing while the file has errors" in hover.contents.value


@pytest.mark.asyncio
async def test_a_diagnostic_code_links_to_its_whole_story(client: LanguageClient, tmp_path):
    path = tmp_path / "typo.mcm"
    text = "autostart { MX 5 }\n"
    found = await _open(client, path, text)
    (d,) = found.diagnostics
    assert d.code == "MM002"
    assert d.code_description.href.endswith("docs/rules.md#mm002-unknown-command")
    hover = await client.text_document_hover_async(t.HoverParams(
        text_document=t.TextDocumentIdentifier(uri=path.as_uri()), position=t.Position(0, 13)))
    shown = hover.contents.value
    assert "mercmac explain MM002" in shown and d.code_description.href in shown
    from mercmac.diagnostics import RULES

    story = next(r for r in RULES if r.code == "MM002").explanation
    assert story.splitlines()[0] not in shown  # the long story is one click away, not here


def _rig(tmp_path: Path, x_text: str) -> Path:
    folder = tmp_path / "raster"
    shutil.copytree(RASTER, folder)
    (folder / "x.mcm").write_text(x_text, encoding="utf-8")
    return folder / "raster.rig.toml"


@pytest.mark.asyncio
async def test_format_on_a_rig_file_formats_its_programs(client: LanguageClient, tmp_path):
    x = (RASTER / "x.mcm").read_text(encoding="utf-8")
    messy = x.replace("\n", "   \n", 3)
    rig = _rig(tmp_path, messy)
    await _open(client, rig, rig.read_text(encoding="utf-8"), "toml")
    edits = await client.text_document_formatting_async(t.DocumentFormattingParams(
        text_document=t.TextDocumentIdentifier(uri=rig.as_uri()),
        options=t.FormattingOptions(tab_size=4, insert_spaces=True)))
    assert not edits  # the rig file itself is left as written
    await _until(lambda: client.applied and client.messages)
    (applied,) = client.applied
    changes = applied.edit.changes
    assert list(changes) == [(rig.parent / "x.mcm").as_uri()]  # y.mcm is formatted already
    (edit,) = changes[(rig.parent / "x.mcm").as_uri()]
    assert edit.new_text == x and edit.range.start == t.Position(0, 0)
    said = client.messages[-1].message
    assert "x.mcm formatted" in said and "y.mcm is formatted already" in said


@pytest.mark.asyncio
async def test_format_on_a_broken_rig_says_why_not(client: LanguageClient, tmp_path):
    rig = _rig(tmp_path, (RASTER / "x.mcm").read_text(encoding="utf-8"))
    text = rig.read_text(encoding="utf-8") + "adress = 3\n"
    await _open(client, rig, text, "toml")
    await client.text_document_formatting_async(t.DocumentFormattingParams(
        text_document=t.TextDocumentIdentifier(uri=rig.as_uri()),
        options=t.FormattingOptions(tab_size=4, insert_spaces=True)))
    await _until(lambda: client.messages)
    assert client.applied == []
    assert "cannot format the programs of raster.rig.toml" in client.messages[-1].message


async def _until(probe) -> None:
    loop = asyncio.get_running_loop()
    deadline = loop.time() + WAIT_S
    while not probe():
        assert loop.time() < deadline, "timed out"
        await asyncio.sleep(0.02)
