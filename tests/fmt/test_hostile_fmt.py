"""`mercmac fmt` (and the reading `check` shares) under hostile files: nothing
lost, nothing hangs, no traceback.

Bytes that do not decode exactly, UTF-16/32 byte order,
an edit made while formatting, read-only files, hard links, SIGTERM, standard input's
encoding, FIFOs, devices and files too large to read.
"""
from __future__ import annotations

import errno
import os
import signal
import stat
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

import mercmac
import mercmac.fmt
from helpers.cli import cli
from helpers.files import leftovers

MESSY = b"macro a {mr5}\n"
NEAT = b"macro a { MR 5 }\n"
MAX_BYTES = 16 * 1024 * 1024  # what mercmac reads of a .mcm file (docs/cli.md, "Limits")
# Where the mercmac under test lives: a child process started there imports the same one.
PACKAGE_ROOT = Path(mercmac.__file__).resolve().parent.parent


def run(*args, timeout: float = 60, **kw) -> subprocess.CompletedProcess:
    """`mercmac ARGS` as a real process."""
    return subprocess.run([sys.executable, "-m", "mercmac", *map(str, args)], cwd=PACKAGE_ROOT,
                          capture_output=True, text=True, timeout=timeout, **kw)


@pytest.fixture
def messy(tmp_path):
    path = tmp_path / "a.mcm"
    path.write_bytes(MESSY)
    return path


# -- item 2: only bytes that read back exactly --------------------------------------------------

@pytest.mark.parametrize("data, where", [
    # a UTF-8 file (its BOM says so) with one Windows-1252 byte in a comment
    (b"\xef\xbb\xbf// Mercury\x99 Macro File\r\n[MC00] em1\r\n", "byte 0x99 at line 1"),
    # UTF-16 with a lone surrogate on line 2
    (b"\xff\xfe" + "// a\n".encode("utf-16-le") + b"\x00\xd8"
     + "\n[MC00] em1\n".encode("utf-16-le"), "bytes 0x00 0xD8 at line 2"),
    # neither UTF-8 nor Windows-1252: 0x81 is no character in either
    (b"// a\r\n// \x81\r\n[MC00] em1\r\n", "byte 0x81 at line 2"),
], ids=["utf8-bom-cp1252-byte", "utf16-lone-surrogate", "undefined-cp1252-byte"])
def test_fmt_refuses_a_byte_it_cannot_write_back_and_names_it(tmp_path, data, where):
    path = tmp_path / "a.mcm"
    path.write_bytes(data)
    result = cli("fmt", path)
    assert result.exit_code == 2 and where in result.output, result.output
    assert path.read_bytes() == data and leftovers(tmp_path) == []


@pytest.mark.parametrize("codec, bom", [
    ("utf-16-be", b"\xfe\xff"), ("utf-32-be", b"\x00\x00\xfe\xff"),
    ("cp1252", b""),  # MMCRun's header: '(TM)' is the single byte 0x99 (MS176E §3.8.6)
])
def test_fmt_writes_each_encoding_back_with_its_byte_order_and_bom(tmp_path, codec, bom):
    path = tmp_path / "a.mcm"
    head = "// Mercury\u2122 Macro File\r\n"
    path.write_bytes(bom + (head + "macro a {mr5}\r\n").encode(codec))
    assert cli("fmt", path).exit_code == 0
    assert path.read_bytes() == bom + (head + "macro a { MR 5 }\r\n").encode(codec)


@pytest.mark.parametrize("codec, bom", [("utf-16-le", b"\xff\xfe"), ("cp1252", b"")])
def test_fmt_of_standard_input_keeps_its_encoding_and_bom(codec, bom):
    data = bom + "// \u2122\r\nmacro a {mr5}\r\n".encode(codec)
    result = cli("fmt", "-", input=data)
    assert result.exit_code == 0
    assert result.stdout_bytes == bom + "// \u2122\r\nmacro a { MR 5 }\r\n".encode(codec)


# -- item 3: an edit made while formatting ------------------------------------------------------

def test_fmt_keeps_a_line_appended_while_it_formats(messy, monkeypatch):
    real = mercmac.fmt.format_text

    def slow(text):  # another program saves while the (large) file is formatted
        with open(messy, "ab") as f:
            f.write(b"// appended\n")
        return real(text)

    monkeypatch.setattr(mercmac.fmt, "format_text", slow)
    result = cli("fmt", messy)
    assert result.exit_code == 2 and "changed after it was read" in result.output
    assert messy.read_bytes() == MESSY + b"// appended\n"
    assert leftovers(messy.parent) == []


