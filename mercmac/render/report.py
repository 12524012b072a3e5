"""Diagnostics as text for people (plain or rich) and as JSON (SPEC §5)."""
from __future__ import annotations

from typing import IO, Iterable

from mercmac.diagnostics import Diagnostic, Severity
from mercmac.render.console import Line, write_lines
from mercmac.source import Source

_STYLE = {Severity.ERROR: "bold red", Severity.WARNING: "bold yellow", Severity.INFO: "bold cyan"}


# Source lines longer than this are shown as a window around the caret.
WINDOW = 100
# Diagnostics per file unless asked otherwise (`check --max-diagnostics`): a screenful of
# the first ones helps a person; a program gets as many as `sim --format json` gives events.
MAX_TEXT = 200
MAX_JSON = 10_000
# Characters that would act on the terminal or hide text: C0/C1 controls, DEL, line and
# paragraph separators, zero-width and bidirectional marks ("Trojan Source").
_HIDDEN = {c: f"\\x{c:02x}" for c in (*range(0x20), *range(0x7F, 0xA0))}
_HIDDEN |= {c: f"\\u{c:04x}" for c in (0x2028, 0x2029, *range(0x200B, 0x2010),
                                         *range(0x202A, 0x202F), *range(0x2066, 0x206A), 0xFEFF)}
_HIDDEN[0x09] = " "  # a tab shows as one space, so the caret stays under its column


def printable(text: str) -> str:
    """`text` with control and invisible characters escaped (`\\x1b`), safe for a terminal."""
    return text.translate(_HIDDEN)


def diagnostic_lines(d: Diagnostic, source: Source | None) -> list[Line]:
    """`file:line:col: severity[CODE rule]: message`, the source line and a caret."""
    lines: list[Line] = [[
        (f"{printable(d.file)}:{d.span.line}:{d.span.column}: ", "bold"),
        (str(d.severity), _STYLE[d.severity]),
        (f"[{d.rule.code} {d.rule.name}]", "dim"),
        (f": {printable(d.message)}", ""),
    ]]
    text = source.line(d.span.line) if source else ""
    if text.strip():
        width = 1
        if d.span.end_line == d.span.line and d.span.end_column > d.span.column:
            width = d.span.end_column - d.span.column
        shown, caret, width = _excerpt(text, d.span.column - 1, width)
        gutter = f"{d.span.line:>5} | "
        lines.append([(gutter, "dim"), (shown, "")])
        pad = " " * (len(gutter) + caret)
        lines.append([(pad, ""), ("^" + "~" * (width - 1), _STYLE[d.severity])])
    return lines


def _excerpt(text: str, start: int, width: int) -> tuple[str, int, int]:
    """The part of a source line to show, escaped; the caret's offset and width in it."""
    first = 0
    if len(text) > WINDOW:  # a long line: a window around the caret, so output stays small
        first = min(max(start - WINDOW // 3, 0), len(text) - WINDOW)
    last = min(first + WINDOW, len(text))
    start = min(start, last)
    end = min(start + width, last)
    before = ("..." if first else "") + printable(text[first:start])
    marked = printable(text[start:end])
    after = printable(text[end:last]) + ("..." if last < len(text) else "")
    return before + marked + after, len(before), max(len(marked), 1)


def summary_line(diagnostics: list[Diagnostic], files: int) -> Line:
    """'2 errors, 1 warning, 0 infos in 3 files' - or that all is well."""
    counts = {s: sum(d.severity is s for d in diagnostics) for s in Severity}
    where = f"{files} file" + ("s" if files != 1 else "")
    if not diagnostics:
        return [(f"No problems found in {where}.", "bold green")]
    parts = [f"{n} {s}{'s' if n != 1 else ''}" for s, n in counts.items()]
    style = _STYLE[Severity.ERROR] if counts[Severity.ERROR] else _STYLE[Severity.WARNING]
    return [(", ".join(parts) + f" in {where}.", style)]


def write_text(diagnostics: list[Diagnostic], sources: dict[str, Source], files: int,
               stream: IO[str] | None = None, *, summary: bool = True,
               limit: int = MAX_TEXT) -> None:
    """Errors first, then warnings, then infos, at most `limit` per file (0: all); the
    number left out; a closing count line."""
    shown, left_out = capped(diagnostics, limit)
    lines: list[Line] = []
    for d in shown:
        lines += diagnostic_lines(d, sources.get(d.file))
    for file, count in left_out.items():
        lines.append([(f"{printable(file)}: {count:,} more diagnostic{'s' if count != 1 else ''} "
                       f"not shown (the first {limit} are); "
                       "`mercmac check --max-diagnostics 0` shows them all", "bold")])
    if summary:
        lines.append(summary_line(diagnostics, files))
    write_lines(lines, stream)


def capped(diagnostics: Iterable[Diagnostic], limit: int) -> tuple[list[Diagnostic], dict[str, int]]:
    """The diagnostics in order, at most `limit` per file (0: all), and the count left out per file."""
    kept: list[Diagnostic] = []
    per_file: dict[str, int] = {}
    left_out: dict[str, int] = {}
    for d in sorted(diagnostics, key=Diagnostic.sort_key):
        n = per_file[d.file] = per_file.get(d.file, 0) + 1
        if limit and n > limit:
            left_out[d.file] = left_out.get(d.file, 0) + 1
        else:
            kept.append(d)
    return kept, left_out


def write_errors(result, stream: IO[str] | None = None) -> bool:
    """Show a compilation's diagnostics on stderr if it has errors; True when it had.

    `build`, `sim` and `flash` refuse a file with errors this way.
    """
    if not result.report.has_errors and result.program is not None:
        return False
    import sys

    write_text(result.report.items, {result.source.name: result.source}, 1, stream or sys.stderr)
    return True


def to_json(diagnostics: Iterable[Diagnostic], limit: int = MAX_JSON) -> str:
    """The `check --format json` object (SPEC §5); with more than `limit` diagnostics in a
    file (0: no limit), the first `limit` and `"truncated": {file: count left out}`."""
    import json

    kept, left_out = capped(diagnostics, limit)
    out: dict = {"diagnostics": [d.as_json() for d in kept]}
    if left_out:
        out["truncated"] = left_out
    return json.dumps(out, indent=2)
