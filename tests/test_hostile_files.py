"""Output paths that are not plain files: nothing lost, nothing hangs, no traceback.

`build -o`, `flash --backup` and `pull -o` write whole files or nothing, only where a regular
file belongs: a device or a FIFO is refused before the controller is touched, a symlink is
followed, permissions are kept, and a failed write leaves the old file and no temporary file.
"""
from __future__ import annotations

import errno
import os
import stat
import subprocess
import sys
import termios

import pytest

from helpers.cli import cli
from helpers.files import leftovers
from mercmac import outfile
from helpers.emulator import FAST, serve

PROGRAM = "target C-863\n[MC00] EM5\n[MC05] MR5000,WS100\n"
BUILT = "MD5,MR5000,WS100\nMD0,EM5\n"
ROOT = os.geteuid() == 0 if hasattr(os, "geteuid") else False
EIO = OSError(errno.EIO, os.strerror(errno.EIO))


@pytest.fixture
def fifo(tmp_path):
    """A FIFO with a reader already attached, so that a wrong `open(..., "w")` cannot hang."""
    path = tmp_path / "pipe"
    os.mkfifo(path)
    reader = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    yield path
    os.close(reader)


@pytest.fixture
def device(tmp_path):
    """A character device node like /dev/null (1, 3), made in tmp_path so that no test risks /dev."""
    path = tmp_path / "null"
    try:
        os.mknod(path, stat.S_IFCHR | 0o666, os.makedev(1, 3))
    except (OSError, AttributeError):
        pytest.skip("cannot make a device node here (needs root)")
    return path


def fail_on(monkeypatch, name: str, error: BaseException = EIO) -> None:
    """Make os.NAME raise ERROR, as a full disk or a dying USB stick would."""
    def broken(*args, **kwargs):
        raise error

    monkeypatch.setattr(os, name, broken)


# --- build -o -----------------------------------------------------------------------------------

def test_build_refuses_a_fifo_and_leaves_it_a_fifo(program_file, fifo):
    result = cli("build", program_file, "-o", fifo)
    assert result.exit_code == 2, result.output
    assert "FIFO" in result.output and str(fifo) in result.output
    assert "Traceback" not in result.output
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)


def test_build_refuses_a_device_node(program_file, device):
    result = cli("build", program_file, "-o", device)
    assert result.exit_code == 2, result.output
    assert "character device" in result.output
    assert stat.S_ISCHR(os.lstat(device).st_mode)


@pytest.mark.skipif(not ROOT, reason="only root could turn /dev/null into a file")
def test_build_refuses_dev_null_and_it_stays_a_device(program_file):
    result = cli("build", program_file, "-o", "/dev/null")
    assert result.exit_code == 2, result.output
    assert stat.S_ISCHR(os.lstat("/dev/null").st_mode)


def test_build_refuses_a_folder(program_file, tmp_path):
    result = cli("build", program_file, "-o", tmp_path)
    assert result.exit_code == 2
    assert tmp_path.is_dir()


def test_build_follows_a_symlink(program_file, tmp_path):
    target, link = tmp_path / "real.txt", tmp_path / "link.txt"
    target.write_text("old\n")
    link.symlink_to(target.name)
    result = cli("build", program_file, "-o", link)
    assert result.exit_code == 0, result.output
    assert link.is_symlink() and os.readlink(link) == target.name
    assert target.read_text() == BUILT


def test_build_keeps_the_permissions(program_file, tmp_path):
    out = tmp_path / "out.txt"
    out.write_text("old\n")
    out.chmod(0o640)
    assert cli("build", program_file, "-o", out).exit_code == 0
    assert stat.S_IMODE(out.stat().st_mode) == 0o640 and out.read_text() == BUILT


def test_build_new_file_gets_the_umask_permissions(program_file, tmp_path):
    mask = os.umask(0o027)
    try:
        assert cli("build", program_file, "-o", tmp_path / "new.txt").exit_code == 0
    finally:
        os.umask(mask)
    assert stat.S_IMODE((tmp_path / "new.txt").stat().st_mode) == 0o640


def test_build_failure_keeps_the_old_file_and_no_temp_file(program_file, tmp_path, monkeypatch):
    out = tmp_path / "out.txt"
    out.write_text("old\n")
    fail_on(monkeypatch, "replace")
    result = cli("build", program_file, "-o", out)
    assert result.exit_code == 2
    assert f"cannot write {out}: Input/output error" in result.output
    assert out.read_text() == "old\n" and leftovers(tmp_path) == []


