"""`mercmac fmt`: read each file, format it with mercmac.fmt, then write, check or diff it."""
from __future__ import annotations

import difflib

import click

from mercmac.cli.common import say
from mercmac.errors import EXIT_FAILED, EXIT_OK, EXIT_USAGE


def format_files(files: tuple[str, ...], *, check: bool, diff: bool) -> int:
    """Format FILES; the exit code (SPEC §5): 2 if any could not be done, else 1 if
    --check/--diff found one that would change, else 0."""
    changed = unchanged = failed = 0
    for path in files:
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


def _one(path: str, *, check: bool, diff: bool) -> bool | None:
    """Whether PATH changed (or would); None when it could not be read, parsed or written.

    The bytes written are the formatted text in the file's own encoding and byte-order mark
    (standard input's too), and the file is replaced only if it still holds what was read.
    """
    from mercmac import outfile
    from mercmac.fmt import FormatError, format_text, load
    from mercmac.source import read_bytes

    name = "<stdin>" if path == "-" else path
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