def test_fmt_sees_an_edit_of_the_same_size_and_time(messy, monkeypatch):
    """Only the content tells: same size, and the modification time put back."""
    real = mercmac.fmt.format_text
    st = messy.stat()

    def slow(text):
        messy.write_bytes(MESSY.replace(b"5", b"6"))
        os.utime(messy, ns=(st.st_atime_ns, st.st_mtime_ns))
        return real(text)

    monkeypatch.setattr(mercmac.fmt, "format_text", slow)
    assert cli("fmt", messy).exit_code == 2
    assert messy.read_bytes() == MESSY.replace(b"5", b"6")


@pytest.mark.slow
def test_fmt_in_a_real_process_never_loses_a_concurrent_append(tmp_path):
    """A real writer appends once while a real `mercmac fmt` works on a 1 MB file: whenever it
    lands (before the read, during formatting, after the write), the line is kept."""
    path = tmp_path / "big.mcm"
    path.write_bytes(MESSY * 70_000)
    proc = subprocess.Popen([sys.executable, "-m", "mercmac", "fmt", str(path)], cwd=PACKAGE_ROOT,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(1.0)  # python and mercmac start, the file is read, formatting is under way
    with open(path, "ab") as f:
        f.write(b"// appended meanwhile\n")
    _, err = proc.communicate(timeout=120)
    assert proc.returncode in (0, 2) and "Traceback" not in err, err
    assert path.read_bytes().endswith(b"// appended meanwhile\n")
    assert leftovers(tmp_path) == []


# -- item 4: read-only files and hard links -----------------------------------------------------

def test_fmt_refuses_a_read_only_file_by_its_mode_even_as_root(messy):
    messy.chmod(0o444)
    result = cli("fmt", messy)
    assert result.exit_code == 2 and "is read-only" in result.output
    assert messy.read_bytes() == MESSY and stat.S_IMODE(messy.stat().st_mode) == 0o444


def test_fmt_keeps_hard_links(messy):
    other = messy.parent / "b.mcm"
    os.link(messy, other)
    inode = messy.stat().st_ino
    assert cli("fmt", messy).exit_code == 0
    assert messy.read_bytes() == other.read_bytes() == NEAT
    assert messy.stat().st_ino == other.stat().st_ino == inode and messy.stat().st_nlink == 2
    assert leftovers(messy.parent) == []


def failing_once(monkeypatch, name: str, error: int):
    """os.NAME fails the first time (a disk error), then works (the restore)."""
    real, calls = getattr(os, name), []

    def once(*args):
        calls.append(args)
        if len(calls) == 1:
            raise OSError(error, os.strerror(error))
        return real(*args)

    monkeypatch.setattr(os, name, once)
    return calls


def test_a_failed_in_place_write_puts_the_old_bytes_back(messy, monkeypatch):
    """The new text is already over the old one when cutting it to length fails."""
    other = messy.parent / "b.mcm"
    os.link(messy, other)
    calls = failing_once(monkeypatch, "ftruncate", errno.EIO)
    result = cli("fmt", messy)
    assert len(calls) == 2  # the write's, then the restore's
    assert result.exit_code == 2 and "Input/output error" in result.output
    assert messy.read_bytes() == other.read_bytes() == MESSY
    assert messy.stat().st_nlink == 2 and leftovers(messy.parent) == []


def test_no_space_for_an_in_place_write_changes_nothing(messy, monkeypatch):
    os.link(messy, messy.parent / "b.mcm")
    failing_once(monkeypatch, "posix_fallocate", errno.ENOSPC)
    result = cli("fmt", messy)
    assert result.exit_code == 2 and "No space left on device" in result.output
    assert messy.read_bytes() == MESSY and leftovers(messy.parent) == []


def test_when_even_the_restore_fails_the_old_text_is_kept_beside_and_named(messy, monkeypatch):
    os.link(messy, messy.parent / "b.mcm")

    def broken(fd, size):
        raise OSError(errno.EIO, os.strerror(errno.EIO))

    monkeypatch.setattr(os, "ftruncate", broken)
    result = cli("fmt", messy)
    kept = leftovers(messy.parent)
    assert result.exit_code == 2 and len(kept) == 1 and str(kept[0]) in result.output
    assert kept[0].read_bytes() == MESSY


# -- item 21: SIGTERM while the file is written ------------------------------------------------

# `mercmac` whose Nth fsync sends the process SIGTERM, as `kill` would while a file is written.
KILLED_WHILE_WRITING = """
import os, signal, sys
real, calls = os.fsync, []
def fsync(fd):
    calls.append(fd)
    if len(calls) == int(sys.argv[1]):
        os.kill(os.getpid(), signal.SIGTERM)
    real(fd)
os.fsync = fsync
from mercmac.cli import main
main(sys.argv[2:])
"""


@pytest.mark.parametrize("links, nth, left", [
    (1, 1, MESSY),  # the temporary file is written: it goes, the old file stays
    (2, 1, MESSY),  # the same before an in-place write
    (2, 2, NEAT),  # the copy of the old bytes is made: SIGTERM waits until the write is done
    (2, 3, NEAT),  # the file is overwritten in place: the same
], ids=["replace", "links-temporary", "links-copy", "links-in-place"])
def test_sigterm_while_writing_leaves_a_whole_file_and_no_temporary_one(messy, links, nth, left):
    if links == 2:
        os.link(messy, messy.parent / "b.mcm")
    done = subprocess.run([sys.executable, "-c", KILLED_WHILE_WRITING, str(nth), "fmt", str(messy)],
                          cwd=PACKAGE_ROOT, capture_output=True, text=True, timeout=60)
    assert done.returncode == 128 + signal.SIGTERM, done.stderr  # answered as Ctrl-C (docs/cli.md)
    assert done.stderr.splitlines() == ["mercmac: interrupted (SIGTERM)"]
    assert leftovers(messy.parent) == [] and messy.read_bytes() == left


# -- items 9 and 10: only regular files, and not too large --------------------------------------

@pytest.mark.parametrize("command", ["check", "fmt"])
def test_a_fifo_named_as_a_file_is_refused_without_hanging(tmp_path, command):
    fifo = tmp_path / "b.mcm"
    os.mkfifo(fifo)
    done = run(command, fifo, timeout=30)
    assert done.returncode == 2 and "it is a FIFO (named pipe), not a regular file" in done.stderr


def _small_memory():
    import resource

    resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))  # the old reader ran out of it


