"""Which .mcm files a set of arguments names: each file as given, every .mcm below each
folder (`check DIR`, `fmt DIR`).

Below a folder only regular files are taken: a FIFO would block its reader for good and a
device never ends, so they are named as skipped, as is every folder that
cannot be read. Symbolic links to folders are not followed (os.walk's default), so a
link loop ends the walk instead of running it forever. A file named on the command line
is left to `mercmac.source.read_source`, which refuses what it cannot read.
"""
from __future__ import annotations

import os
import stat
from typing import NamedTuple

from mercmac.outfile import kind, reason

SUFFIX = ".mcm"  # in any case: `PROG.MCM` from a Windows share is one too


class Skipped(NamedTuple):
    """A file or folder below an argument that was passed over, and why (in words)."""

    path: str
    why: str


class Named(NamedTuple):
    """The files to read, in order; what was skipped; the folders that hold no .mcm file."""

    files: list[str]
    skipped: list[Skipped]
    empty: list[str]


def named_files(arguments: tuple[str, ...] | list[str]) -> Named:
    """The files that ARGUMENTS name ('-' is standard input), each folder's sorted."""
    files: list[str] = []
    skipped: list[Skipped] = []
    empty: list[str] = []
    for argument in arguments:
        if argument == "-" or not os.path.isdir(argument):
            files.append(argument)
            continue
        found, passed_over = _below(argument)
        if not found and not passed_over:
            empty.append(argument)
        files += found
        skipped += passed_over
    return Named(files, skipped, empty)


def _below(folder: str) -> tuple[list[str], list[Skipped]]:
    """The regular .mcm files below FOLDER, sorted; and what was skipped there."""
    skipped: list[Skipped] = []

    def unreadable(e: OSError) -> None:
        skipped.append(Skipped(e.filename or folder, f"cannot read the folder: {reason(e)}"))

    found = []
    for top, _, names in os.walk(folder, onerror=unreadable):
        for name in names:
            if name.lower().endswith(SUFFIX):
                path = os.path.join(top, name)
                why = _not_readable(path)
                if why:
                    skipped.append(Skipped(path, why))
                else:
                    found.append(path)
    return sorted(found), sorted(skipped)


def _not_readable(path: str) -> str | None:
    """Why PATH is not a file to read (a FIFO, a device, a broken link); None if it is."""
    try:
        mode = os.stat(path).st_mode  # through a link: a link to a regular file is taken
    except OSError as e:
        return reason(e)
    return None if stat.S_ISREG(mode) else f"it is {kind(mode)}, not a regular file"
