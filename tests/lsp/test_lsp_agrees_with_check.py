"""The language server publishes what `mercmac check` reports.

Each example of examples/macros/ is copied into a project folder with a settings file
(mercmac.toml or pyproject.toml's [tool.mercmac]), `// mercmac: ignore` comments on lines
that have findings, and a few lines that add findings of their own, some of them
suppressed and one suppression that cannot be read (invalid-suppression). Then
`mercmac check --format json` (a real process) and the real `mercmac lsp` (pytest-lsp)
must give the same diagnostics; with workspace settings, those of `check` with the same
values as options. The server used to publish every finding, suppressed or not.
"""
from __future__ import annotations

import json
import random
import re
import subprocess
import sys
from pathlib import Path

import pytest

from helpers.lsp_client import next_notification
from helpers.paths import EXAMPLE_FILES

pytest_lsp = pytest.importorskip("pytest_lsp", reason="the test extra installs pytest-lsp")
from lsprotocol import types as t  # noqa: E402  (pytest-lsp brings it)
from pytest_lsp import ClientServerConfig, LanguageClient  # noqa: E402

# Lines that add findings to any example: raw blocks in slots the examples leave free or
# share (a shared one is a duplicate-slot finding, which must agree too).
PROBE = """\
// probe: what check reports, the server publishes
[MC31] EM27,JN2000,XN1,XF1   // mercmac: ignore[joystick-in-macro]
[MC30] DC200,DP200,WS   // mercmac: ignore
[MC29] EM26,LED1   // mercmac: IGNORE[MM002, no-such-rule]
[MC28] TT,DP200,JN2000
"""
VARIANTS = {
    "mercmac.toml": ({"mercmac.toml": 'target = "C-663"\nignore = ["unreachable-macro"]\n'},
                     None, []),
    "pyproject.toml": ({"pyproject.toml": '[project]\nname = "rig"\n\n[tool.mercmac]\nselect = '
                                          '["undefined-macro", "nested-call", "MM013", "MM034", '
                                          '"model-unsupported", "unknown-command"]\n'},
                       None, []),
    "workspace settings over the file's": (
        {"mercmac.toml": 'target = "C-663"\nignore = ["default-argument"]\n'},
        {"target": "C-863", "ignore": ["contradictory-condition"], "select": None,
         "path": "mercmac"},
        ["--target", "C-863", "--ignore", "contradictory-condition"]),
    "workspace select, sent by the client": (
        {}, {"select": ["MM012", "invalid-suppression", "argument-range", "MM010"]},
        ["--select", "MM012,invalid-suppression", "--select", "argument-range,MM010"]),
}


def _project(folder: Path, files: dict[str, str]) -> list[Path]:
    """The examples in `folder` with suppression comments and the probe, and the settings."""
    folder.mkdir()
    for name, text in files.items():
        (folder / name).write_text(text, encoding="utf-8")
    out = []
    for example in EXAMPLE_FILES:
        path = folder / example.name
        path.write_text(_suppressed(example) + PROBE, encoding="utf-8")
        out.append(path)
    return out


def _suppressed(example: Path) -> str:
    """The example with `// mercmac: ignore[RULE]` on the line of its first finding that
    is not a syntax error (appended after a comment the line has)."""
    text = example.read_text(encoding="utf-8")
    found = _check([example], [])[example.name]
    lines = text.split("\n")
    for d in found:
        if d[0] != "MM001":
            lines[d[1]] += f"   // mercmac: ignore[{d[0]}]"
            break
    return "\n".join(lines)


