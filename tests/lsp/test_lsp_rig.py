"""The language server and rigs, through the real `mercmac lsp`.

- A rig file (`*.rig.toml`) gets what `check RIG` reports on it, at its line and column
  in the rig file, on open and on each change.
- A `.mcm` that a rig (in its folder or above) names as a program is checked with that
  controller's model when it has no `target`; a `target` of another model is reported
  as the rig's model-mismatch (MR006) is. A `.mcm` no rig names is checked as before.
"""
from __future__ import annotations

import asyncio
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from helpers.paths import ROOT

pytest.importorskip("pytest_lsp", reason="the test extra installs pytest-lsp")
from lsprotocol import types as t  # noqa: E402  (pytest-lsp brings it)
from pytest_lsp import LanguageClient  # noqa: E402  (the client: tests/lsp/conftest.py)

WAIT_S = 30.0
RASTER = ROOT / "examples" / "rigs" / "raster"
C863_ONLY = "macro tune { DP 200 }\nautostart { call tune }\n"  # DP: C-863 only (MM010)



@pytest.fixture
def rig(tmp_path) -> Path:
    """A copy of the raster rig, programs one folder down (paths relative to the rig)."""
    folder = tmp_path / "raster"
    shutil.copytree(RASTER, folder)
    (folder / "axes").mkdir()
    for name in ("x.mcm", "y.mcm"):
        (folder / name).rename(folder / "axes" / name)
    path = folder / "raster.rig.toml"
    path.write_text(path.read_text(encoding="utf-8").replace('"x.mcm"', '"axes/x.mcm"')
                    .replace('"y.mcm"', '"axes/y.mcm"'), encoding="utf-8")
    return path


async def _published(client: LanguageClient, uri: str, before: object) -> list[t.Diagnostic]:
    """The diagnostics published for `uri` after `before`, the list the client held when the
    request went out. (Read from the client's store, not by waiting for the next
    notification: one that arrives before such a wait has begun is missed, and the test
    times out under load.)"""
    loop = asyncio.get_running_loop()
    deadline = loop.time() + WAIT_S
    while (now := client.diagnostics.get(uri)) is before:
        if loop.time() > deadline:
            raise TimeoutError(f"no diagnostics published for {uri} in {WAIT_S:g} s")
        await asyncio.sleep(0.02)
    return list(now)


async def _open(client: LanguageClient, path: Path, text: str | None = None,
                language: str = "mcm") -> list[t.Diagnostic]:
    uri = path.as_uri()
    before = client.diagnostics.get(uri)
    client.text_document_did_open(t.DidOpenTextDocumentParams(text_document=t.TextDocumentItem(
        uri=uri, language_id=language, version=1,
        text=path.read_text(encoding="utf-8") if text is None else text)))
    return await _published(client, uri, before)


async def _eventually(client: LanguageClient, uri: str, codes: list[str]) -> list[str]:
    """The codes of the diagnostics the client holds for `uri`, once they are `codes` or
    WAIT_S has passed."""
    loop = asyncio.get_running_loop()
    deadline = loop.time() + WAIT_S
    while (found := _codes(client.diagnostics.get(uri, []))) != codes and loop.time() < deadline:
        await asyncio.sleep(0.05)
    return found


def _codes(diagnostics) -> list[str]:
    return sorted(d.code for d in diagnostics)


@pytest.mark.asyncio
async def test_a_clean_rig_file_has_no_diagnostics(client: LanguageClient, rig: Path):
    assert await _open(client, rig, language="toml") == []


@pytest.mark.asyncio
async def test_rig_diagnostics_stand_in_the_rig_file(client: LanguageClient, rig: Path):
    text = rig.read_text(encoding="utf-8")
    repeated = text.replace("address = 1 ", "address = 0 ")
    found = await _open(client, rig, repeated, language="toml")
    assert _codes(found) == ["MR005"]
    line = repeated.split("\n").index(next(x for x in repeated.split("\n")
                                           if x.startswith("address = 0 ") and "OFF" in x))
    assert found[0].range.start.line == line and found[0].source == "mercmac"
    # on change: a wire into an input that the box drives too (MR008) and the address fixed
    changed = text.replace('"y.out2 -> x.in2"', '"y.out2 -> x.in1"')
    before = client.diagnostics.get(rig.as_uri())
    client.text_document_did_change(t.DidChangeTextDocumentParams(
        text_document=t.VersionedTextDocumentIdentifier(uri=rig.as_uri(), version=2),
        content_changes=[t.TextDocumentContentChangeWholeDocument(text=changed)]))
    found = await _published(client, rig.as_uri(), before)
    assert "MR008" in _codes(found) and "MR005" not in _codes(found)
    wire_line = changed.split("\n").index(next(x for x in changed.split("\n")
                                               if '"y.out2 -> x.in1"' in x))
    assert {d.range.start.line for d in found if d.code == "MR008"} == {wire_line}


@pytest.mark.asyncio
async def test_a_broken_rig_file_says_where(client: LanguageClient, rig: Path):
    found = await _open(client, rig, rig.read_text(encoding="utf-8") + "adress = 3\n",
                        language="toml")
    assert _codes(found) == ["MR001"]


