"""Writing the user's files: the whole new file or the old one, and only where a file belongs.

Every file mercmac writes (build output, backups, pulled programs, VCD dumps,
the emulator's state) goes through here. The text goes to a temporary file in
the same folder, is flushed to disk, and replaces the old file only when it is
complete; on any failure, Ctrl-C included, the temporary file is removed and
the old file is untouched.

Paths are taken deliberately: a symlink is followed (its target is rewritten,
the link stays), an existing file keeps its permission bits, and anything that
is not a regular file (a device such as /dev/null, a FIFO, a folder, a socket)
is refused before anything is written, so a typo never turns /dev/sda into a
regular file.
"""
from __future__ import annotations

import contextlib
import os
import stat
import tempfile
from pathlib import Path
from typing import IO, Iterator

from mercmac.errors import UsageError

TEMP_PREFIX = ".mercmac-"
TEMP_SUFFIX = ".tmp"

_KINDS = (
    (stat.S_ISDIR, "a folder"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISSOCK, "a socket"),
)


class OutputError(UsageError):
    """A file that cannot or must not be written; exit code 2, nothing changed."""


def writable_target(path: str | os.PathLike, *, make_parents: bool = False) -> Path:
    """The regular file that writing PATH will replace (symlinks followed), or OutputError.

    Call it before any work whose result would be lost if the file then could
    not be written (a flash writes its backup before touching the controller).
    """
    given = Path(path)
    target = Path(os.path.realpath(given)) if given.is_symlink() else given
    try:
        st = target.stat()
    except FileNotFoundError:
        st = None
    except OSError as e:
        raise OutputError(f"cannot write {given}: {reason(e)}") from None
    if st is not None and not stat.S_ISREG(st.st_mode):
        kind = next((name for test, name in _KINDS if test(st.st_mode)), "not a regular file")
        raise OutputError(f"cannot write {given}: it is {kind}, not a regular file",
                          hint="give the path of a file to create or replace")
    folder = target.parent
    if make_parents:
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as e:
            raise OutputError(f"cannot create the folder {folder}: {reason(e)}") from None
    if not folder.is_dir():
        missing = "is not a folder" if folder.exists() else "does not exist"
        raise OutputError(f"cannot write {given}: {folder} {missing}")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise OutputError(f"cannot write {given}: no permission to write in {folder}")
    return target


@contextlib.contextmanager
def replacing(path: str | os.PathLike, *, binary: bool = False, encoding: str = "utf-8",
              make_parents: bool = False, durable: bool = True) -> Iterator[IO]:
    """A file object on a temporary file that replaces PATH when the block ends normally."""
    target = writable_target(path, make_parents=make_parents)
    try:
        fd, tmp = tempfile.mkstemp(prefix=TEMP_PREFIX, suffix=TEMP_SUFFIX, dir=target.parent)
    except OSError as e:
        raise OutputError(f"cannot write {path}: {reason(e)}") from None
    try:
        mode = "wb" if binary else "w"
        try:
            f = os.fdopen(fd, mode, **({} if binary else {"encoding": encoding, "newline": "\n"}))
        except BaseException:
            os.close(fd)
            raise
        with f:
            yield f
            f.flush()
            if durable:
                os.fsync(f.fileno())
        _copy_mode(target, tmp)
        os.replace(tmp, target)
    except OSError as e:
        _remove(tmp)
        raise OutputError(f"cannot write {path}: {reason(e)}") from None
    except BaseException:
        _remove(tmp)
        raise
    if durable:
        _sync_folder(target.parent)


def write_text(path: str | os.PathLike, text: str, *, encoding: str = "utf-8",
               make_parents: bool = False) -> Path:
    """Write TEXT to PATH whole or not at all; returns the file written."""
    with replacing(path, encoding=encoding, make_parents=make_parents) as f:
        f.write(text)
    return writable_target(path)


def appending(path: str | os.PathLike, *, encoding: str = "utf-8") -> IO[str]:
    """PATH opened to add text at its end as it goes (a log), created if new; OutputError
    for anything but a regular file. The kind is checked again on what was opened, without
    blocking (O_NONBLOCK), so a FIFO or device put there after the check is refused too."""
    target = writable_target(path)
    flags = (os.O_WRONLY | os.O_APPEND | os.O_CREAT | getattr(os, "O_NONBLOCK", 0)
             | getattr(os, "O_NOCTTY", 0))
    try:
        fd = os.open(target, flags, 0o666)
    except OSError as e:
        raise OutputError(f"cannot write {path}: {reason(e)}") from None
    try:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            kind = next((name for test, name in _KINDS if test(mode)), "not a regular file")
            raise OutputError(f"cannot write {path}: it is {kind}, not a regular file",
                              hint="give the path of a file to create or add to")
        if hasattr(os, "O_NONBLOCK"):
            os.set_blocking(fd, True)
        return os.fdopen(fd, "a", encoding=encoding, newline="\n", buffering=1)
    except BaseException:
        os.close(fd)
        raise


def _copy_mode(target: Path, tmp: str) -> None:
    """The replaced file's permissions (and owner, when allowed); a new file gets the umask's."""
    try:
        st = target.stat()
    except FileNotFoundError:
        os.chmod(tmp, 0o666 & ~_umask())
        return
    os.chmod(tmp, stat.S_IMODE(st.st_mode))
    if hasattr(os, "chown"):
        with contextlib.suppress(OSError):
            os.chown(tmp, st.st_uid, st.st_gid)


def _umask() -> int:
    """The process umask, read without setting it where Linux allows (os.umask is racy in threads)."""
    with contextlib.suppress(OSError, ValueError):
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("Umask:"):
                return int(line.split()[1], 8)
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _sync_folder(folder: Path) -> None:
    """Make the rename itself survive a power cut (POSIX); the file is already in place, so
    a folder that cannot be synced (Windows, some network file systems) is no error."""
    with contextlib.suppress(OSError, AttributeError):
        fd = os.open(folder, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def _remove(tmp: str) -> None:
    with contextlib.suppress(OSError):
        os.unlink(tmp)


def reason(e: BaseException) -> str:
    """The cause in words: 'Input/output error', never `(5, 'Input/output error')` or `[Errno 5]`.

    Also for errors that are not OSErrors but carry (errno, text) the same way (termios.error).
    """
    if isinstance(e, OSError) and e.strerror:
        return e.strerror
    args = e.args[0] if len(e.args) == 1 and isinstance(e.args[0], tuple) else e.args
    if len(args) >= 2 and isinstance(args[0], int) and isinstance(args[1], str):
        return args[1]
    if len(args) == 1 and isinstance(args[0], int):
        return os.strerror(args[0])
    return str(e) or type(e).__name__
