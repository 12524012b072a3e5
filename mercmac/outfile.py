"""Writing the user's files: the whole new file or the old one, and only where a file belongs.

Every file mercmac writes (build output, backups, pulled programs, VCD dumps,
the emulator's state, `fmt`) goes through here. The text goes to a temporary file in
the same folder, is flushed to disk, and replaces the old file only when it is
complete; on any failure, Ctrl-C, SIGTERM and SIGHUP included, the temporary file is removed
and the old file is untouched.

A file with more than one name (hard links) is written in place instead, so that every
name sees the new text: the new bytes are complete on disk first, the old
bytes are copied beside the file, the space is reserved, and only then is the file
overwritten and cut to length, with Ctrl-C, SIGTERM and SIGHUP held off. If that fails (an I/O
error) the old bytes are written back; if even that fails, or the machine stops midway,
the copy beside the file (`.mercmac-*.tmp`) holds the old text, and the error names it.

A read-only file (no write permission bit, as an editor sees it, even for root) is
refused, and so is a file in a read-only folder (no write permission bit: root could
write there, but the folder says it is not meant to change). A caller that read the file first may pass what it read (`Snapshot`): the
file is then replaced only if it still holds exactly that (size, modification time and
SHA-256), so that an edit another program saved meanwhile is not lost. The comparison
and the replacement are two steps (no file system offers a compare-and-swap of a file):
only an edit saved in the microseconds between them would go unseen.

Paths are taken deliberately: a symlink is followed (its target is rewritten,
the link stays), an existing file keeps its permission bits, and anything that
is not a regular file (a device such as /dev/null, a FIFO, a folder, a socket)
is refused before anything is written, so a typo never turns /dev/sda into a
regular file. In a folder mercmac fills with files it names itself (`fill`: `pull --rig`),
a symlink is never followed but refused, and every file is checked before the first is
written; a file already there is replaced only when the caller says so.
"""
from __future__ import annotations

import contextlib
import errno
import os
import signal
import stat
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Iterator, NamedTuple

from mercmac.errors import STOPPING, InputError, held_signals

TEMP_PREFIX = ".mercmac-"
TEMP_SUFFIX = ".tmp"

_KINDS = (
    (stat.S_ISDIR, "a folder"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISSOCK, "a socket"),
)


class OutputError(InputError):
    """A file that cannot or must not be written; exit code 2, nothing changed."""


def kind(mode: int) -> str:
    """What a file of this st_mode is, in words: 'a FIFO (named pipe)', 'a folder', ..."""
    return next((name for test, name in _KINDS if test(mode)), "not a regular file")


class Snapshot(NamedTuple):
    """What a file held when it was read: its size, modification time and SHA-256."""

    size: int
    mtime_ns: int
    digest: bytes


def snapshot(path: str | os.PathLike, data: bytes) -> Snapshot:
    """The snapshot of PATH, just read as DATA (stat after the read: a change in between
    shows as a size or a digest that does not match)."""
    import hashlib  # here: a run that writes no file does not import it (start-up)

    return Snapshot(len(data), os.stat(path).st_mtime_ns, hashlib.sha256(data).digest())


def writable_target(path: str | os.PathLike, *, make_parents: bool = False,
                    follow: bool = True) -> Path:
    """The regular file that writing PATH will replace (symlinks followed, or with
    FOLLOW False refused), or OutputError.

    Call it before any work whose result would be lost if the file then could
    not be written (a flash writes its backup before touching the controller).
    """
    given = Path(path)
    if not follow and given.is_symlink():
        raise OutputError(f"cannot write {given}: it is a symbolic link, not followed here",
                          hint="remove the link, or choose another folder")
    target = _followed(given)
    try:
        st = target.stat()
    except FileNotFoundError:
        st = None
    except OSError as e:
        raise OutputError(f"cannot write {given}: {reason(e)}") from None
    if st is not None and not stat.S_ISREG(st.st_mode):
        raise OutputError(f"cannot write {given}: it is {kind(st.st_mode)}, not a regular file",
                          hint="give the path of a file to create or replace")
    if st is not None and _read_only(target, st):
        raise OutputError(f"cannot write {given}: it is read-only",
                          hint="make it writable (chmod u+w) if it is meant to change")
    folder = target.parent
    if not make_parents and not folder.is_dir():
        missing = "is not a folder" if folder.exists() else "does not exist"
        raise OutputError(f"cannot write {given}: {folder} {missing}")
    writable_folder(folder, make=make_parents, doing=f"cannot write {given}")
    return target


