"""Diagnostics as text for people (plain or rich) and as JSON (SPEC §5)."""
from __future__ import annotations

from typing import IO, Iterable

from mercmac.diagnostics import Diagnostic, Severity
from mercmac.render.console import Line, write_lines
from mercmac.source import Source

_STYLE = {Severity.ERROR: "bold red", Severity.WARNING: "bold yellow", Severity.INFO: "bold cyan"}


def diagnostic_lines(d: Diagnostic, source: Source | None) -> list[Line]:
    """`file:line:col: severity[CODE rule]: message`, the source line and a caret."""
    lines: list[Line] = [[
        (f"{d.file}:{d.span.line}:{d.span.column}: ", "bold"),
        (str(d.severity), _STYLE[d.severity]),
        (f"[{d.rule.code} {d.rule.name}]", "dim"),
        (f": {d.message}", ""),
    ]]
    text = source.line(d.span.line) if source else ""
    if text.strip():
        width = 1
        if d.span.end_line == d.span.line and d.span.end_column > d.span.column:
            width = d.span.end_column - d.span.column
        gutter = f"{d.span.line:>5} | "
        lines.append([(gutter, "dim"), (text.expandtabs(1), "")])
        pad = " " * (len(gutter) + d.span.column - 1)
        lines.append([(pad, ""), ("^" + "~" * (width - 1), _STYLE[d.severity])])
    return lines


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
               stream: IO[str] | None = None, *, summary: bool = True) -> None:
    """Errors first, then warnings, then infos; a closing count line."""
    lines: list[Line] = []
    for d in sorted(diagnostics, key=Diagnostic.sort_key):
        lines += diagnostic_lines(d, sources.get(d.file))
    if summary:
        lines.append(summary_line(diagnostics, files))
    write_lines(lines, stream)


def write_errors(result, stream: IO[str] | None = None) -> bool:
    """Show a compilation's diagnostics on stderr if it has errors; True when it had.

    `build`, `sim` and `flash` refuse a file with errors this way.
    """
    if not result.report.has_errors and result.program is not None:
        return False
    import sys

    write_text(result.report.items, {result.source.name: result.source}, 1, stream or sys.stderr)
    return True


def to_json(diagnostics: Iterable[Diagnostic]) -> str:
    """The `check --format json` object (SPEC §5)."""
    import json

    ordered = sorted(diagnostics, key=Diagnostic.sort_key)
    return json.dumps({"diagnostics": [d.as_json() for d in ordered]}, indent=2)