@pytest.mark.parametrize("command", ["check", "fmt"])
def test_dev_zero_is_refused_at_once(command):
    done = run(command, "/dev/zero", timeout=60, preexec_fn=_small_memory)
    assert done.returncode == 2, done.stderr
    assert "cannot read /dev/zero: it is a character device, not a regular file" in done.stderr


@pytest.mark.parametrize("command", ["check", "fmt"])
def test_a_file_larger_than_mercmac_reads_is_refused_with_its_size(tmp_path, command):
    big = tmp_path / "big.mcm"
    with open(big, "wb") as f:
        f.write(b"// " + b"x" * 1000 + b"\n")
        f.truncate(MAX_BYTES + 4 * 1024 * 1024)  # sparse: 20 MB that take no disk
    result = cli(command, big)
    assert result.exit_code == 2
    assert f"cannot read {big}: it is 20.0 MB: larger than mercmac reads (16 MB)" in result.output
    assert big.stat().st_size == MAX_BYTES + 4 * 1024 * 1024


@pytest.mark.parametrize("command", ["check", "fmt"])
def test_standard_input_larger_than_mercmac_reads_is_refused(command):
    data = b"// " + b"x" * MAX_BYTES + b"\n"
    result = cli(command, "-", input=data)
    assert result.exit_code == 2
    assert "it holds more than mercmac reads (16 MB)" in result.output


def test_a_fifo_with_a_writer_is_refused_too(tmp_path):
    """A writer is attached: opening would not block, reading would wait for it to end."""
    fifo = tmp_path / "b.mcm"
    os.mkfifo(fifo)
    stop = threading.Event()

    def writer():
        fd = os.open(fifo, os.O_RDWR)  # holds the FIFO open for writing, never closes early
        stop.wait(30)
        os.close(fd)

    thread = threading.Thread(target=writer)
    thread.start()
    try:
        done = run("fmt", fifo, timeout=30)
    finally:
        stop.set()
        thread.join()
    assert done.returncode == 2 and "not a regular file" in done.stderr


@pytest.mark.parametrize("command", ["check", "fmt"])
def test_a_closed_standard_input_is_said_not_a_traceback(command):
    done = run(command, "-", stdin=None, timeout=60, close_fds=True,
               preexec_fn=lambda: os.close(0))
    assert done.returncode == 2 and "standard input is closed" in done.stderr, done.stderr