@pytest.mark.asyncio
async def test_rig_features_offer_no_macro_words(client: LanguageClient, rig: Path):
    """A rig file is TOML: no completion, no `target` action, no formatting of it."""
    await _open(client, rig, language="toml")
    where = t.TextDocumentIdentifier(uri=rig.as_uri())
    completion = await client.text_document_completion_async(t.CompletionParams(
        text_document=where, position=t.Position(0, 0)))
    assert not completion.items
    actions = await client.text_document_code_action_async(t.CodeActionParams(
        text_document=where, range=t.Range(t.Position(0, 0), t.Position(0, 0)),
        context=t.CodeActionContext(diagnostics=[])))
    assert not actions
    edits = await client.text_document_formatting_async(t.DocumentFormattingParams(
        text_document=where, options=t.FormattingOptions(tab_size=4, insert_spaces=True)))
    assert not edits


@pytest.mark.asyncio
async def test_a_program_of_a_rig_is_checked_with_its_model(client: LanguageClient, rig: Path):
    program = rig.parent / "axes" / "y.mcm"
    # the rig says C-663: DP (C-863 only) is refused without any `target` in the file
    assert _codes(await _open(client, program, C863_ONLY)) == ["MM010"]


@pytest.mark.asyncio
async def test_a_target_of_another_model_is_a_mismatch(client: LanguageClient, rig: Path):
    program = rig.parent / "axes" / "x.mcm"
    text = program.read_text(encoding="utf-8").replace("target C-663", "target C-863")
    found = await _open(client, program, text)
    mismatch = [d for d in found if d.code == "MR006"]
    assert len(mismatch) == 1 and "C-663" in mismatch[0].message
    assert mismatch[0].range.start.line == text.split("\n").index("target C-863")


@pytest.mark.asyncio
async def test_an_open_rig_edit_counts_for_its_programs(client: LanguageClient, rig: Path):
    """The rig's text in the editor, unsaved, decides the model of its programs, and an
    edit of it checks the open programs again."""
    program = rig.parent / "axes" / "y.mcm"  # `target C-663`, as the rig on disk says
    assert await _open(client, program) == []
    await _open(client, rig, language="toml")
    as_c863 = rig.read_text(encoding="utf-8").replace(
        'model = "C-663"\nprogram = "axes/y.mcm"', 'model = "C-863"\nprogram = "axes/y.mcm"')
    client.text_document_did_change(t.DidChangeTextDocumentParams(
        text_document=t.VersionedTextDocumentIdentifier(uri=rig.as_uri(), version=2),
        content_changes=[t.TextDocumentContentChangeWholeDocument(text=as_c863)]))
    # the rig's open and its change each check the program again: wait until the last
    # diagnostics the client holds for it are the change's (a notification that came
    # before a wait began would be missed by waiting for the next one)
    assert await _eventually(client, program.as_uri(), ["MR006"]) == ["MR006"]


@pytest.mark.asyncio
async def test_a_program_no_rig_names_is_checked_as_before(client: LanguageClient, tmp_path):
    alone = tmp_path / "alone.mcm"
    alone.write_text(C863_ONLY, encoding="utf-8")
    assert _codes(await _open(client, alone)) == []


@pytest.mark.asyncio
async def test_a_saved_program_checks_its_rig_again(client: LanguageClient, rig: Path):
    """The rig's checks read its programs as saved: a save of one re-checks the open rig."""
    assert await _open(client, rig, language="toml") == []
    program = rig.parent / "axes" / "x.mcm"
    await _open(client, program)
    quiet = "target C-663\nautostart { WN 2, WF 2 }\n"  # never sets out1 (x.out1 -> y.in1)
    program.write_text(quiet, encoding="utf-8")
    before = client.diagnostics.get(rig.as_uri())
    client.text_document_did_save(t.DidSaveTextDocumentParams(
        text_document=t.TextDocumentIdentifier(uri=program.as_uri()), text=quiet))
    found = await _published(client, rig.as_uri(), before)
    assert "MR009" in _codes(found)


@pytest.mark.asyncio
async def test_the_rig_file_gets_what_check_reports(client: LanguageClient, rig: Path):
    """Codes, severities, positions and words as `mercmac check --format json RIG` (a
    real process) reports them on the rig file."""
    import json
    import subprocess

    text = rig.read_text(encoding="utf-8").replace("address = 1 ", "address = 0 ").replace(
        '"y.out2 -> x.in2",', '"y.out2 -> x.in2",\n  "y.out3 -> x.in1",')
    rig.write_text(text, encoding="utf-8")
    checked = subprocess.run([sys.executable, "-m", "mercmac", "check", "--format", "json",
                              str(rig)], capture_output=True, text=True, timeout=60)
    wanted = sorted((d["code"], d["severity"], d["line"] - 1, d["column"] - 1,
                     d["end_line"] - 1, d["end_column"] - 1, d["message"])
                    for d in json.loads(checked.stdout)["diagnostics"]
                    if d["file"].endswith("raster.rig.toml"))
    assert {w[0] for w in wanted} == {"MR005", "MR008", "MR009"}
    severity = {1: "error", 2: "warning", 3: "info"}
    found = sorted((d.code, severity[d.severity], d.range.start.line, d.range.start.character,
                    d.range.end.line, d.range.end.character, d.message)
                   for d in await _open(client, rig, language="toml"))
    assert found == wanted


