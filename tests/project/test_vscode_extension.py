"""The VS Code extension (editors/vscode): its TextMate grammar, its client, its package.

The node tests read the grammar with vscode-textmate as VS Code does, and start the real
vscode-languageclient (bundled by esbuild, as the .vsix ships it) against this mercmac. They
need Node.js: the extension's npm packages are installed here once per run (`npm ci`, kept
while package-lock.json is unchanged) when npm exists, and the tests skip, saying so, when not.
"""
from __future__ import annotations

import hashlib
import json
import os
import shlex
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path
from typing import Iterator

import pytest

from helpers.locking import held, lock_file
from helpers.paths import ROOT
from mercmac.highlight import textmate_json

VSCODE = ROOT / "editors" / "vscode"
GRAMMAR = VSCODE / "syntaxes" / "mcm.tmLanguage.json"
STAMP = VSCODE / "node_modules" / ".mercmac-lock-sha256"
# The node tests share node_modules/ and dist/ (`vsce package` rebuilds dist/ too): each
# holds a lock on them from the install to its end, so that two pytest-xdist workers take
# turns (scheduling them on one worker, `xdist_group`, does nothing under pytest 9).
# What the .vsix holds (vsce's own files aside): the bundle, never the sources or the tests.
PACKAGED = {"extension/package.json", "extension/readme.md", "extension/LICENSE.txt",
            "extension/icon.png", "extension/icons/mcm.svg", "extension/dist/extension.js",
            "extension/language-configuration.json", "extension/syntaxes/mcm.tmLanguage.json"}


def test_the_committed_grammar_is_the_generated_one():
    assert GRAMMAR.read_text(encoding="utf-8") == textmate_json(), \
        "regenerate it: python -m mercmac.highlight --textmate > editors/vscode/syntaxes/mcm.tmLanguage.json"


def test_the_extension_names_its_files():
    package = json.loads((VSCODE / "package.json").read_text(encoding="utf-8"))
    assert package["main"] == "./dist/extension.js" and "src/extension.js" in package["scripts"]["build"]
    assert (VSCODE / "src" / "extension.js").exists()
    assert (VSCODE / package["icon"]).exists() and (VSCODE / "LICENSE").exists()
    assert (VSCODE / package["contributes"]["grammars"][0]["path"]).exists()
    assert (VSCODE / package["contributes"]["languages"][0]["configuration"]).exists()
    assert all((VSCODE / icon).exists() for icon in package["contributes"]["languages"][0]["icon"].values())
    assert (VSCODE / "package-lock.json").exists()
    ignored = (VSCODE / ".gitignore").read_text(encoding="utf-8").split()
    assert {"node_modules/", "dist/"} <= set(ignored)


def _npm(*args: str, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([shutil.which("npm"), *args], cwd=VSCODE, capture_output=True,
                          text=True, timeout=timeout, stdin=subprocess.DEVNULL)


@pytest.fixture
def node_packages() -> Iterator[str]:
    """node, with the extension's packages installed (once, while the lock file is the same)
    and its bundle built, for this test alone among the workers; the test is skipped when
    Node.js or npm is missing."""
    node, npm = shutil.which("node"), shutil.which("npm")
    if node is None or npm is None:
        pytest.skip("Node.js (node and npm) is not installed: the VS Code extension is not tested")
    with held(lock_file(VSCODE)):
        yield _installed(node)


def _installed(node: str) -> str:
    """node, after `npm ci` (unless the stamp says the lock file is installed) and the build."""
    lock = hashlib.sha256((VSCODE / "package-lock.json").read_bytes()).hexdigest()
    if not STAMP.exists() or STAMP.read_text() != lock:
        done = _npm("ci", "--no-audit", "--no-fund")
        if done.returncode != 0 and "ETXTBSY" in done.stderr:
            # esbuild's install script runs the binary it has just written; while a process
            # forked at that moment still holds the file open for writing, Linux answers
            # ETXTBSY ("text file busy"). It is transient: one more `npm ci` installs it.
            done = _npm("ci", "--no-audit", "--no-fund")
        assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
        STAMP.write_text(lock)
    built = _npm("run", "build", timeout=120)
    assert built.returncode == 0, built.stdout[-3000:] + built.stderr[-3000:]
    return node


def _this_mercmac(folder: Path) -> Path:
    """An executable of this tree's mercmac. The venv's console script runs what was
    installed, which may be older: tools/pythons.py installs `.[test]` again only when
    pyproject.toml changes (the tests import mercmac from the tree, and so must this)."""
    if os.name != "posix":
        return Path(sys.executable).with_name("mercmac")
    script = folder / "mercmac"
    script.write_text(f"#!/bin/sh\nPYTHONPATH={shlex.quote(str(ROOT))}${{PYTHONPATH:+:$PYTHONPATH}} "
                      f'exec {shlex.quote(sys.executable)} -m mercmac "$@"\n', encoding="utf-8")
    script.chmod(0o755)
    return script


@pytest.mark.slow
def test_node_tests_pass(node_packages, tmp_path):
    """The grammar on the examples, and the client started against this mercmac."""
    env = {**os.environ, "MERCMAC_BIN": str(_this_mercmac(tmp_path))}
    out = subprocess.run([node_packages, "--test", "test/"], cwd=VSCODE, capture_output=True,
                         text=True, timeout=180, env=env, stdin=subprocess.DEVNULL)
    assert out.returncode == 0, out.stdout[-6000:] + out.stderr[-2000:]


@pytest.mark.slow
def test_vsce_packages_a_clean_vsix(node_packages, tmp_path):
    """`vsce package` runs without a prompt or a warning; the .vsix holds the bundle only."""
    vsix = tmp_path / "mercmac.vsix"
    out = _npm("exec", "--", "vsce", "package", "--out", str(vsix), timeout=180)
    said = out.stdout + out.stderr
    assert out.returncode == 0, said[-4000:]
    assert "WARNING" not in said and "[y/N]" not in said, said[-4000:]  # vsce's prompts end so
    with zipfile.ZipFile(vsix) as package:
        names = {n for n in package.namelist() if n.startswith("extension/")}
    assert names == PACKAGED
