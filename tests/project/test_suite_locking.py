"""What pytest-xdist workers share runs one at a time: two processes that take the lock of
helpers.locking (the VS Code tests' `npm ci`, tests/project/test_vscode_extension.py) are
never inside at once, however they are scheduled."""
from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

import pytest

from helpers.locking import held, lock_file
from helpers.paths import ROOT

# One process of the test: inside the lock it claims the folder's `inside` file (a second
# claim means two are in), says it entered, and stays until the test says `go`.
WORKER = """
import sys, time
from pathlib import Path
sys.path.insert(0, sys.argv[1])
from helpers.locking import held
folder, name = Path(sys.argv[2]), sys.argv[3]
with held(folder / "work.lock"):
    try:
        (folder / "inside").open("x").close()
    except FileExistsError:
        (folder / "overlap").touch()
    (folder / f"{name}.in").touch()
    while not (folder / "go").exists():
        time.sleep(0.01)
    (folder / "inside").unlink(missing_ok=True)
"""
WAIT_S = 60  # for an event that comes at once on a quiet machine


def _start(folder: Path, name: str) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-c", WORKER, str(ROOT / "tests"), str(folder), name])


def _waiting_on(path: Path) -> bool:
    """Whether a process waits for the flock on `path` (Linux: a `->` line of /proc/locks)."""
    inode = f":{path.stat().st_ino} "
    text = Path("/proc/locks").read_text()
    return any("-> FLOCK" in line and inode in line for line in text.splitlines())


def _until(condition) -> None:
    end = time.monotonic() + WAIT_S
    while not condition():
        assert time.monotonic() < end, "the processes never got there"
        time.sleep(0.01)


@pytest.mark.skipif(not Path("/proc/locks").exists(), reason="needs Linux's /proc/locks")
def test_a_second_process_waits_until_the_first_has_left(tmp_path):
    first = _start(tmp_path, "first")
    _until(lambda: (tmp_path / "first.in").exists())
    second = _start(tmp_path, "second")
    try:
        _until(lambda: _waiting_on(tmp_path / "work.lock") or (tmp_path / "second.in").exists())
        assert not (tmp_path / "second.in").exists(), "both processes were inside at once"
    finally:
        (tmp_path / "go").touch()
        assert first.wait(timeout=WAIT_S) == 0 and second.wait(timeout=WAIT_S) == 0
    assert (tmp_path / "second.in").exists() and not (tmp_path / "overlap").exists()


def test_the_lock_of_a_folder_is_outside_it_and_its_own(tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    ours = lock_file(tmp_path / "a")
    assert ours == lock_file(tmp_path / "a") != lock_file(tmp_path / "b")
    assert tmp_path not in ours.parents
    with held(ours):
        assert ours.exists()