@pytest.mark.asyncio
async def test_the_rig_rules_of_a_program_stand_in_it(client: LanguageClient, rig: Path):
    """`check RIG` reports SC in macro 0 (MR007) and an input nothing drives (MR010) in the
    program: the editor shows them there, from its unsaved text."""
    program = rig.parent / "axes" / "y.mcm"
    text = program.read_text(encoding="utf-8").replace(
        "autostart {\n", "autostart {\n    SC 1\n    WN 4\n")
    found = await _open(client, program, text)
    assert _codes(found) == ["MR007", "MR010"]
    lines = text.split("\n")
    assert {d.code: d.range.start.line for d in found} == {
        "MR007": lines.index("    SC 1"), "MR010": lines.index("    WN 4")}


# -- a broken rig is never shown clean -----------------------------------------------------------
# Whatever `check RIG` says in the rig file, the editor shows at the same place; where `check`
# cannot read the rig, one diagnostic at 1:1 says why in its words. The server used to publish
# nothing for a rig over 16 MB, a rig naming itself as a program, a program path with a NUL and
# a wire line of 5,000 digits (the last two also crashed `check`: mercmac/rig/load.py).
SEVERITY = {1: "error", 2: "warning", 3: "info"}
BROKEN = {
    "larger than mercmac reads": lambda text: text + "#" * (17 * 1024 * 1024) + "\n",
    "naming itself as a program": lambda text: text.replace('"axes/y.mcm"', '"raster.rig.toml"'),
    "a program that is a folder": lambda text: text.replace('"axes/y.mcm"', '"axes"'),
    "a program path with a NUL": lambda text: text.replace('"axes/y.mcm"', '"axes/y\\u0000.mcm"'),
    "a wire line of 5,000 digits": lambda text: text.replace('"x.out1 -> y.in1"',
                                                             '"x.out1 -> y.in' + "1" * 5000 + '"'),
}


def _check_says(rig: Path) -> list[tuple]:
    """What `mercmac check --format json RIG` (a real process) reports in the rig file itself:
    (code, severity, start, end, message), positions 0-based as the editor's; a rig it
    cannot read, as the editor is to show it: MR001 at 1:1 with `check`'s reason."""
    checked = subprocess.run([sys.executable, "-m", "mercmac", "check", "--format", "json",
                              str(rig)], capture_output=True, text=True, timeout=120)
    assert "Traceback" not in checked.stderr, checked.stderr[-2000:]
    unread = f"mercmac: cannot read {rig}: "
    if checked.returncode == 2 and checked.stderr.startswith(unread):
        why = checked.stderr[len(unread):].strip()
        return [("MR001", "error", (0, 0), (0, 1), f"the rig cannot be checked: {why}")]
    here = os.path.realpath(rig)
    return sorted((d["code"], d["severity"], (d["line"] - 1, d["column"] - 1),
                   (d["end_line"] - 1, d["end_column"] - 1), d["message"])
                  for d in json.loads(checked.stdout)["diagnostics"]
                  if os.path.realpath(d["file"]) == here)


def _shown(found: list[t.Diagnostic]) -> list[tuple]:
    return sorted((d.code, SEVERITY[d.severity], (d.range.start.line, d.range.start.character),
                   (d.range.end.line, d.range.end.character), d.message) for d in found)


@pytest.mark.asyncio
@pytest.mark.parametrize("broken", BROKEN)
async def test_a_broken_rig_shows_what_check_says(client: LanguageClient, rig: Path, broken):
    """The NUL and 5,000-digit cases need `check` itself fixed: until
    then `check` crashes, and this test says so."""
    text = BROKEN[broken](rig.read_text(encoding="utf-8"))
    rig.write_text(text, encoding="utf-8")
    wanted = _check_says(rig)
    assert wanted and any(w[1] == "error" for w in wanted)  # never clean
    assert _shown(await _open(client, rig, text, language="toml")) == wanted


def test_a_rig_check_that_fails_is_said_at_1_1(monkeypatch, tmp_path):
    """A bug in the rig checks is a diagnostic on the rig, as a compiler bug is on a file."""
    from mercmac.compiler.checking import choice_for
    from mercmac.lsp import rig
    from mercmac.rig import checks
    from mercmac.source import Source

    def broken(*args, **kw):
        raise RuntimeError("a bug")

    monkeypatch.setattr(checks, "check_rig", broken)
    (found,) = rig.rig_diagnostics(Source(str(tmp_path / "r.rig.toml"), ""), choice_for(None))
    assert (found.rule.code, found.span.line, found.span.column) == ("MR001", 1, 1)
    assert "internal error while checking this rig (RuntimeError: a bug)" in found.message
