"""The language server's views answer Neovim's own LSP client (headless): inlay hints, code
lenses, semantic tokens, folding ranges, signature help, document links in a rig file,
workspace symbols. These are LSP features, not VS Code's: an editor that speaks LSP gets them.

The client is Neovim's (tests/helpers/neovim_client.lua): its JSON-RPC, its capabilities, its
didOpen; the test skips, saying so, where `nvim` is not installed (`apt-get install neovim`).
"""
from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from helpers.paths import ROOT, TESTS

pytest.importorskip("pygls", reason="the lsp extra installs the language server")
NVIM = shutil.which("nvim")
pytestmark = pytest.mark.skipif(NVIM is None, reason="Neovim (nvim) is not installed: "
                                                     "apt-get install neovim")
CLIENT = TESTS / "helpers" / "neovim_client.lua"
RASTER = ROOT / "examples" / "rigs" / "raster"
PROGRAM = """\
target C-863
const FAR = 5000

// scan: out and back
macro scan {
  MR FAR, WS 100
  when 1 { MR 100, WS 10 }
  MR -FAR
}

autostart {
  call scan
}
"""


def _ask(tmp_path: Path, requests: list[dict]) -> dict:
    """Neovim's answers to `requests` ({file, method, params}), from a real `mercmac lsp`."""
    spec = {"server": [sys.executable, "-m", "mercmac", "lsp"], "root": str(tmp_path),
            "requests": requests, "out": str(tmp_path / "answers.json")}
    (tmp_path / "spec.json").write_text(json.dumps(spec), encoding="utf-8")
    done = subprocess.run([NVIM, "--headless", "-u", "NONE", "-i", "NONE", "-n",
                           "-c", f"luafile {CLIENT}"],
                          env={"MERCMAC_NVIM_SPEC": str(tmp_path / "spec.json"),
                               "PATH": "/usr/bin:/bin", "HOME": str(tmp_path)},
                          capture_output=True, text=True, timeout=120, stdin=subprocess.DEVNULL)
    out = tmp_path / "answers.json"
    assert out.exists(), f"nvim wrote no answers: {done.stdout[-500:]} {done.stderr[-500:]}"
    answers = json.loads(out.read_text(encoding="utf-8"))
    assert answers["failure"] is None, answers["failure"]
    return answers


def _program(tmp_path: Path) -> Path:
    path = tmp_path / "scan.mcm"
    path.write_text(PROGRAM, encoding="utf-8")
    return path


def test_inlay_hints_and_the_build_lens_answer_neovim(tmp_path):
    path = _program(tmp_path)
    hints, lenses = _ask(tmp_path, [
        {"file": str(path), "method": "textDocument/inlayHint",
         "params": {"range": {"start": {"line": 0, "character": 0},
                              "end": {"line": 13, "character": 0}}}},
        {"file": str(path), "method": "textDocument/codeLens", "params": {}},
    ])["requests"]
    labels = {(h["position"]["line"], h["label"]) for h in hints["result"]}
    assert (0, "3 of 32 slots") in labels and (4, "MC01") in labels and (10, "MC00") in labels
    assert any(line == 6 for line, _ in labels)  # the when block's own slot
    built = subprocess.run([sys.executable, "-m", "mercmac", "build", str(path)],
                           capture_output=True, text=True, check=True).stdout.splitlines()
    copied = [line for lens in lenses["result"] if lens["command"]["command"] == "mercmac.copyBuild"
              for line in lens["command"]["arguments"][0]["lines"]]
    assert sorted(copied) == sorted(built)
    (run,) = [lens for lens in lenses["result"] if lens["command"]["command"] == "mercmac.simulate"]
    assert run["range"]["start"]["line"] == 10 and run["command"]["arguments"] == [
        {"uri": path.as_uri()}]


def _tokens(data: list[int], legend: dict, text: str) -> list[tuple[str, str]]:
    """(word, type) of each token of a semanticTokens/full answer, decoded by its legend."""
    lines, out, line, start = text.split("\n"), [], 0, 0
    for i in range(0, len(data), 5):
        delta_line, delta_start, length, kind, _ = data[i:i + 5]
        line += delta_line
        start = start + delta_start if delta_line == 0 else delta_start
        out.append((lines[line][start:start + length], legend["tokenTypes"][kind]))
    return out


def test_tokens_folding_and_signature_help_answer_neovim(tmp_path):
    path = _program(tmp_path)
    answers = _ask(tmp_path, [
        {"file": str(path), "method": "textDocument/semanticTokens/full", "params": {}},
        {"file": str(path), "method": "textDocument/foldingRange", "params": {}},
        {"file": str(path), "method": "textDocument/signatureHelp",
         "params": {"position": {"line": 5, "character": 5}}},  # `MR |FAR`
    ])
    tokens, folds, signature = answers["requests"]
    legend = answers["capabilities"]["semanticTokensProvider"]["legend"]
    words = _tokens(tokens["result"]["data"], legend, PROGRAM)
    assert ("MR", "function") in words and ("FAR", "variable") in words
    assert ("scan", "function") in words
    # a block folds to its header, its closing brace left in view
    assert {(f["startLine"], f["endLine"]) for f in folds["result"]} >= {(4, 7), (10, 11)}
    (shown,) = signature["result"]["signatures"]
    assert shown["label"].startswith("MR") and "counts" in str(shown)  # C-863: encoder counts


def test_a_rig_links_its_programs_and_symbols_span_them_in_neovim(tmp_path):
    folder = tmp_path / "raster"
    shutil.copytree(RASTER, folder)
    rig = folder / "raster.rig.toml"
    links, symbols = _ask(tmp_path, [
        {"file": str(rig), "method": "textDocument/documentLink", "params": {}},
        {"file": str(rig), "method": "workspace/symbol", "params": {"query": ""},
         "workspace": True},
    ])["requests"]
    targets = sorted(Path(link["target"].removeprefix("file://")).name
                     for link in links["result"])
    assert targets == ["x.mcm", "y.mcm"]
    files = {Path(s["location"]["uri"].removeprefix("file://")).name for s in symbols["result"]}
    assert files == {"x.mcm", "y.mcm"}