def _check(paths: list[Path], options: list[str]) -> dict[str, list[tuple]]:
    """`mercmac check --format json OPTIONS PATHS` as a subprocess: file name -> diagnostics
    as the server sends them (0-based, UTF-16 units), sorted."""
    out = subprocess.run([sys.executable, "-m", "mercmac", "check", "--format", "json",
                          *options, *map(str, paths)], capture_output=True, text=True,
                         stdin=subprocess.DEVNULL, timeout=120)
    assert out.returncode in (0, 1), out.stderr
    found: dict[str, list[tuple]] = {p.name: [] for p in paths}
    texts = {p.name: p.read_text(encoding="utf-8").split("\n") for p in paths}
    for d in json.loads(out.stdout)["diagnostics"]:
        name = Path(d["file"]).name
        lines = texts[name]
        found[name].append((d["code"], d["line"] - 1, _units(lines, d["line"], d["column"]),
                            d["end_line"] - 1, _units(lines, d["end_line"], d["end_column"]),
                            d["message"]))
    return {name: sorted(items) for name, items in found.items()}


def _units(lines: list[str], line: int, column: int) -> int:
    """UTF-16 units before 1-based `column` of 1-based `line`."""
    head = lines[line - 1][:column - 1] if line - 1 < len(lines) else ""
    return len(head.encode("utf-16-le")) // 2


WAIT_S = 30.0  # generous for a busy machine; a server that never answers fails the test


async def _wait(client: LanguageClient) -> None:
    """The next publishDiagnostics, or a failure after WAIT_S."""
    await next_notification(client, t.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS, WAIT_S)


def _published(diagnostics) -> list[tuple]:
    return sorted((d.code, d.range.start.line, d.range.start.character, d.range.end.line,
                   d.range.end.character, d.message) for d in diagnostics)


@pytest_lsp.fixture(config=ClientServerConfig(
    server_command=[sys.executable, "-m", "mercmac", "lsp", "--stdio"]))
async def client(lsp_client: LanguageClient):
    yield
    await lsp_client.shutdown_session()


async def _start(client: LanguageClient, workspace: dict | None, pull: bool) -> None:
    """Initialize; the workspace settings are asked for (pull) or sent (didChangeConfiguration)."""
    if pull:
        client.set_configuration(workspace, section="mercmac")
    capabilities = t.ClientCapabilities(workspace=t.WorkspaceClientCapabilities(
        configuration=pull, did_change_configuration=t.DidChangeConfigurationClientCapabilities()))
    await client.initialize_session(t.InitializeParams(capabilities=capabilities))
    if not pull and workspace is not None:
        client.workspace_did_change_configuration(t.DidChangeConfigurationParams(
            settings={"mercmac": workspace}))


async def _open_all(client: LanguageClient, paths: list[Path]) -> dict[str, list[tuple]]:
    """Open every file; what the server published for each, once it has for all."""
    for path in paths:
        client.text_document_did_open(t.DidOpenTextDocumentParams(text_document=t.TextDocumentItem(
            uri=path.as_uri(), language_id="mcm", version=1,
            text=path.read_text(encoding="utf-8"))))
    while any(p.as_uri() not in client.diagnostics for p in paths):
        await _wait(client)
    return {p.name: _published(client.diagnostics[p.as_uri()]) for p in paths}


@pytest.mark.slow
@pytest.mark.asyncio
@pytest.mark.parametrize("variant", VARIANTS)
async def test_the_server_publishes_what_check_reports_on_every_example(
        client: LanguageClient, tmp_path, variant):
    files, workspace, options = VARIANTS[variant]
    paths = _project(tmp_path / "project", files)
    expected = _check(paths, options)
    await _start(client, workspace, pull="sent by the client" not in variant)
    published = await _open_all(client, paths)
    for path in paths:
        assert published[path.name] == expected[path.name], path.name
    assert all(expected.values())  # the probe adds findings to every file
    assert client.messages == []  # the settings were all understood


@pytest.mark.asyncio
async def test_a_suppressed_line_shows_nothing_where_it_used_to_show_the_finding(
        client: LanguageClient, tmp_path):
    path = tmp_path / "probe.mcm"
    path.write_text("[MC01] EM9   // mercmac: ignore[undefined-macro]\n[MC02] EM8\n",
                    encoding="utf-8")
    await _start(client, None, pull=False)
    published = (await _open_all(client, [path]))[path.name]
    assert [(code, line) for code, line, *_ in published] == [("MM012", 1)]