def writable_folder(folder: str | os.PathLike, *, make: bool = False, doing: str = "") -> Path:
    """FOLDER, where new files may be written (made with its parents when MAKE), or
    OutputError starting with DOING. A missing folder is judged by the nearest one above it
    that exists, where it would be made: read-only as a file is (_read_only), even for root,
    who could otherwise make and fill folders in a 0555 one."""
    folder = Path(folder)
    doing = doing or f"cannot write in {folder}"
    there = next((p for p in (folder, *folder.parents) if p.exists()), folder)
    if not there.is_dir():
        raise OutputError(f"{doing}: {there} is not a folder")
    if _read_only(there, there.stat()):
        raise OutputError(f"{doing}: no permission to write in {there}",
                          hint="make it writable (chmod u+w) if it is meant to change")
    if make:
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as e:
            raise OutputError(f"cannot create the folder {folder}: {reason(e)}") from None
    return folder


def _followed(given: Path) -> Path:
    """The file a path names: a symlink's target (which is rewritten; the link stays)."""
    return Path(os.path.realpath(given)) if given.is_symlink() else given


def _read_only(path: Path, st: os.stat_result) -> bool:
    """As an editor sees it: no write permission bit at all (root may write anything, but a
    0444 file or a 0555 folder says it is not meant to change), or not writable by this user
    (a folder: not writable and searchable)."""
    access = os.W_OK | (os.X_OK if stat.S_ISDIR(st.st_mode) else 0)
    return not st.st_mode & 0o222 or not os.access(path, access)


def in_folder(folder: str | os.PathLike, name: str) -> Path:
    """FOLDER/NAME, or OutputError when NAME is no plain file name (a separator, '.', '..',
    a NUL): a name made from what a rig file, the history or a controller said must never
    lead out of the folder it was meant for."""
    seps = {os.sep, os.altsep} - {None}
    if name in ("", ".", "..") or "\0" in name or any(sep in name for sep in seps):
        raise OutputError(f"cannot write {name!r} in {folder}: it is no plain file name",
                          hint="a name with a path separator or '..' would lead out of the folder")
    return Path(folder) / name


class Occupied(OutputError):
    """Files that are there already and are not to be replaced (`fill` without REPLACE)."""

    def __init__(self, paths: list[Path]):
        self.paths = paths
        super().__init__("there already: " + ", ".join(map(str, paths)))


def fill(folder: str | os.PathLike, texts: dict[str, str], *, replace: bool = False) -> list[Path]:
    """Write each of TEXTS (file name -> text) into FOLDER (made if missing), every target
    checked before the first is written, so that a refusal writes nothing: a name that is no
    plain file name, anything writable_target refuses, a symlink (never followed in a folder
    mercmac fills, even with REPLACE: it could point anywhere), and unless REPLACE, a file
    that is there already (Occupied, naming them all). Returns the files written."""
    paths = _fillable(folder, list(texts), replace)
    writable_folder(folder, make=True)
    for path, text in zip(paths, texts.values()):
        write_text(path, text, follow=False)
    return paths


def _fillable(folder: str | os.PathLike, names: list[str], replace: bool) -> list[Path]:
    """FOLDER/NAME for each of NAMES, or the refusal `fill` would make, before anything is
    written."""
    paths = [in_folder(folder, name) for name in names]
    writable_folder(folder, doing=f"cannot write in {folder}")
    there = []
    for path in paths:
        if path.is_symlink():
            raise OutputError(f"cannot write {path}: it is a symbolic link (to "
                              f"{os.readlink(path)}); mercmac does not write through a link "
                              f"in a folder it fills", hint="remove the link, or choose "
                              "another folder")
        if os.path.lexists(path):
            writable_target(path)  # a folder, a device, a read-only file: refused
            there.append(path)
    if there and not replace:
        raise Occupied(there)
    return paths


