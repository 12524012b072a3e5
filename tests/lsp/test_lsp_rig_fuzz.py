"""The language server and `check` agree on hostile rigs:
the rigs of tests/helpers/hostile_rigs.py (random keys, types, names, paths and wires,
sometimes broken TOML), each opened in the real `mercmac lsp` and checked by `mercmac check
--format json`: the same diagnostics at the same places, and none of them quoting the
secret that lies outside the rig's folder.
"""
from __future__ import annotations

import asyncio
import json
import random
from pathlib import Path

import pytest
from click.testing import CliRunner

from helpers.budgets import fuzz_budget
from helpers.hostile_rigs import make_rig
from mercmac.source import split_lines

pytest.importorskip("pytest_lsp", reason="the test extra installs pytest-lsp")
from lsprotocol import types as t  # noqa: E402  (pytest-lsp brings it)
from pytest_lsp import LanguageClient  # noqa: E402  (the client: tests/lsp/conftest.py)

RIGS = fuzz_budget(30)
WAIT_S = 30.0
SEVERITY = {1: "error", 2: "warning", 3: "info"}


def _checked(rig: Path) -> list[tuple]:
    """What `check --format json` reports in the rig file, as the server's ranges read."""
    from mercmac.cli import main

    result = CliRunner().invoke(main, ["check", "--format", "json", str(rig)])
    assert result.exit_code in (0, 1, 2), result.output
    if result.exit_code == 2 and not result.stdout.strip():
        return [("unreadable",)]
    lines = split_lines(rig.read_bytes().decode("utf-8-sig")) or [""]
    return sorted((d["code"], d["severity"], *_position(lines, d["line"], d["column"]),
                   *_position(lines, d["end_line"], d["end_column"]), d["message"])
                  for d in json.loads(result.stdout)["diagnostics"]
                  if Path(d["file"]).resolve() == rig.resolve())


def _position(lines: list[str], line: int, column: int) -> tuple[int, int]:
    """A 1-based line and column as LSP places them (the rig files here are ASCII, so a
    column counts UTF-16 units too): a column past its line's end is the end of the line, a
    line past the last the end of the text (LSP 3.17, Position)."""
    if line > len(lines):
        return len(lines) - 1, len(lines[-1])
    return line - 1, min(column - 1, len(lines[line - 1]))


async def _published(client: LanguageClient, rig: Path) -> list[tuple]:
    uri = rig.as_uri()
    before = client.diagnostics.get(uri)
    client.text_document_did_open(t.DidOpenTextDocumentParams(text_document=t.TextDocumentItem(
        uri=uri, language_id="toml", version=1,
        # as an editor holds it: VS Code, neovim and emacs keep a byte-order mark apart
        text=rig.read_bytes().decode("utf-8-sig"))))
    loop = asyncio.get_running_loop()
    deadline = loop.time() + WAIT_S
    while (now := client.diagnostics.get(uri)) is before:
        if loop.time() > deadline:
            raise TimeoutError(f"no diagnostics published for {rig} in {WAIT_S:g} s")
        await asyncio.sleep(0.02)
    return sorted((d.code, SEVERITY[d.severity], d.range.start.line, d.range.start.character,
                   d.range.end.line, d.range.end.character, d.message) for d in now)


@pytest.mark.slow
@pytest.mark.asyncio
async def test_the_server_says_what_check_says_of_hostile_rigs(client: LanguageClient,
                                                              tmp_path: Path):
    for seed in range(RIGS):
        rig = make_rig(random.Random(seed), tmp_path / str(seed))
        wanted, found = _checked(rig), await _published(client, rig)
        assert found == wanted, (seed, rig.read_text(encoding="utf-8", errors="replace")[:1500])
        assert not any("SECRET-" in d[-1] for d in found), seed