@pytest.mark.asyncio
async def test_changed_workspace_settings_check_the_open_documents_again(
        client: LanguageClient, tmp_path):
    path = tmp_path / "probe.mcm"
    path.write_text("[MC01] EM9\n[MC02] DC200\n", encoding="utf-8")
    await _start(client, {"target": None}, pull=True)
    assert [d[0] for d in (await _open_all(client, [path]))[path.name]] == ["MM012"]
    client.set_configuration({"target": "C-863", "ignore": ["MM012"]}, section="mercmac")
    client.workspace_did_change_configuration(t.DidChangeConfigurationParams(settings=None))
    await _wait(client)
    assert [d.code for d in client.diagnostics[path.as_uri()]] == ["MM010"]  # DC: C-663 only


@pytest.mark.asyncio
async def test_an_edited_settings_file_is_read_again(client: LanguageClient, tmp_path):
    path = tmp_path / "probe.mcm"
    path.write_text("[MC01] EM9\n", encoding="utf-8")
    await _start(client, None, pull=False)
    assert [d[0] for d in (await _open_all(client, [path]))[path.name]] == ["MM012"]
    (tmp_path / "mercmac.toml").write_text('ignore = ["undefined-macro"]\n', encoding="utf-8")
    client.workspace_did_change_watched_files(t.DidChangeWatchedFilesParams(changes=[
        t.FileEvent(uri=(tmp_path / "mercmac.toml").as_uri(), type=t.FileChangeType.Created)]))
    await _wait(client)
    assert list(client.diagnostics[path.as_uri()]) == []


@pytest.mark.asyncio
async def test_bad_workspace_settings_are_shown_and_the_good_ones_still_apply(
        client: LanguageClient, tmp_path):
    path = tmp_path / "probe.mcm"
    path.write_text("[MC01] EM9,DC200,XN1,XF1\n", encoding="utf-8")
    workspace = {"target": "C-999", "select": ["nested-cal"], "ignore": ["MM013"]}
    await _start(client, workspace, pull=True)
    published = (await _open_all(client, [path]))[path.name]
    assert [d[0] for d in published] == ["MM012"]  # no target (no MM010), MM013 ignored
    shown = [m.message for m in client.messages]
    assert any("mercmac.target = 'C-999' is not a model" in m for m in shown), shown
    assert any("mercmac.select: no rule 'nested-cal'" in m for m in shown), shown
    assert all(m.type == t.MessageType.Error for m in client.messages)
    hover = await client.text_document_hover_async(t.HoverParams(
        text_document=t.TextDocumentIdentifier(uri=path.as_uri()), position=t.Position(0, 8)))
    assert hover is not None  # still serving


@pytest.mark.asyncio
async def test_a_settings_file_check_refuses_is_shown_once_and_the_file_still_checked(
        client: LanguageClient, tmp_path):
    (tmp_path / "mercmac.toml").write_text('target = "C-999"\n', encoding="utf-8")
    path = tmp_path / "probe.mcm"
    path.write_text("[MC01] EM9\n", encoding="utf-8")
    out = subprocess.run([sys.executable, "-m", "mercmac", "check", str(path)],
                         capture_output=True, text=True, stdin=subprocess.DEVNULL, timeout=120)
    assert out.returncode == 2 and "is not a model" in out.stderr
    await _start(client, None, pull=False)
    assert [d[0] for d in (await _open_all(client, [path]))[path.name]] == ["MM012"]
    for version in (2, 3):  # each keystroke checks again; the message is not repeated
        client.text_document_did_change(t.DidChangeTextDocumentParams(
            text_document=t.VersionedTextDocumentIdentifier(uri=path.as_uri(), version=version),
            content_changes=[t.TextDocumentContentChangeWholeDocument(text="[MC01] EM9\n" * version)]))
        await _wait(client)
    assert len(client.messages) == 1 and "is not a model" in client.messages[0].message


# A statement that ends its line (`const`, `target`): its span used to take the newline and
# the blank lines after it, so the editor underlined the next statement (and the server,
# which reads a chunk with a newline added, one line more than `check` said).
ONE_LINERS = "target C-999\nconst A = 1\nconst A = 2\n\n\nautostart { MR A }\n"


