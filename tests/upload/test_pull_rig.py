"""`pull --rig DIR` and `decompile --port --rig DIR` (issue 18 §4): a scanned chain becomes a
rig folder, names given back by the flash history, against an emulated chain on a pty."""
from __future__ import annotations

import shutil
from contextlib import contextmanager
from pathlib import Path

import pytest

from helpers.cli import cli, mercmac_process
from helpers.emulator import FAST, FAST_TIMING
from helpers.paths import ROOT
from mercmac.compiler import compile_file
from mercmac.emulator.chain import Chain
from mercmac.emulator.ptyserver import PtyServer
from mercmac.emulator.virtual import VirtualController
from mercmac.rig.load import read_rig
from mercmac.upload.rig import flash_rig

RASTER = ROOT / "examples" / "rigs" / "raster"
# what a controller mercmac never flashed may hold: MMCRun's raw lines (MS176E §3.8.6)
RAW = ({1: "CN1,WN2,CF1,WF2", 0: "SV20000,CP0,EM1"}, {0: "SV10000,WN1,MR500,WS10,CN2"})


@contextmanager
def chain(macros=({}, {})):
    vcs = [VirtualController("C-663", a, macros=dict(m)) for a, m in enumerate(macros)]
    with PtyServer(Chain(vcs)) as server:
        yield server, vcs


@pytest.fixture
def rig(tmp_path) -> Path:
    folder = tmp_path / "raster"
    shutil.copytree(RASTER, folder)
    return folder / "raster.rig.toml"


def held(server, vcs) -> list[dict[int, str]]:
    return [server.call(lambda _c, vc=vc: dict(vc.macros)) for vc in vcs]


def test_pull_rig_gives_back_the_flashed_rig_and_it_round_trips(rig, tmp_path, data_dir):
    out = tmp_path / "pulled"
    with chain() as (server, vcs):
        flash_rig(server.path, str(rig), timing=FAST_TIMING)
        result = cli("pull", server.path, "--rig", out, *FAST)
        assert result.exit_code == 0, result.output
        before = [server.call(lambda _c, vc=vc: vc.md_count) for vc in vcs]
        again = flash_rig(server.path, str(out / "raster.rig.toml"), timing=FAST_TIMING)
        assert [server.call(lambda _c, vc=vc: vc.md_count) for vc in vcs] == before
    assert again.changes_nothing
    assert sorted(p.name for p in out.iterdir()) == ["raster.rig.toml", "x.mcm", "y.mcm"]
    assert (out / "x.mcm").read_text() == (rig.parent / "x.mcm").read_text()  # names, comments
    text = (out / "raster.rig.toml").read_text()
    assert "Wires cannot be read from controllers" in text
    pulled = read_rig(str(out / "raster.rig.toml")).rig
    assert [(c.name, c.address, c.model) for c in pulled.controllers] == [("x", 0, "C-663"),
                                                                          ("y", 1, "C-663")]
    assert cli("check", out / "raster.rig.toml").exit_code == 0


def test_a_chain_mercmac_never_flashed_is_named_by_address(tmp_path, data_dir):
    out = tmp_path / "bench"
    with chain(RAW) as (server, vcs):
        result = cli("pull", server.path, "--rig", out, *FAST)
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in out.iterdir()) == ["a0.mcm", "a1.mcm", "bench.rig.toml"]
    for address, macros in enumerate(RAW):
        program = compile_file(str(out / f"a{address}.mcm")).program
        assert {s: m.line for s, m in program.macros.items()} == macros


def test_decompile_rig_writes_sources_that_build_to_what_each_holds(tmp_path, data_dir):
    out = tmp_path / "sources"
    with chain(RAW) as (server, vcs):
        result = cli("decompile", "--port", server.path, "--rig", out, *FAST)
    assert result.exit_code == 0, result.output
    rig = read_rig(str(out / "sources.rig.toml")).rig
    for c, macros in zip(rig.controllers, RAW):
        text = Path(c.program).read_text()
        assert "[MC" not in text  # decompiled, not the raw blocks
        program = compile_file(c.program, c.model).program
        assert {s: m.line for s, m in program.macros.items()} == macros


def test_rig_with_options_that_do_not_go_with_it_is_refused(tmp_path):
    assert cli("pull", "/dev/null", "--rig", tmp_path / "d", "-o", tmp_path / "x.mcm").exit_code == 2
    assert cli("pull", "/dev/null", "--rig", tmp_path / "d", "--address", "1").exit_code == 2
    assert cli("decompile", "--rig", tmp_path / "d").exit_code == 2


def test_pull_rig_as_a_process(rig, tmp_path, data_dir):
    out = tmp_path / "pulled"
    with chain() as (server, vcs):
        flash_rig(server.path, str(rig), timing=FAST_TIMING)
        done = mercmac_process("pull", server.path, "--rig", str(out), *FAST, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "recorded source" in done.stderr
    assert (out / "y.mcm").read_text() == (rig.parent / "y.mcm").read_text()