def test_build_running_out_of_space_keeps_the_old_file(program_file, tmp_path):
    """A real write error in a real process: the file size limit stops the write at 8 bytes."""
    out = tmp_path / "out.txt"
    out.write_text("old\n")

    def small_files():
        import resource
        import signal

        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # EFBIG instead of a killed process
        resource.setrlimit(resource.RLIMIT_FSIZE, (8, 8))

    env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1"}
    done = subprocess.run([sys.executable, "-m", "mercmac", "build", str(program_file), "-o", str(out)],
                          capture_output=True, text=True, timeout=60, env=env, preexec_fn=small_files)
    assert done.returncode == 2, done.stderr
    assert "Traceback" not in done.stderr and f"cannot write {out}: File too large" in done.stderr
    assert out.read_text() == "old\n" and leftovers(tmp_path) == []


def test_build_interrupted_keeps_the_old_file(program_file, tmp_path, monkeypatch):
    out = tmp_path / "out.txt"
    out.write_text("old\n")
    fail_on(monkeypatch, "fsync", KeyboardInterrupt())
    result = cli("build", program_file, "-o", out)
    assert result.exit_code == 130
    assert out.read_text() == "old\n" and leftovers(tmp_path) == []


# --- flash --backup -----------------------------------------------------------------------------

@pytest.mark.parametrize("kind", ["fifo", "device"])
def test_flash_refuses_a_backup_that_is_not_a_file_before_touching_the_controller(
        request, program_file, kind):
    bad = request.getfixturevalue(kind)
    with serve(macros={3: "TP"}) as (server, vc):
        result = cli("flash", server.path, program_file, "--backup", bad, *FAST)
        assert result.exit_code == 2, result.output
        assert f"cannot write {bad}" in result.output and "not a regular file" in result.output
        assert vc.md_count == 0 and not vc.lines and vc.macros == {3: "TP"}
    assert not stat.S_ISREG(os.lstat(bad).st_mode)


@pytest.mark.skipif(not ROOT, reason="only root could turn /dev/null into a file")
def test_flash_backup_to_dev_null_is_refused_and_it_stays_a_device(program_file):
    with serve() as (server, vc):
        result = cli("flash", server.path, program_file, "--backup", "/dev/null", *FAST)
        assert result.exit_code == 2, result.output
        assert "character device" in result.output
        assert vc.md_count == 0 and not vc.lines
    assert stat.S_ISCHR(os.lstat("/dev/null").st_mode)


def test_flash_backup_follows_a_symlink_and_keeps_permissions(program_file, tmp_path):
    target, link = tmp_path / "kept.mcm", tmp_path / "latest.mcm"
    target.write_text("// old backup\n")
    target.chmod(0o640)
    link.symlink_to(target)
    with serve(macros={3: "TP"}) as (server, vc):
        result = cli("flash", server.path, program_file, "--backup", link, *FAST)
    assert result.exit_code == 0, result.output
    assert link.is_symlink() and os.readlink(link) == str(target)
    assert "[MC03] TP" in target.read_text()
    assert stat.S_IMODE(target.stat().st_mode) == 0o640


def test_flash_with_a_failing_backup_writes_nothing_and_leaves_no_temp_file(
        program_file, tmp_path, monkeypatch):
    backup = tmp_path / "b.mcm"
    backup.write_text("// older backup\n")
    with serve(macros={3: "TP"}) as (server, vc):
        fail_on(monkeypatch, "fsync")
        result = cli("flash", server.path, program_file, "--backup", backup, *FAST)
        monkeypatch.undo()
        assert result.exit_code == 1, result.output
        assert "Input/output error" in result.output and "nothing was written" in result.output
        assert "(5," not in result.output and "Errno" not in result.output
        assert vc.md_count == 0 and vc.macros == {3: "TP"}
    assert backup.read_text() == "// older backup\n" and leftovers(tmp_path) == []


def test_default_backup_folder_is_still_created(program_file, tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "no" / "such" / "data"))
    with serve(macros={3: "TP"}) as (server, vc):
        result = cli("flash", server.path, program_file, *FAST)
    assert result.exit_code == 0, result.output
    [saved] = (tmp_path / "no" / "such" / "data" / "mercmac" / "backups").glob("*.mcm")
    assert "[MC03] TP" in saved.read_text()


