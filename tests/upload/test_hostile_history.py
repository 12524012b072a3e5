"""The flash history under hostile records.

A record that is no record (wrong types, nulls, a time without offset, deep nesting, a
FIFO, a link to /dev/zero, too big) is skipped with one warning naming it, and the others
still work in `history`, `pull` and `decompile --port`; a recorded source that no longer
builds to what the controller holds is not given back; a history that cannot be written
is said after the flash; names are escaped in the table.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from helpers.cli import cli
from helpers.emulator import FAST, serve
from helpers.history import PROGRAM

pytestmark = pytest.mark.skipif(not hasattr(os, "openpty"), reason="needs pseudo-terminals")

@pytest.fixture
def flashed(tmp_path, data_dir):
    """An emulator that holds PROGRAM, flashed by `mercmac flash`: (server, its record)."""
    program = tmp_path / "prog.mcm"
    program.write_text(PROGRAM)
    with serve() as (server, vc):
        done = cli("flash", server.path, program, "--backup", tmp_path / "b.mcm", *FAST)
        assert done.exit_code == 0, done.output
        (record,) = (data_dir / "history").glob("*.json")
        yield server, record


def _record(good: Path, **changes) -> str:
    data = json.loads(good.read_text())
    data.update(changes)
    return json.dumps(data)


def _warnings(output: str, name: str) -> list[str]:
    return [line for line in output.splitlines() if line.startswith("warning:") and name in line]


# name -> (the file's text, given the good record; words of the reason)
BAD = {
    "naive-time": (lambda g: _record(g, time="2026-01-01T10:00:00"), "no UTC offset"),
    "port-null": (lambda g: _record(g, port=None), "'port' is null, not text"),
    "file-null": (lambda g: _record(g, file=None), "'file' is null"),
    "firmware-null": (lambda g: _record(g, firmware=None), "'firmware' is null"),
    "source-null": (lambda g: _record(g, source=None), "'source' is null"),
    "model-int": (lambda g: _record(g, model=863), "'model' is a whole number, not text or null"),
    "port-list": (lambda g: _record(g, port=["/dev/a"]), "'port' is a list"),
    "file-int": (lambda g: _record(g, file=5), "'file' is a whole number"),
    "address-text": (lambda g: _record(g, address="0"), "'address' is text"),
    "address-bool": (lambda g: _record(g, address=True), "'address' is true or false"),
    "build-ints": (lambda g: _record(g, build=[5]), "a list holding a whole number"),
    "source-surrogate": (lambda g: _record(g, source="// \ud800\n" + PROGRAM), "lone surrogate"),
    "nested": (lambda g: "[" * 200_000, "nested too deeply"),
    "list": (lambda g: "[1, 2]", "a list, not a JSON object"),
    "not-json": (lambda g: "{not json", "not JSON"),
    "format-2": (lambda g: _record(g, format=2), "format 2"),
    "unknown-field": (lambda g: _record(g, colour="red"), "'colour'"),
    "missing-field": (lambda g: json.dumps({k: v for k, v in json.loads(g.read_text()).items()
                                            if k != "build"}), "no 'build'"),
}


@pytest.mark.parametrize("name", BAD)
def test_a_bad_record_is_skipped_with_one_warning_and_the_good_one_listed(flashed, name):
    server, good = flashed
    text, why = BAD[name]
    bad = good.parent / f"{name}.json"
    bad.write_text(text(good))
    table = cli("history")
    assert table.exit_code == 0, table.output
    assert "prog.mcm" in table.stdout and len(table.stdout.splitlines()) == 2
    (warning,) = _warnings(table.output, bad.name)
    assert why in warning
    as_json = cli("history", "--format", "json")
    assert as_json.exit_code == 0 and len(_warnings(as_json.output, bad.name)) == 1
    assert [f["file"] for f in json.loads(as_json.stdout)["flashes"]] == [
        json.loads(good.read_text())["file"]]


@pytest.mark.parametrize("name", ["naive-time", "port-null", "source-null", "nested"])
def test_pull_and_decompile_still_give_back_the_good_record(flashed, name):
    server, good = flashed
    text, _ = BAD[name]
    (good.parent / f"{name}.json").write_text(text(good))
    pulled = cli("pull", server.path, *FAST)
    assert pulled.exit_code == 0, pulled.output
    assert pulled.stdout == PROGRAM and len(_warnings(pulled.output, f"{name}.json")) == 1
    back = cli("decompile", "--port", server.path, *FAST)
    assert back.exit_code == 0, back.output
    assert back.stdout == PROGRAM and len(_warnings(back.output, f"{name}.json")) == 1


def _mercmac(*args, data_dir: Path, memory: int | None = None) -> subprocess.CompletedProcess:
    """The CLI as a process: a hang fails after a minute, reading without end at `memory`."""
    def limit():
        import resource

        resource.setrlimit(resource.RLIMIT_AS, (memory, memory))

    env = dict(os.environ, MERCMAC_DATA_DIR=str(data_dir), NO_COLOR="1")
    try:
        return subprocess.run([sys.executable, "-m", "mercmac", *map(str, args)], env=env,
                              capture_output=True, text=True, timeout=60,
                              preexec_fn=limit if memory else None)
    except subprocess.TimeoutExpired:
        pytest.fail(f"mercmac {' '.join(map(str, args))} hangs")


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_a_fifo_in_the_history_folder_is_skipped_not_waited_on(flashed, data_dir):
    server, good = flashed
    os.mkfifo(good.parent / "x.json")
    for args in (["history"], ["pull", server.path, *FAST], ["decompile", "--port", server.path]):
        done = _mercmac(*args, data_dir=data_dir)
        assert done.returncode == 0, done.stderr
        (warning,) = _warnings(done.stderr, "x.json")
        assert "FIFO" in warning, args
    assert done.stdout == PROGRAM


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="needs /dev/zero")
def test_a_link_to_dev_zero_and_a_huge_record_are_not_read(flashed, data_dir):
    server, good = flashed
    (good.parent / "zero.json").symlink_to("/dev/zero")
    (good.parent / "huge.json").write_text(_record(good, source="x" * 2_000_000))
    done = _mercmac("history", data_dir=data_dir, memory=1 << 30)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "character device" in _warnings(done.stderr, "zero.json")[0]
    assert "larger than a record may be (1,000,000 bytes)" in _warnings(done.stderr, "huge.json")[0]
    assert "prog.mcm" in done.stdout


def test_a_recorded_source_that_no_longer_builds_so_is_not_given_back(flashed):
    server, good = flashed
    # as if this mercmac lowered the program otherwise: the source says MR 6000 now
    good.write_text(_record(good, source=PROGRAM.replace("MR 5000", "MR 6000")))
    pulled = cli("pull", server.path, *FAST)
    assert pulled.exit_code == 0, pulled.output
    assert "[MC05] MR5000,WS100" in pulled.stdout and "the step" not in pulled.stdout
    (warning,) = _warnings(pulled.output, "no longer builds")
    assert "prog.mcm" in warning and "the stored macros are given back" in warning
    back = cli("decompile", "--port", server.path, *FAST)
    assert back.exit_code == 0, back.output
    assert "Decompiled by mercmac" in back.stdout and "MR 5000" in back.stdout
    assert "decompiled instead" in _warnings(back.output, "no longer builds")[0]


def test_a_recorded_source_with_errors_now_is_not_given_back(flashed):
    server, good = flashed
    good.write_text(_record(good, source=PROGRAM.replace("MR 5000", "MR 5000, EM 40")))
    pulled = cli("pull", server.path, *FAST)
    assert pulled.exit_code == 0 and "[MC05] MR5000,WS100" in pulled.stdout
    assert "it has errors" in _warnings(pulled.output, "no longer builds")[0]


def test_a_history_folder_that_is_a_file_is_said_after_the_flash(tmp_path, data_dir):
    program = tmp_path / "prog.mcm"
    program.write_text(PROGRAM)
    data_dir.mkdir()
    (data_dir / "history").write_text("")
    with serve() as (server, vc):
        done = cli("flash", server.path, program, "--backup", tmp_path / "b.mcm", *FAST)
    assert done.exit_code == 0, done.output  # the flash itself is done and verified
    assert "ok: flashed and verified" in done.output
    (warning,) = [line for line in done.output.splitlines() if line.startswith("warning:")]
    assert "could not be recorded" in warning and str(data_dir / "history") in warning
    listed = cli("history")
    assert listed.exit_code == 0 and "not a folder" in _warnings(listed.output, "history")[0]


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0,
                    reason="root writes into read-only folders")
def test_a_read_only_history_folder_is_said_after_the_flash(tmp_path, data_dir):
    program = tmp_path / "prog.mcm"
    program.write_text(PROGRAM)
    (data_dir / "history").mkdir(parents=True)
    (data_dir / "history").chmod(0o555)
    try:
        with serve() as (server, vc):
            done = cli("flash", server.path, program, "--backup", tmp_path / "b.mcm", *FAST)
    finally:
        (data_dir / "history").chmod(0o755)
    assert done.exit_code == 0, done.output
    assert "could not be recorded" in done.output and "no permission" in done.output


def test_history_escapes_names_that_would_act_on_the_terminal(tmp_path, data_dir):
    folder = tmp_path / "evil\n\x1b[2J"
    folder.mkdir()
    program = folder / "prog\x1b]0;x\x07.mcm"
    program.write_text(PROGRAM)
    with serve() as (server, vc):
        assert cli("flash", server.path, program, "--backup", tmp_path / "b.mcm",
                   *FAST).exit_code == 0
        pulled = cli("pull", server.path, *FAST)
    table = cli("history")
    assert table.exit_code == 0
    assert "\x1b" not in table.stdout and len(table.stdout.splitlines()) == 2
    assert "evil\\x0a\\x1b[2J/prog\\x1b]0;x\\x07.mcm" in table.stdout
    assert "\x1b" not in pulled.stderr and "\\x1b[2J" in pulled.stderr


def test_a_file_name_that_is_not_utf8_is_recorded_and_shown_as_its_bytes(tmp_path, data_dir):
    program = tmp_path / os.fsdecode(b"prog\xff.mcm")  # a byte no UTF-8 name holds
    program.write_text(PROGRAM)
    with serve() as (server, vc):
        assert cli("flash", server.path, program, "--backup", tmp_path / "b.mcm",
                   *FAST).exit_code == 0
        pulled = cli("pull", server.path, *FAST)
    table = cli("history")
    assert table.exit_code == 0 and "prog\\xff.mcm" in table.stdout, table.output
    assert "warning" not in table.output
    assert pulled.exit_code == 0 and pulled.stdout == PROGRAM
