"""The README's set-up commands are true: CI runs exactly its test command."""
from __future__ import annotations

from helpers.paths import ROOT
from helpers.readme import setup_commands


def test_readme_opens_with_two_setup_commands():
    install, tests = setup_commands()
    assert "pip install ." in install and "mercmac" in install.split("&&")[-1]
    assert "pytest" in tests


def test_ci_runs_the_readme_test_command():
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8").splitlines()
    assert setup_commands()[1] in ci


def test_readme_example_files_exist():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    for word in text.split():
        if word.startswith("examples/") and word.endswith(".mcm"):
            assert (ROOT / word).exists(), word
