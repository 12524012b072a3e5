"""Names come back: `flash` records what it wrote, `pull` gives back that source, `history` lists."""
from __future__ import annotations

import json
import os
import shutil

import pytest

from helpers.cli import cli
from helpers.emulator import FAST
from helpers.paths import FOUR_MODES
from mercmac.upload import history

pytestmark = pytest.mark.skipif(not hasattr(os, "openpty"), reason="needs pseudo-terminals")


@pytest.fixture
def program(tmp_path):
    path = tmp_path / "four-modes.mcm"
    shutil.copy(FOUR_MODES, path)
    return path


def _serve(**kw):
    from helpers.emulator import serve

    return serve(**kw)


def test_flash_then_pull_gives_back_the_source(tmp_path, data_dir, program):
    with _serve() as (server, vc):
        flashed = cli("flash", server.path, program, "--backup", tmp_path / "b.mcm", *FAST)
        assert flashed.exit_code == 0, flashed.output
        pulled = cli("pull", server.path, "-o", tmp_path / "back.mcm", *FAST)
        raw = cli("pull", server.path, "--raw", *FAST)
    assert pulled.exit_code == 0, pulled.output
    assert (tmp_path / "back.mcm").read_text() == program.read_text()
    assert "the controller holds four-modes.mcm, flashed " in pulled.output
    assert f"from {program}" in pulled.output
    assert raw.exit_code == 0 and "[MC00]" in raw.stdout and "macro jog" not in raw.stdout
    records = list((data_dir / "history").glob("*.json"))
    assert len(records) == 1
    saved = json.loads(records[0].read_text())
    assert saved["port"] == server.path and saved["address"] == 0
    assert saved["model"] == "C-863" and saved["firmware"] == "2.30"
    assert saved["file"] == str(program) and saved["source"] == program.read_text()
    assert saved["build"][-1].startswith("MD0,")


def test_a_changed_controller_is_not_taken_for_the_recorded_build(tmp_path, data_dir, program):
    with _serve() as (server, vc):
        assert cli("flash", server.path, program, "--backup", tmp_path / "b.mcm", *FAST).exit_code == 0
        server.call(lambda _c: vc._define("MD15,MR5"))
        pulled = cli("pull", server.path, *FAST)
    assert pulled.exit_code == 0, pulled.output
    assert "[MC15] MR5" in pulled.stdout and "holds four-modes.mcm" not in pulled.output


def test_a_dry_run_records_nothing(tmp_path, data_dir, program):
    with _serve() as (server, vc):
        assert cli("flash", server.path, program, "--dry-run", *FAST).exit_code == 0
    assert history.records() == []


def test_history_lists_newest_first(tmp_path, data_dir, program):
    other = tmp_path / "small.mcm"
    other.write_text("target C-863\n[MC05] MR5000,WS100\n")
    with _serve() as (server, vc):
        for f in (program, other):
            assert cli("flash", server.path, f, "--backup", tmp_path / "b.mcm", *FAST).exit_code == 0
    table = cli("history")
    assert table.exit_code == 0, table.output
    lines = table.output.splitlines()
    assert lines[0].split() == ["time", "port", "address", "model", "firmware", "file", "macros"]
    assert str(other) in lines[1] and str(program) in lines[2]
    as_json = json.loads(cli("history", "--format", "json").output)
    assert [f["file"] for f in as_json["flashes"]] == [str(other), str(program)]
    assert as_json["flashes"][0]["macros"] == {"5": "MR5000,WS100"}


def test_history_without_flashes_and_unreadable_records(data_dir):
    (data_dir / "history").mkdir(parents=True)
    (data_dir / "history" / "junk.json").write_text("{not json")
    (data_dir / "history" / "other.json").write_text('{"format": 99}')
    result = cli("history")
    assert result.exit_code == 0 and "no flashes recorded yet" in result.output
    assert json.loads(cli("history", "--format", "json").stdout) == {"flashes": []}


MINE = "// mine\n[MC05] MR5000,WS100\n[MC00] MA5\n"  # a source that builds to its record


def test_lookup_matches_as_the_controller_stores_macros(data_dir):
    history.record(port="/dev/ttyUSB0", address=2, model="C-863", firmware="2.30",
                   file="p.mcm", source=MINE, build=["MD5,MR5000,WS100", "MD0,MA5"])
    assert history.lookup({5: "mr 5000 , ws100", 0: "MA+5"}).source == MINE
    assert history.lookup({5: "MR5000,WS100"}) is None
    assert history.lookup({5: "MR5000,WS100", 0: "MA5", 7: "TP"}) is None
    assert history.lookup({}) is None


def test_lookup_prefers_this_port_and_address(data_dir):
    for port in ("/dev/a", "/dev/b", "/dev/c"):
        history.record(port=port, address=0, model="C-863", firmware="2.30", file=f"{port[-1]}.mcm",
                       source=f"// {port}\n[MC05] MR5\n", build=["MD5,MR5"])
    assert history.lookup({5: "MR5"}, port="/dev/b", address=0).source.startswith("// /dev/b")
    assert history.lookup({5: "MR5"}).source.startswith("// /dev/c")  # else the newest


def test_an_unwritable_history_does_not_fail_the_flash(tmp_path, monkeypatch, program):
    blocker = tmp_path / "file"
    blocker.write_text("")
    monkeypatch.setenv("MERCMAC_DATA_DIR", str(blocker))  # a file: no folder can be made in it
    with _serve() as (server, vc):
        result = cli("flash", server.path, program, "--backup", tmp_path / "b.mcm", *FAST)
    assert result.exit_code == 0, result.output


def test_backups_follow_the_data_dir_variable(tmp_path, data_dir, program):
    with _serve() as (server, vc):
        assert cli("flash", server.path, program, *FAST).exit_code == 0
    assert len(list((data_dir / "backups").glob("*.mcm"))) == 1