# --- pull -o ------------------------------------------------------------------------------------

@pytest.mark.parametrize("kind", ["fifo", "device"])
def test_pull_refuses_a_path_that_is_not_a_file_before_reading(request, kind):
    bad = request.getfixturevalue(kind)
    with serve(macros={3: "TP"}) as (server, vc):
        result = cli("pull", server.path, "-o", bad, *FAST)
        assert result.exit_code == 2, result.output
        assert "not a regular file" in result.output
        assert not vc.lines
    assert not stat.S_ISREG(os.lstat(bad).st_mode)


@pytest.mark.skipif(not ROOT, reason="only root could turn /dev/full into a file")
def test_pull_to_dev_full_is_refused_and_it_stays_a_device():
    with serve(macros={3: "TP"}) as (server, vc):
        result = cli("pull", server.path, "-o", "/dev/full", *FAST)
        assert result.exit_code == 2, result.output
        assert not vc.lines
    assert stat.S_ISCHR(os.lstat("/dev/full").st_mode)


def test_pull_follows_a_symlink_and_keeps_permissions(tmp_path):
    target, link = tmp_path / "real.mcm", tmp_path / "link.mcm"
    target.write_text("old\n")
    target.chmod(0o640)
    link.symlink_to(target)
    with serve(macros={3: "TP"}) as (server, vc):
        result = cli("pull", server.path, "-o", link, *FAST)
    assert result.exit_code == 0, result.output
    assert link.is_symlink() and "[MC03] TP" in target.read_text()
    assert stat.S_IMODE(target.stat().st_mode) == 0o640


def test_pull_follows_a_dangling_symlink(tmp_path):
    link = tmp_path / "link.mcm"
    link.symlink_to("made.mcm")
    with serve(macros={3: "TP"}) as (server, vc):
        result = cli("pull", server.path, "-o", link, *FAST)
    assert result.exit_code == 0, result.output
    assert link.is_symlink() and "[MC03] TP" in (tmp_path / "made.mcm").read_text()


def test_pull_write_failure_keeps_the_old_file_and_no_temp_file(tmp_path, monkeypatch):
    out = tmp_path / "p.mcm"
    out.write_text("old\n")
    with serve(macros={3: "TP"}) as (server, vc):
        fail_on(monkeypatch, "replace")
        result = cli("pull", server.path, "-o", out, *FAST)
        monkeypatch.undo()
    assert result.exit_code == 2, result.output
    assert f"cannot write {out}: Input/output error" in result.output
    assert out.read_text() == "old\n" and leftovers(tmp_path) == []


# --- the cause in words -------------------------------------------------------------------------

@pytest.mark.parametrize("error", [
    OSError(errno.EIO, "Input/output error"),
    OSError((errno.EIO, "Input/output error")),  # a tuple passed on as one argument
    termios.error(errno.EIO, "Input/output error"),  # not an OSError: str() shows the tuple
    OSError(errno.EIO),
])
def test_reason_says_the_cause_in_words(error):
    assert outfile.reason(error) == "Input/output error"


def test_an_unwritable_folder_is_named(tmp_path, program_file):
    result = cli("build", program_file, "-o", tmp_path / "missing" / "out.txt")
    assert result.exit_code == 2
    assert "does not exist" in result.output and str(tmp_path / "missing") in result.output


def test_a_read_only_folder_is_refused_by_its_mode_even_as_root(tmp_path, program_file):
    """Root writes into a 0555 folder, but the folder says it is not to change,
    as a 0444 file does; and no folder is made in it either."""
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    try:
        into = cli("build", program_file, "-o", ro / "out.txt")
        below = cli("pull", "/dev/null", "-o", ro / "new" / "x.mcm")
    finally:
        ro.chmod(0o755)
    for result in (into, below):
        assert result.exit_code == 2, result.output
        assert f"no permission to write in {ro}" in result.output
    assert list(ro.iterdir()) == []


def test_a_file_name_never_leads_out_of_its_folder(tmp_path):
    for name in ("../x", "/abs", "a/b", "..", ".", "", "a\0b"):
        with pytest.raises(outfile.OutputError, match="no plain file name"):
            outfile.in_folder(tmp_path, name)
    assert outfile.in_folder(tmp_path, "..x.mcm") == tmp_path / "..x.mcm"
