"""`mercmac decompile`, `describe` and `history` on the command line: sources, errors, the graph."""
from __future__ import annotations

import importlib.util
import os
import shutil

import pytest

from helpers.cli import cli
from helpers.emulator import FAST
from helpers.paths import FOUR_MODES

RAW = "target C-863\n[MC05] MR5000,WS100\n[MC00] MA0,EM5\n"
needs_decompiler = pytest.mark.skipif(importlib.util.find_spec("mercmac.decompile") is None,
                                      reason="mercmac.decompile is not there yet")


def _ready(name: str) -> bool:
    """Whether mercmac.decompile offers `name` yet (it is written alongside this CLI)."""
    try:
        import mercmac.decompile as library

        getattr(library, name)({5: "MR5"})
    except (ImportError, AttributeError, NotImplementedError):
        return False
    return True


needs_describe = pytest.mark.skipif(not _ready("describe") or not _ready("call_graph_dot"),
                                    reason="mercmac.decompile.describe is not there yet")
needs_pty = pytest.mark.skipif(not hasattr(os, "openpty"), reason="needs pseudo-terminals")


def _no_traceback(result):
    assert "Traceback" not in result.output, result.output
    assert result.exception is None or isinstance(result.exception, SystemExit), result.output


@pytest.mark.parametrize("command", ["decompile", "describe"])
def test_a_file_or_a_port_not_both_nor_neither(command, write):
    neither = cli(command, catch=True)
    both = cli(command, write(RAW), "--port", "/dev/does-not-exist", catch=True)
    for result in (neither, both):
        assert result.exit_code == 2 and "give a FILE or --port PORT" in result.output
        _no_traceback(result)


@pytest.mark.parametrize("command", ["decompile", "describe"])
def test_bad_files(command, tmp_path, write):
    missing = cli(command, tmp_path / "nope.mcm", catch=True)
    assert missing.exit_code == 2 and "nope.mcm" in missing.output
    broken = cli(command, write("[MC05] MR\n"), catch=True)
    assert broken.exit_code == 1 and "bad-argument" in broken.output
    for result in (missing, broken):
        _no_traceback(result)


@pytest.mark.parametrize("command", ["decompile", "describe"])
def test_a_port_that_cannot_be_opened(command):
    result = cli(command, "--port", "/dev/does-not-exist-mercmac", *FAST, catch=True)
    assert result.exit_code == 2 and "does-not-exist-mercmac" in result.output
    _no_traceback(result)


def test_graph_needs_a_dot_or_svg_name(write):
    result = cli("describe", write(RAW), "--graph", "calls.png", catch=True)
    assert result.exit_code == 2 and "give a .dot or .svg file" in result.output


def test_svg_without_graphviz_says_so(write, tmp_path, monkeypatch):
    monkeypatch.setattr(shutil, "which", lambda name, *a, **k: None)
    result = cli("describe", write(RAW), "--graph", tmp_path / "calls.svg", catch=True)
    assert result.exit_code == 2 and "Graphviz's `dot`" in result.output
    assert "not installed" in result.output and not (tmp_path / "calls.svg").exists()


@needs_pty
def test_decompile_gives_back_a_flashed_source(tmp_path, data_dir):
    from helpers.emulator import serve

    program = tmp_path / "four-modes.mcm"
    shutil.copy(FOUR_MODES, program)
    with serve() as (server, vc):
        assert cli("flash", server.path, program, "--backup", tmp_path / "b.mcm", *FAST).exit_code == 0
        from_port = cli("decompile", "--port", server.path, "-o", tmp_path / "out.mcm", *FAST)
        assert cli("pull", server.path, "--raw", "-o", tmp_path / "raw.mcm", *FAST).exit_code == 0
    assert from_port.exit_code == 0, from_port.output
    assert (tmp_path / "out.mcm").read_text() == program.read_text()
    assert "holds four-modes.mcm, flashed " in from_port.output
    # A file is decompiled from what it holds; the history speaks of controllers:
    # tests/decompile/test_decompile_file.py
    from_file = cli("decompile", tmp_path / "raw.mcm")
    assert from_file.exit_code == 0 and from_file.stdout != program.read_text()
    assert "holds four-modes.mcm" not in from_file.output


@needs_decompiler
def test_decompile_round_trips(write, tmp_path, data_dir):
    from mercmac.compiler import compile_file

    result = cli("decompile", write(RAW), "-o", tmp_path / "out.mcm")
    assert result.exit_code == 0, result.output
    back = compile_file(str(tmp_path / "out.mcm"))
    assert not back.report.has_errors
    assert back.program.md_lines() == ["MD5,MR5000,WS100", "MD0,MA0,EM5"]


@needs_describe
@pytest.mark.parametrize("fmt", ["text", "markdown", "json"])
def test_describe_formats(fmt, write):
    result = cli("describe", write(RAW), "--format", fmt)
    assert result.exit_code == 0, result.output
    assert result.stdout.strip()
    if fmt == "json":
        import json

        json.loads(result.stdout)


@needs_describe
def test_describe_writes_the_call_graph_as_dot(write, tmp_path):
    result = cli("describe", write(RAW), "--graph", tmp_path / "calls.dot")
    assert result.exit_code == 0, result.output
    assert "digraph" in (tmp_path / "calls.dot").read_text()


@needs_describe
@pytest.mark.skipif(shutil.which("dot") is None, reason="Graphviz is not installed")
def test_describe_draws_the_call_graph_as_svg(write, tmp_path):
    result = cli("describe", write(RAW), "--graph", tmp_path / "calls.svg")
    assert result.exit_code == 0, result.output
    assert "<svg" in (tmp_path / "calls.svg").read_text()


def test_commands_are_listed():
    out = cli("--help").output
    for name in ("decompile", "describe", "history"):
        assert name in out