@pytest.mark.asyncio
async def test_a_one_line_statement_is_marked_on_its_own_line(client: LanguageClient, tmp_path):
    path = tmp_path / "one.mcm"
    path.write_text(ONE_LINERS, encoding="utf-8")
    await _start(client, None, pull=False)  # first: the fixture's shutdown needs a session
    published = (await _open_all(client, [path]))["one.mcm"]
    expected = _check([path], [])["one.mcm"]
    assert [(code, line, end_line, end) for code, line, _, end_line, end, _ in expected] == [
        ("MM003", 0, 0, 12), ("MM018", 2, 2, 11)]
    assert published == expected


def _edit(rng: random.Random, lines: list[str]) -> tuple[t.Range, str]:
    """One edit as an editor sends it (a range and its new text), of a kind that moves
    statements across the re-checker's chunks: a line added (a `const`, a blank, a copy of
    another), a line taken out, two lines joined, a word changed."""
    n = len(lines)
    at = rng.randrange(n)
    kind = rng.choice(("const", "blank", "copy", "delete", "join", "word"))
    start = t.Position(at, 0)
    if kind == "const":
        return t.Range(start, start), f"const {rng.choice('ABC')} = {rng.randrange(9)}\n"
    if kind == "blank":
        return t.Range(start, start), "\n" * rng.randint(1, 3)
    if kind == "copy":
        return t.Range(start, start), lines[rng.randrange(n)] + "\n"
    if kind == "delete" and at + 1 < n:
        return t.Range(start, t.Position(at + 1, 0)), ""
    if kind == "join" and at + 1 < n:
        return t.Range(t.Position(at, len(lines[at])), t.Position(at + 1, 0)), " "
    words = [m for m in re.finditer(r"[A-Za-z]+", lines[at])]
    if not words:
        return t.Range(start, start), "// an edit\n"
    word = rng.choice(words)
    new = rng.choice(("MX", "WA", "target", "macro", word.group()[::-1]))
    return t.Range(t.Position(at, word.start()), t.Position(at, word.end())), new


def _apply(text: str, rng_: t.Range, new: str) -> str:
    lines = text.split("\n")
    start = sum(len(x) + 1 for x in lines[:rng_.start.line]) + rng_.start.character
    end = sum(len(x) + 1 for x in lines[:rng_.end.line]) + rng_.end.character
    return text[:start] + new + text[end:]


# positions here count characters: the examples' are one UTF-16 unit each, as the LSP's are
EDITED = [p for p in EXAMPLE_FILES if max(map(ord, p.read_text(encoding="utf-8"))) < 0x10000]


@pytest.mark.slow
@pytest.mark.asyncio
@pytest.mark.parametrize("example", EDITED, ids=lambda p: p.name)
async def test_after_random_edits_the_ranges_are_checks(client: LanguageClient, tmp_path,
                                                        example: Path):
    """Each example edited at random, an edit at a time as an editor sends them: after
    each, the server's diagnostics (ranges included) are `check --format json`'s."""
    rng = random.Random(f"{example.name}-30")
    path = tmp_path / example.name
    text = example.read_text(encoding="utf-8")
    path.write_text(text, encoding="utf-8")
    await _start(client, None, pull=False)
    await _open_all(client, [path])
    for version in range(2, 10):
        change, new = _edit(rng, text.split("\n"))
        text = _apply(text, change, new)
        waiting = next_notification(client, t.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS, WAIT_S)
        client.text_document_did_change(t.DidChangeTextDocumentParams(
            text_document=t.VersionedTextDocumentIdentifier(uri=path.as_uri(), version=version),
            content_changes=[t.TextDocumentContentChangePartial(range=change, text=new)]))
        await waiting
        path.write_text(text, encoding="utf-8")
        assert _published(client.diagnostics[path.as_uri()]) == _check([path], [])[path.name], \
            f"after edit {version - 1} ({change}, {new!r}):\n{text}"