def fill_tree(root: str | os.PathLike, texts: dict[str, str], *,
              replace: bool = False) -> list[Path]:
    """`fill` for a tree: TEXTS maps a path below ROOT ('rigs/raster/x.mcm', parts joined
    by '/') to its text. Every folder on the way is made if missing and none may be a
    symlink (never followed in a tree mercmac fills); every target of every folder is
    checked before the first is written (Occupied names all the files there already)."""
    groups: dict[tuple[str, ...], dict[str, str]] = {}
    for path, text in texts.items():
        *folders, name = path.split("/")
        groups.setdefault(tuple(folders), {})[name] = text
    there = []
    for folders, group in groups.items():
        try:
            _fillable(_subfolder(root, folders), list(group), replace)
        except Occupied as e:
            there += e.paths
    if there:
        raise Occupied(there)
    return [path for folders, group in groups.items()
            for path in fill(_subfolder(root, folders), group, replace=replace)]


def _subfolder(root: str | os.PathLike, parts: tuple[str, ...]) -> Path:
    """ROOT/PART/..., each part a plain name and, where it exists, a folder and no link."""
    folder = Path(root)
    for part in parts:
        folder = in_folder(folder, part)
        if folder.is_symlink():
            raise OutputError(f"cannot write in {folder}: it is a symbolic link (to "
                              f"{os.readlink(folder)}); mercmac does not write through a link "
                              f"in a folder it fills", hint="remove the link, or choose "
                              "another folder")
        if os.path.lexists(folder) and not folder.is_dir():
            raise OutputError(f"cannot write in {folder}: it is no folder",
                              hint="move it away, or choose another folder")
    return folder


@contextlib.contextmanager
def replacing(path: str | os.PathLike, **how) -> Iterator[IO]:
    """A file object on a temporary file that replaces PATH when the block ends normally
    (in place when PATH has hard links); HOW as for `drafting`."""
    with drafting(path, **how) as draft:
        yield draft.file


@dataclass(slots=True)
class Draft:
    """The new file `drafting` writes, and whether it is to replace the old one."""

    file: IO
    keep: bool = True  # False: the old file stays (a VCD cut short by Ctrl-C is no dump to keep)


@contextlib.contextmanager
def drafting(path: str | os.PathLike, *, binary: bool = False, encoding: str = "utf-8",
             make_parents: bool = False, durable: bool = True,
             expect: Snapshot | None = None, follow: bool = True) -> Iterator[Draft]:
    """`replacing`, with the last word left to the caller: a Draft whose file replaces PATH
    when the block ends normally, unless `keep` was set False; with EXPECT, only if PATH
    still holds that; FOLLOW as for writable_target."""
    target = writable_target(path, make_parents=make_parents, follow=follow)
    with _terminable(path):
        try:
            import tempfile  # here: start-up of runs that write no file

            fd, tmp = tempfile.mkstemp(prefix=TEMP_PREFIX, suffix=TEMP_SUFFIX, dir=target.parent)
        except OSError as e:
            raise OutputError(f"cannot write {path}: {reason(e)}") from None
        try:
            mode = "wb" if binary else "w"
            try:
                text = {} if binary else {"encoding": encoding, "newline": "\n"}
                f = os.fdopen(fd, mode, **text)
            except BaseException:
                os.close(fd)
                raise
            draft = Draft(f)
            with f:
                yield draft
                f.flush()
                if durable and draft.keep:
                    os.fsync(f.fileno())
            if not draft.keep:  # the caller let it go: the old file stays as it was
                _remove(tmp)
                return
            _unchanged(target, expect, path)
            _put(tmp, target, path)
        except OSError as e:
            _remove(tmp)
            raise OutputError(f"cannot write {path}: {reason(e)}") from None
        except BaseException:
            _remove(tmp)
            raise
    if durable:
        _sync_folder(target.parent)


def write_bytes(path: str | os.PathLike, data: bytes, *, make_parents: bool = False,
                expect: Snapshot | None = None, follow: bool = True) -> Path:
    """Write DATA to PATH whole or not at all; returns the file written."""
    with replacing(path, binary=True, make_parents=make_parents, expect=expect,
                   follow=follow) as f:
        f.write(data)
    return _followed(Path(path))


def write_text(path: str | os.PathLike, text: str, *, encoding: str = "utf-8",
               make_parents: bool = False, expect: Snapshot | None = None,
               follow: bool = True) -> Path:
    """Write TEXT to PATH whole or not at all (UnicodeEncodeError before anything is
    written); returns the file written."""
    return write_bytes(path, text.encode(encoding), make_parents=make_parents, expect=expect,
                       follow=follow)


