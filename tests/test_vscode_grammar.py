"""The VS Code extension (editors/vscode): its TextMate grammar on the examples, its client.

The node tests read the grammar with the vscode-textmate npm package, as VS Code does; they
need node and `npm ci --prefix editors/vscode` (the test is skipped, saying so, without them).
"""
from __future__ import annotations

import json
import shutil
import subprocess

import pytest

from conftest import ROOT
from mercmac.highlight import textmate_json

VSCODE = ROOT / "editors" / "vscode"
GRAMMAR = VSCODE / "syntaxes" / "mcm.tmLanguage.json"


def test_the_committed_grammar_is_the_generated_one():
    assert GRAMMAR.read_text(encoding="utf-8") == textmate_json(), \
        "regenerate it: python -m mercmac.highlight --textmate > editors/vscode/syntaxes/mcm.tmLanguage.json"


def test_the_extension_names_its_files():
    package = json.loads((VSCODE / "package.json").read_text(encoding="utf-8"))
    assert (VSCODE / package["main"]).exists()
    assert (VSCODE / package["contributes"]["grammars"][0]["path"]).exists()
    assert (VSCODE / package["contributes"]["languages"][0]["configuration"]).exists()
    assert (VSCODE / "package-lock.json").exists()
    assert "node_modules/" in (VSCODE / ".gitignore").read_text(encoding="utf-8").split()


def test_node_tests_pass():
    node = shutil.which("node")
    if node is None:
        pytest.skip("node is not installed")
    for package in ("vscode-textmate", "vscode-oniguruma"):
        if not (VSCODE / "node_modules" / package).is_dir():
            pytest.skip(f"{package} is not installed: run `npm ci --prefix editors/vscode`")
    out = subprocess.run([node, "--test", "test/"], cwd=VSCODE, capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stdout[-4000:] + out.stderr[-2000:]
