"""`mercmac fmt`: read each file, format it with mercmac.fmt, then write, check or diff it."""
from __future__ import annotations

import difflib
import sys

import click

from mercmac.cli.common import say
from mercmac.errors import EXIT_FAILED, EXIT_OK, EXIT_USAGE


def format_files(files: tuple[str, ...], *, check: bool, diff: bool) -> int:
    """Format FILES; the exit code (docs/cli.md, "Exit codes"): 2 if any could not be done,
    else 1 if --check/--diff found one that would change, else 0."""
    paths, failed = _programs(files)
    changed = unchanged = 0
    for path in paths:
        outcome = _one(path, check=check, diff=diff)
        if outcome is None:
            failed += 1
        elif outcome:
            changed += 1
        else:
            unchanged += 1
    _summary(changed, unchanged, failed, dry=check or diff)
    if failed:
        return EXIT_USAGE
    return EXIT_FAILED if changed and (check or diff) else EXIT_OK


def _programs(files: tuple[str, ...]) -> tuple[list[str], int]:
    """FILES with each rig file (`*.rig.toml`, docs/rigs.md) in the place of its programs, and
    how many rig files could not be read (each said). The rig file itself is TOML that
    the user wrote: fmt leaves it as written."""
    import os

    from mercmac.rig import is_rig_path

    rigs = [path for path in files if is_rig_path(path)]
    if not rigs:
        return list(files), 0
    out, failed = {}, 0  # real path -> as named: a program named twice is formatted once
    for path in files:
        programs = _rig_programs(path) if path in rigs else [path]
        if programs is None:
            failed += 1
            continue
        if path in rigs:
            say(f"{path}: formatting the programs of its {len(programs)} controller"
                f"{'s' * (len(programs) != 1)}; the rig file itself is left as written")
        for program in programs:
            out.setdefault(program if program == "-" else os.path.realpath(program), program)
    return list(out.values()), failed


def _rig_programs(path: str) -> list[str] | None:
    """The program files of the rig at PATH, or None when the rig cannot be read (said)."""
    from mercmac.render import report as render
    from mercmac.rig.open import RigUnreadable, open_rig

    try:
        rig_file = open_rig(path).rig_file  # fmt runs nothing: its programs are not checked
    except RigUnreadable as e:
        say(e.message)
        return None
    if rig_file.rig is None:
        render.write_text(rig_file.report.items, {rig_file.source.name: rig_file.source}, 1,
                          sys.stderr)
        say(f"cannot format the programs of {path}: the rig file has errors")
        return None
    return [c.program for c in rig_file.rig.controllers]


def _one(path: str, *, check: bool, diff: bool) -> bool | None:
    """Whether PATH changed (or would); None when it could not be read, parsed or written.

    The bytes written are the formatted text in the file's own encoding and byte-order mark
    (standard input's too), and the file is replaced only if it still holds what was read.
    """
    from mercmac import outfile
    from mercmac.fmt import FormatError, format_text, load
    from mercmac.names import printable
    from mercmac.source import read_bytes

    name = "<stdin>" if path == "-" else printable(path)
    try:
        data = read_bytes(path)
        before = None if path == "-" else outfile.snapshot(path, data)
        text, encoding = load(data)
        formatted = format_text(text)
        if diff and formatted != text:
            show_diff(text, formatted, name)
        elif path == "-" and not check:
            click.echo(encoding.write(formatted), nl=False)  # bytes: as they came in
        elif check and formatted != text:
            say(f"would reformat {name}")
        elif formatted != text and not check:
            outfile.write_bytes(path, encoding.write(formatted), expect=before)
            say(f"reformatted {name}")  # each file written is named (a rig's programs too)
        return formatted != text
    except FormatError as e:
        say(f"cannot format {name}: {e.message}", e.hint)
    except OSError as e:
        say(f"cannot read {name}: {outfile.reason(e)}")
    except outfile.OutputError as e:
        say(e.message, e.hint)
    except UnicodeEncodeError:
        say(f"cannot write {name}: its characters do not fit its encoding")
    return None


def show_diff(text: str, formatted: str, name: str) -> None:
    """A unified diff of a file's text before and after (`fmt --diff`, `check --diff`)."""
    from mercmac.source import split_lines

    click.echo("".join(difflib.unified_diff(split_lines(text, keepends=True),
                                            split_lines(formatted, keepends=True), name, name)),
               nl=False)


def _summary(changed: int, unchanged: int, failed: int, *, dry: bool) -> None:
    """ruff format's closing line: '1 file would be reformatted, 7 files left unchanged'."""
    def files(n: int) -> str:
        return f"{n} file{'s' * (n != 1)}"

    verb = "would be reformatted" if dry else "reformatted"
    parts = [f"{files(changed)} {verb}" if changed else "",
             f"{files(unchanged)} left unchanged" if unchanged else "",
             f"{files(failed)} not formatted" if failed else ""]
    click.echo(", ".join(p for p in parts if p), err=True)