def _unchanged(target: Path, expect: Snapshot | None, path) -> None:
    """OutputError unless TARGET still holds what EXPECT says was read (`fmt`
    of a large file takes a while, and an editor may save meanwhile)."""
    if expect is None:
        return
    try:
        st = target.stat()
        same = (st.st_size, st.st_mtime_ns) == expect[:2] and _digest(target) == expect.digest
    except FileNotFoundError:
        same = False
    if not same:
        raise OutputError(f"cannot write {path}: it changed after it was read (another "
                          "program wrote to it); left as it is now",
                          hint="run the command again")


def _digest(path: Path) -> bytes:
    import hashlib

    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.digest()


def _put(tmp: str, target: Path, path) -> None:
    """The complete temporary file becomes TARGET: renamed over it, or copied into it in
    place when TARGET has other names (hard links) that must see the new text too."""
    try:
        # lstat: a symlink put there since the check is replaced itself, never written through
        links = target.lstat().st_nlink
    except FileNotFoundError:
        links = 1
    if links > 1:
        _overwrite(target, tmp, path)
        _remove(tmp)
        return
    _copy_mode(target, tmp)
    os.replace(tmp, target)


def _overwrite(target: Path, new: str, path) -> None:
    """Copy NEW over TARGET in place, whole or not at all (see the module's docstring)."""
    with held_signals():  # also while the copy is made and removed: none is left behind
        keep = _copy_beside(target)
        try:
            _copy_into(new, target)
        except BaseException as e:  # an I/O error, or a signal that another thread took
            _restore(keep, target, path, e)
            raise
        _remove(keep)


def _restore(keep: str, target: Path, path, cause: BaseException) -> None:
    """Put the old bytes back after a failed in-place write; OutputError naming the copy
    that holds them when even that fails."""
    try:
        _copy_into(keep, target)
    except OSError:
        raise OutputError(f"cannot write {path}: {reason(cause)}, and its old text could not "
                          f"be put back: it is in {keep}",
                          hint=f"copy {keep} over {path} when the disk works again") from None
    _remove(keep)


def _copy_beside(target: Path) -> str:
    """A durable copy of TARGET's bytes in its folder: what a failed in-place write restores."""
    import tempfile

    fd, keep = tempfile.mkstemp(prefix=TEMP_PREFIX, suffix=TEMP_SUFFIX, dir=target.parent)
    try:
        with os.fdopen(fd, "wb") as out, open(target, "rb") as old:
            for block in iter(lambda: old.read(1 << 20), b""):
                out.write(block)
            out.flush()
            os.fsync(out.fileno())
    except BaseException:
        _remove(keep)
        raise
    return keep


def _copy_into(source: str | Path, target: Path) -> None:
    """SOURCE's bytes over TARGET's, same inode: space reserved first, cut to length last."""
    with open(source, "rb") as src, open(target, "r+b") as out:
        size = os.fstat(src.fileno()).st_size
        if size and hasattr(os, "posix_fallocate"):
            try:
                os.posix_fallocate(out.fileno(), 0, size)  # ENOSPC here, before a byte changes
            except OSError as e:
                if e.errno not in (errno.EOPNOTSUPP, errno.EINVAL, errno.ENOSYS):
                    raise
        for block in iter(lambda: src.read(1 << 20), b""):
            out.write(block)
        out.flush()
        os.ftruncate(out.fileno(), size)
        os.fsync(out.fileno())


class _Terminated(BaseException):
    """SIGTERM during a write: unwinds it like Ctrl-C, so that the temporary file goes."""


def _terminated(signum, frame) -> None:
    raise _Terminated


@contextlib.contextmanager
def _terminable(path) -> Iterator[None]:
    """While a file is written, SIGTERM, if it would end the process on the spot (SIG_DFL),
    raises _Terminated (main thread only, where Python runs signal handlers), so that the
    cleanup runs; then the signal is delivered again and the process ends, killed by SIGTERM,
    as it would have. A command of mercmac's has its own handler (cli.common.run_guarded: the
    KeyboardInterrupt that Ctrl-C raises too), which the cleanup already answers."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.getsignal(signal.SIGTERM)
    if previous is not signal.SIG_DFL:
        yield
        return
    signal.signal(signal.SIGTERM, _terminated)
    try:
        yield
    except _Terminated:
        signal.signal(signal.SIGTERM, previous)
        signal.raise_signal(signal.SIGTERM)
        raise OutputError(f"cannot write {path}: stopped by SIGTERM") from None
    finally:
        signal.signal(signal.SIGTERM, previous)


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
            raise OutputError(f"cannot write {path}: it is {kind(mode)}, not a regular file",
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
