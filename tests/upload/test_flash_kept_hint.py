"""A flash that leaves macros the file does not define says how to remove them:
against the emulator on a real pseudo-terminal, through the real CLI."""
from __future__ import annotations

from helpers.cli import cli
from helpers.emulator import FAST, serve

PROGRAM = "target C-863\n[MC03] MR100\n[MC04] TP\n"


def flash(server, tmp_path, *options):
    prog = tmp_path / "p.mcm"
    prog.write_text(PROGRAM, encoding="utf-8")
    return cli("flash", server.path, prog, "--backup", tmp_path / "b.mcm", *FAST,
               *options)


def test_kept_macros_come_with_the_erase_unused_hint(tmp_path):
    with serve(macros={3: "MR100", 9: "GH", 13: "TT"}) as (server, vc):
        result = flash(server, tmp_path)
    assert result.exit_code == 0, result.output
    assert "2 kept (not in file)" in result.output
    assert "the controller also holds MC09, MC13, which were kept (not in the file): flash " \
           "with --erase-unused to remove them" in result.output
    assert vc.macros == {3: "MR100", 4: "TP", 9: "GH", 13: "TT"}  # kept indeed


def test_a_dry_run_says_it_too(tmp_path):
    with serve(macros={9: "GH"}) as (server, vc):
        result = flash(server, tmp_path, "--dry-run")
    assert result.exit_code == 0, result.output
    assert "MC09, which would be kept (not in the file): flash with --erase-unused to remove " \
           "it" in result.output


def test_no_hint_when_nothing_is_kept(tmp_path):
    with serve(macros={9: "GH"}) as (server, vc):
        result = flash(server, tmp_path, "--erase-unused")
    assert result.exit_code == 0, result.output
    assert "--erase-unused" not in result.output and vc.macros == {3: "MR100", 4: "TP"}
