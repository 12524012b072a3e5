"""What a controller holds, as a `.mcm` file: the flash backup and `mercmac pull`.

The file is MMCRun's format (MS176E §3.8.6, Example 4) with a `target`
line, so `mercmac check` accepts it and `mercmac flash` puts back exactly
these macros.
"""
from __future__ import annotations

import datetime as _dt
import re
from pathlib import Path

from mercmac import __version__, outfile
from mercmac.mdtext import slot_name
from mercmac.names import printable
from mercmac.upload.protocol import Version


DATA_DIR_VARIABLE = "MERCMAC_DATA_DIR"


class BackupError(Exception):
    """The backup file cannot be written; nothing may be flashed then."""

    def __init__(self, message: str, hint: str | None = None):
        super().__init__(message)
        self.hint = hint


def to_mcm(macros: dict[int, str], version: Version, *, port: str, address: int,
           when: _dt.datetime | None = None) -> str:
    """The .mcm text: a header comment, `target`, then one `[MCnn]` line per stored slot.
    The port and VE's text are escaped (mercmac.names): a newline in a port's name would end
    the comment, and what follows it would be read as lines of the program."""
    when = when or _dt.datetime.now().astimezone()
    head = [
        "// Mercury(TM) Macro File",
        f"// read by mercmac {__version__} from {printable(port)}, address {address}, "
        f"on {when.isoformat(timespec='seconds')}",
        f"// controller: {version.name}, firmware {version.firmware}",
        f"// VE: {printable(version.text)}",
        f"// {len(macros)} macro{'s' if len(macros) != 1 else ''} stored",
        f"target {version.model}" if version.model else "// no `target`: VE names no known model",
        "",
    ]
    body = [f"[{slot_name(slot)}] {text}" for slot, text in sorted(macros.items())]
    return "\n".join(head + body) + "\n"


def default_path(port: str, address: int, when: _dt.datetime | None = None) -> Path:
    """A timestamped file in the per-user data directory: never overwrites an older backup."""
    when = when or _dt.datetime.now()
    folder = data_dir() / "backups"
    stem = f"{port_tag(port)}-addr{address}-{when.strftime('%Y%m%d-%H%M%S')}"
    path, n = folder / f"{stem}.mcm", 1
    while path.exists():
        n += 1
        path = folder / f"{stem}-{n}.mcm"
    return path


def data_dir() -> Path:
    """mercmac's per-user data directory (backups, flash history); $MERCMAC_DATA_DIR overrides it."""
    import os

    if chosen := os.environ.get(DATA_DIR_VARIABLE):
        return Path(chosen)
    import platformdirs

    return Path(platformdirs.user_data_dir("mercmac", appauthor=False))


def check(path: Path) -> Path:
    """The file a save to PATH will replace (its folders made), or BackupError: call it before
    the controller is touched, so that a device, a FIFO or a folder is refused first."""
    try:
        return outfile.writable_target(path, make_parents=True)
    except outfile.OutputError as e:
        raise BackupError(e.message) from None


def check_default() -> Path:
    """The folder of the timestamped backups (default_path), or BackupError when it cannot
    be written there: checked before the port opens, as a --backup path is (check), so that
    an unwritable data folder is the same I/O problem, with nothing touched."""
    folder = data_dir() / "backups"
    try:
        return outfile.writable_folder(folder, doing=f"cannot write backups in {folder}")
    except outfile.OutputError as e:
        raise BackupError(f"{e.message} (the per-user data folder)",
                          hint=f"set ${DATA_DIR_VARIABLE} to a folder that can be written, "
                               f"or give --backup PATH") from None


def save(text: str, path: Path) -> Path:
    """Write atomically and durably: a power cut leaves the old file or the whole new one.

    Only a regular file (or a new path) is replaced; a symlink is followed and the old file's
    permissions are kept (mercmac.outfile). Returns PATH as given.
    """
    try:
        outfile.write_text(path, text, make_parents=True)
    except outfile.OutputError as e:
        raise BackupError(e.message) from None
    return path


def port_tag(port: str) -> str:
    """'/dev/ttyUSB0' -> 'ttyUSB0', '/dev/pts/3' -> 'pts-3', 'socket://lab:4001' -> 'lab-4001'."""
    tail = port.split("://", 1)[-1]
    tail = re.sub(r"^(/dev/|\\\\\.\\)", "", tail)
    return re.sub(r"[^A-Za-z0-9_.]+", "-", tail).strip("-") or "port"

