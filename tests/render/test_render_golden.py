"""A few golden renderings pin the full text output (set MERCMAC_UPDATE_GOLDEN=1 to rewrite)."""
from __future__ import annotations

import os

import pytest
from click.testing import CliRunner

from helpers.paths import GOLDEN, ROOT
from mercmac.cli import main

CASES = {
    "check-example3.txt": ["check", "examples/macros/manual-example3-operator-moves.mcm"],
    "check-example4.txt": ["check", "examples/macros/manual-example4-four-modes.mcm"],
    "check-example4.json": ["check", "--format", "json", "examples/macros/manual-example4-four-modes.mcm"],
    "build-four-modes.txt": ["build", "examples/macros/four-modes.mcm"],
    "explain-MM005.txt": ["explain", "MM005"],
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_golden(name, monkeypatch):
    monkeypatch.chdir(ROOT)
    monkeypatch.setenv("NO_COLOR", "1")
    output = CliRunner().invoke(main, CASES[name]).output
    path = GOLDEN / name
    if os.environ.get("MERCMAC_UPDATE_GOLDEN"):
        path.write_text(output, encoding="utf-8")
    assert output == path.read_text(encoding="utf-8")
