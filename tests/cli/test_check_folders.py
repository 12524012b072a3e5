"""`check DIR` and `fmt DIR`: only regular .mcm files are read
(`.MCM` too), a FIFO or a device below the folder is named as skipped instead of hanging
the walk, an unreadable subfolder is named, and either makes the exit code 2."""
from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

from helpers.cli import as_nobody, cli

pytestmark = pytest.mark.skipif(os.name != "posix", reason="FIFOs, file modes and links")
CLEAN = "[MC00] TP\n"
UGLY = "[MC00]   TP ,  TT\n"  # fmt rewrites it
ROOT = os.geteuid() == 0


def _run(*args, cwd, user: bool = False) -> subprocess.CompletedProcess:
    """`mercmac ARGS` as a real process, so that a hang is a timeout and not a stuck test;
    with USER, as `nobody` when the tests run as root (root reads any folder)."""
    prefix = as_nobody() if user else []
    env = dict(os.environ, NO_COLOR="1")
    return subprocess.run([*prefix, sys.executable, "-m", "mercmac", *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=60, preexec_fn=_memory_cap)


def _memory_cap() -> None:
    """At most 2 GB of address space: a reader of /dev/zero fails instead of filling the
    machine's memory."""
    import resource

    resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))


@pytest.fixture
def project(tmp_path):
    """p/a.mcm (clean), p/b.mcm a FIFO with no writer, p/c.mcm (needs formatting)."""
    (tmp_path / "p").mkdir()
    (tmp_path / "p" / "a.mcm").write_text(CLEAN, encoding="utf-8")
    os.mkfifo(tmp_path / "p" / "b.mcm")
    (tmp_path / "p" / "c.mcm").write_text(UGLY, encoding="utf-8")
    return tmp_path


def test_check_names_a_fifo_below_a_folder_and_checks_the_rest(project):
    done = _run("check", "--output-format", "concise", "p", cwd=project)
    assert done.returncode == 2, done.stderr
    assert f"skipped {Path('p', 'b.mcm')}: it is a FIFO" in done.stderr
    assert "in 2 files" in done.stdout  # a.mcm and c.mcm were checked


def test_fmt_names_a_fifo_below_a_folder_and_formats_the_rest(project):
    done = _run("fmt", "p", cwd=project)
    assert done.returncode == 2, done.stderr
    assert f"skipped {Path('p', 'b.mcm')}: it is a FIFO" in done.stderr
    assert (project / "p" / "c.mcm").read_text(encoding="utf-8") != UGLY  # formatted


def test_a_link_to_a_device_below_a_folder_is_skipped(tmp_path):
    (tmp_path / "a.mcm").write_text(CLEAN, encoding="utf-8")
    (tmp_path / "zero.mcm").symlink_to("/dev/zero")
    (tmp_path / "gone.mcm").symlink_to(tmp_path / "nowhere.mcm")
    done = _run("check", str(tmp_path), cwd=tmp_path)  # a process of its own: see _memory_cap
    assert done.returncode == 2, done.stderr
    assert f"skipped {tmp_path / 'zero.mcm'}: it is a character device" in done.stderr
    assert f"skipped {tmp_path / 'gone.mcm'}: No such file or directory" in done.stderr
    assert "in 1 file" in done.stdout


def test_a_link_loop_is_not_followed(tmp_path):
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "a.mcm").write_text("[MC00] XX1\n", encoding="utf-8")
    (tmp_path / "sub" / "loop").symlink_to(tmp_path, target_is_directory=True)
    (tmp_path / "B.MCM").write_text("[MC00] XX1\n", encoding="utf-8")
    result = cli("check", "--output-format", "concise", tmp_path)
    assert result.exit_code == 1 and "in 2 files" in result.output  # each file once


@pytest.mark.parametrize("name", ["PROG.MCM", "prog.Mcm"])
def test_mcm_in_any_case_is_taken(tmp_path, name):
    (tmp_path / "p").mkdir()
    (tmp_path / "p" / name).write_text("[MC00] XX1\n", encoding="utf-8")
    result = cli("check", "--output-format", "concise", tmp_path / "p")
    assert result.exit_code == 1 and f"{name}:1:8: MM002" in result.output
    (tmp_path / "p" / name).write_text(UGLY, encoding="utf-8")
    assert cli("fmt", "--check", tmp_path / "p").exit_code == 1  # would reformat it


@pytest.mark.parametrize("command", [["check"], ["fmt", "--check"]])
def test_an_unreadable_subfolder_is_named_and_exits_2(command):
    folder = Path(tempfile.mkdtemp())
    try:
        folder.chmod(0o755)
        (folder / "a.mcm").write_text(CLEAN, encoding="utf-8")
        (folder / "locked").mkdir()
        (folder / "locked" / "b.mcm").write_text("[MC00] XX1\n", encoding="utf-8")
        (folder / "locked").chmod(0)
        done = _run(*command, str(folder), cwd="/", user=True)
        assert done.returncode == 2, (done.stdout, done.stderr)
        assert f"skipped {folder / 'locked'}: cannot read the folder: Permission denied" \
            in done.stderr
        assert "Traceback" not in done.stderr
    finally:
        (folder / "locked").chmod(0o755)
        (folder / "locked" / "b.mcm").unlink()
        (folder / "locked").rmdir()
        (folder / "a.mcm").unlink()
        folder.rmdir()


def test_named_files_is_a_library_function(tmp_path):
    from mercmac.files import named_files

    (tmp_path / "d").mkdir()
    (tmp_path / "d" / "b.MCM").write_text(CLEAN, encoding="utf-8")
    os.mkfifo(tmp_path / "d" / "a.mcm")
    (tmp_path / "e").mkdir()
    named = named_files(["-", str(tmp_path / "d"), str(tmp_path / "e")])
    assert named.files == ["-", str(tmp_path / "d" / "b.MCM")]
    assert [s.path for s in named.skipped] == [str(tmp_path / "d" / "a.mcm")]
    assert named.empty == [str(tmp_path / "e")]
