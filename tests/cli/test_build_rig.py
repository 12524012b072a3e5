"""`build RIG.rig.toml`: build makes one controller's MD lines for one output, so a rig file
is refused (exit 2: docs/cli.md, "Exit codes") with its programs named, one build each; it
was once parsed as a program (29 syntax errors on the bundled rig)."""
from __future__ import annotations

import shutil

from helpers.cli import cli
from helpers.paths import ROOT

RASTER = ROOT / "examples" / "rigs" / "raster"


def test_build_refuses_a_rig_and_names_its_programs(tmp_path, monkeypatch):
    shutil.copytree(RASTER, tmp_path / "raster")
    monkeypatch.chdir(tmp_path / "raster")
    result = cli("build", "raster.rig.toml", "-o", "out.md", catch=True)
    assert isinstance(result.exception, SystemExit) and result.exit_code == 2, result.output
    assert "build takes one program (a .mcm file), and raster.rig.toml is a rig file" \
        in result.stderr
    assert "mercmac build x.mcm; mercmac build y.mcm" in result.stderr
    assert "error[" not in result.output and not (tmp_path / "raster" / "out.md").exists()


def test_build_refuses_a_rig_it_cannot_read_alike(tmp_path):
    broken = tmp_path / "b.rig.toml"
    broken.write_text("[controllers.x\n", encoding="utf-8")
    for rig in (broken, tmp_path / "none.RIG.TOML"):
        result = cli("build", rig, catch=True)
        assert result.exit_code == 2 and "is a rig file" in result.stderr, result.output
        assert f"mercmac check {rig}" in result.stderr


def test_build_of_each_named_program_works(tmp_path, monkeypatch):
    monkeypatch.chdir(RASTER)
    for program in ("x.mcm", "y.mcm"):
        result = cli("build", program)
        assert result.exit_code == 0 and result.stdout.startswith("MD"), result.output
