"""`fmt RIG`: every program of a rig in the one layout; the rig file itself,
TOML the user wrote, is left as written (and fmt says so)."""
from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from helpers.cli import cli
from helpers.paths import ROOT

RASTER = ROOT / "examples" / "rigs" / "raster"
MESSY = "target c-663\nmacro   row{WN 1,mr 500 , WS 10\n  goto row}\nautostart { goto row }\n"


@pytest.fixture
def rig(tmp_path) -> Path:
    """A copy of the raster rig whose y.mcm is laid out badly."""
    folder = tmp_path / "raster"
    shutil.copytree(RASTER, folder)
    (folder / "y.mcm").write_text(MESSY, encoding="utf-8")
    return folder / "raster.rig.toml"


def test_fmt_formats_every_program_and_leaves_the_rig_file(rig):
    toml_before, x_before = rig.read_bytes(), (rig.parent / "x.mcm").read_bytes()
    result = cli("fmt", rig)
    assert result.exit_code == 0, result.output
    assert rig.read_bytes() == toml_before
    assert (rig.parent / "x.mcm").read_bytes() == x_before  # already in the layout
    y = (rig.parent / "y.mcm").read_text(encoding="utf-8")
    assert y != MESSY and "macro row {" in y and "MR 500" in y
    assert "the rig file itself is left as written" in result.stderr
    assert "1 file reformatted, 1 file left unchanged" in result.stderr
    assert f"reformatted {rig.parent / 'y.mcm'}\n" in result.stderr  # named
    assert "x.mcm" not in result.stderr  # left unchanged: not named


def test_fmt_names_each_plain_file_it_rewrites(tmp_path):
    """Once "1 file reformatted" did not say which file was written."""
    for name in ("a.mcm", "b.mcm", "c.mcm"):
        (tmp_path / name).write_text(MESSY, encoding="utf-8")
    (tmp_path / "c.mcm").write_text(cli("fmt", "-", input=MESSY).stdout, encoding="utf-8")
    result = cli("fmt", tmp_path)
    assert result.exit_code == 0, result.output
    written = [line for line in result.stderr.splitlines() if "reformatted" in line]
    assert written == [f"mercmac: reformatted {tmp_path / 'a.mcm'}",
                       f"mercmac: reformatted {tmp_path / 'b.mcm'}",
                       "2 files reformatted, 1 file left unchanged"]


def test_fmt_check_and_diff_change_nothing(rig):
    check = cli("fmt", "--check", rig)
    assert check.exit_code == 1 and "would reformat" in check.stderr and "y.mcm" in check.stderr
    diff = cli("fmt", "--diff", rig)
    assert diff.exit_code == 1 and "+macro row {" in diff.stdout
    assert (rig.parent / "y.mcm").read_text(encoding="utf-8") == MESSY


def test_fmt_of_a_formatted_rig_is_clean(rig):
    assert cli("fmt", rig).exit_code == 0
    again = cli("fmt", "--check", rig)
    assert again.exit_code == 0 and "2 files left unchanged" in again.stderr


def test_a_program_named_twice_is_formatted_once(rig):
    result = cli("fmt", "--check", rig, rig.parent / "y.mcm")
    assert result.stderr.count("would reformat") == 1
    assert "1 file would be reformatted, 1 file left unchanged" in result.stderr


def test_a_rig_file_with_errors_is_not_formatted(tmp_path):
    broken = tmp_path / "b.rig.toml"
    broken.write_text("[controllers.x\n", encoding="utf-8")
    result = cli("fmt", broken)
    assert result.exit_code == 2 and "b.rig.toml:1:" in result.stderr
    assert broken.read_text(encoding="utf-8") == "[controllers.x\n"
    missing = cli("fmt", tmp_path / "none.rig.toml")
    assert missing.exit_code == 2 and "cannot read" in missing.stderr
