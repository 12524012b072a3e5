"""The names of mercmac's own commands: a synonym or a misspelling gets
"did you mean", lazily loaded commands too; a bare `mercmac` shows the help and exits 0."""
from __future__ import annotations

import pytest

from helpers.cli import cli, mercmac_process


@pytest.mark.parametrize("typed, meant", [
    ("simulate", "sim"), ("upload", "flash"), ("write", "flash"), ("program", "flash"),
    ("download", "pull"), ("read", "pull"), ("lint", "check"), ("format", "fmt"),
    ("compile", "build"), ("Simulate", "sim"),
    ("flsh", "flash"), ("decomple", "decompile"), ("emulat", "emulate"),  # lazily loaded
    ("chek", "check"), ("comands", "commands"),
])
def test_a_synonym_or_misspelling_suggests_the_command(typed, meant):
    result = cli(typed, "prog.mcm")
    assert result.exit_code == 2
    assert f"No such command '{typed}'. Did you mean '{meant}'?" in result.output


@pytest.mark.parametrize("typed", ["xyzzy", "\x1b[2J", "q" * 5000])
def test_an_unknown_name_without_a_near_one(typed):
    result = cli(typed)
    assert result.exit_code == 2 and "Did you mean" not in result.output
    assert "\x1b" not in result.output


def test_options_of_the_group_still_work():
    assert cli("--version").exit_code == 0
    assert cli("--bogus").exit_code == 2 and "No such option" in cli("--bogus").output


def test_bare_mercmac_prints_the_help_and_exits_0(tmp_path):
    out = mercmac_process(cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert "Usage: " in out.stdout and "Commands:" in out.stdout and out.stderr == ""
    assert cli().output == cli("--help").output
