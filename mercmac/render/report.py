"""Diagnostics as text for people (plain or rich, full or concise), as JSON (docs/cli.md), as
GitHub workflow commands and as SARIF 2.1.0."""
from __future__ import annotations

import sys
from typing import IO, Iterable

from mercmac.diagnostics import Diagnostic, Severity
from mercmac.names import SURROGATES, printable
from mercmac.render.console import Line, Piece, use_colour, write_lines
from mercmac.source import Source

_STYLE = {Severity.ERROR: "bold red", Severity.WARNING: "bold yellow", Severity.INFO: "bold cyan"}


# Source lines longer than this are shown as a window around the caret.
WINDOW = 100
# Diagnostics per file unless asked otherwise (`check --max-diagnostics`): a screenful of
# the first ones helps a person; a program gets as many as `sim --format json` gives events.
MAX_TEXT = 200
MAX_JSON = 10_000


def diagnostic_lines(d: Diagnostic, source: Source | None, *, colour: bool = False) -> list[Line]:
    """`file:line:col: severity[CODE rule]: message`, the source line (highlighted in
    `colour`) and a caret."""
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
        code = _highlighted(text, d.span.column - 1) if colour else [(shown, "")]
        lines.append([(gutter, "dim"), *code])
        pad = " " * (len(gutter) + caret)
        lines.append([(pad, ""), ("^" + "~" * (width - 1), _STYLE[d.severity])])
    return lines


def _excerpt(text: str, start: int, width: int) -> tuple[str, int, int]:
    """The part of a source line to show, escaped; the caret's offset and width in it."""
    first, last = _window(text, start)
    start = min(start, last)
    end = min(start + width, last)
    before = ("..." if first else "") + printable(text[first:start])
    marked = printable(text[start:end])
    after = printable(text[end:last]) + ("..." if last < len(text) else "")
    return before + marked + after, len(before), max(len(marked), 1)


def _window(text: str, start: int) -> tuple[int, int]:
    """The part of a source line shown, first..last: a long line shows a window around the
    caret, so output stays small."""
    first = 0
    if len(text) > WINDOW:
        first = min(max(start - WINDOW // 3, 0), len(text) - WINDOW)
    return first, min(first + WINDOW, len(text))


# Rich styles of the .mcm lexer's tokens (mercmac.highlight), the first prefix that fits.
_TOKEN_STYLES = (("Token.Error", "bold red underline"), ("Token.Comment", "dim italic"),
                 ("Token.Keyword.Constant", "cyan"), ("Token.Keyword", "magenta"),
                 ("Token.Operator.Word", "magenta"), ("Token.Name.Builtin", "bold cyan"),
                 ("Token.Name.Label", "bold blue"), ("Token.Name.Function", "green"),
                 ("Token.Name.Constant", "yellow"), ("Token.Literal.Number", "bright_green"))


def _highlighted(text: str, start: int) -> list[Piece]:
    """_excerpt's text in the lexer's colours; only on a colour terminal, for it imports pygments."""
    from mercmac.highlight import McmLexer

    first, last = _window(text, start)
    pieces: list[Piece] = [("...", "")] if first else []
    for at, kind, value in McmLexer().get_tokens_unprocessed(text):
        lo, hi = max(at, first), min(at + len(value), last)
        if lo < hi:
            style = next((s for p, s in _TOKEN_STYLES if str(kind).startswith(p)), "")
            pieces.append((printable(text[lo:hi]), style))
    return pieces + ([("...", "")] if last < len(text) else [])


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
    colour = use_colour(stream or sys.stdout)
    lines: list[Line] = []
    for d in shown:
        lines += diagnostic_lines(d, sources.get(d.file), colour=colour)
    for file, count in left_out.items():
        lines.append([(f"{printable(file)}: {count:,} more diagnostic{'s' if count != 1 else ''} "
                       f"not shown (the first {limit} are); "
                       "`mercmac check --max-diagnostics 0` shows them all", "bold")])
    if summary:
        lines.append(summary_line(diagnostics, files))
    write_lines(lines, stream)


def write_findings(findings, stream: IO[str] | None = None) -> None:
    """Checks' findings (checking.Findings: a compilation and what it reports, one per
    file) in text, as `check` shows them: `sim`, `describe`, `emulate` and `flash` refuse a
    rig with errors this way."""
    write_text([d for f in findings for d in f.diagnostics],
               {f.compilation.source.name: f.compilation.source for f in findings},
               len(findings), stream or sys.stderr)


def finding_texts(findings, limit: int = MAX_TEXT) -> list[str]:
    """The errors of checks' findings (all they report when they refuse without one) as
    `check` words each in text (its line, the source line, the caret), plain, at most
    `limit` per file: the page of `sim --web` lists why a file that changed is not run."""
    sources = {f.compilation.source.name: f.compilation.source for f in findings}
    found = [d for f in findings for d in f.diagnostics]
    errors = [d for d in found if d.severity is Severity.ERROR]
    shown, _ = capped(errors or found, limit)
    return ["\n".join("".join(piece for piece, _ in line)
                      for line in diagnostic_lines(d, sources.get(d.file))) for d in shown]


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
    write_text(result.report.items, {result.source.name: result.source}, 1, stream or sys.stderr)
    return True


def write_warnings(result, stream: IO[str] | None = None) -> None:
    """Show a compilation's warnings on stderr (infos stay with `check`); `build` and
    `flash` go on: a warning is worth reading, not a reason to refuse."""
    warnings = [d for d in result.report.items if d.severity is Severity.WARNING]
    if warnings:
        write_text(warnings, {result.source.name: result.source}, 1, stream or sys.stderr,
                   summary=False)  # "0 infos" would be untrue: infos are left out


def to_json(diagnostics: Iterable[Diagnostic], limit: int = MAX_JSON) -> str:
    """The `check --format json` object (docs/cli.md, "JSON output"); with more than
    `limit` diagnostics in a file (0: no limit), the first `limit` and
    `"truncated": {file: count left out}`."""
    import json

    kept, left_out = capped(diagnostics, limit)
    out: dict = {"diagnostics": [d.as_json() for d in kept]}
    if left_out:
        out["truncated"] = left_out
    return json.dumps(out, indent=2)


# -- check's other output formats (`check --output-format`) ------------------------------

def write_concise(diagnostics: list[Diagnostic], files: int, stream: IO[str] | None = None,
                  *, limit: int = MAX_TEXT) -> None:
    """One line per diagnostic, `file:line:col: CODE [rule] message` (ruff's concise), the
    number left out and the closing count line."""
    shown, left_out = capped(diagnostics, limit)
    lines: list[Line] = [[
        (f"{printable(d.file)}:{d.span.line}:{d.span.column}: ", "bold"),
        (d.rule.code, _STYLE[d.severity]), (f" [{d.rule.name}]", "dim"),
        (f" {printable(d.message)}", ""),
    ] for d in shown]
    lines += [[(f"{printable(file)}: {count:,} more not shown", "bold")]
              for file, count in left_out.items()]
    write_lines([*lines, summary_line(diagnostics, files)], stream)


# GitHub workflow commands: the level of each severity, and the escapes of the command's
# message and of its properties (actions/toolkit, packages/core/src/command.ts).
_GITHUB_LEVEL = {Severity.ERROR: "error", Severity.WARNING: "warning", Severity.INFO: "notice"}
_GITHUB_DATA = str.maketrans({"%": "%25", "\r": "%0D", "\n": "%0A"})
_GITHUB_PROPERTY = str.maketrans({"%": "%25", "\r": "%0D", "\n": "%0A", ":": "%3A", ",": "%2C"})


def to_github(diagnostics: Iterable[Diagnostic], limit: int = MAX_JSON) -> str:
    """`::error file=F,line=L,col=C,endLine=..,endColumn=..,title=CODE rule::message` per
    diagnostic: GitHub Actions shows them as annotations on the pull request's lines."""
    kept, left_out = capped(diagnostics, limit)
    out = []
    for d in kept:
        end_line, end_column = d.end
        where = {"file": _github_file(d.file), "line": d.span.line, "col": d.span.column,
                 "endLine": end_line, "endColumn": end_column,
                 "title": f"{d.rule.code} {d.rule.name}"}
        props = ",".join(f"{k}={str(v).translate(_GITHUB_PROPERTY)}" for k, v in where.items())
        out.append(f"::{_GITHUB_LEVEL[d.severity]} {props}::{d.message.translate(_GITHUB_DATA)}")
    for file, count in left_out.items():
        out.append(f"::warning file={_github_file(file).translate(_GITHUB_PROPERTY)}::{count} "
                   f"more diagnostics not shown (--max-diagnostics)")
    return "".join(line + "\n" for line in out)


def _github_file(file: str) -> str:
    """A path as the repository names it; a byte that is not UTF-8 as `\\xff`, the one
    thing a workflow command cannot carry."""
    return file.replace("\\", "/").translate(SURROGATES)


_SARIF_LEVEL = {Severity.ERROR: "error", Severity.WARNING: "warning", Severity.INFO: "note"}
SARIF_SCHEMA = "https://json.schemastore.org/sarif-2.1.0.json"


def to_sarif(diagnostics: Iterable[Diagnostic], limit: int = MAX_JSON) -> str:
    """A SARIF 2.1.0 log of one run (GitHub code scanning, editors); every rule is listed
    in the driver, and each result points at its rule by id and index."""
    import json

    from mercmac import __version__
    from mercmac.diagnostics import RULES

    kept, left_out = capped(diagnostics, limit)
    index = {r.code: i for i, r in enumerate(RULES)}
    run: dict = {
        "tool": {"driver": {"name": "mercmac", "version": __version__,
                            "rules": [_sarif_rule(r) for r in RULES]}},
        "columnKind": "unicodeCodePoints",  # columns count characters, as in the text output
        "results": [_sarif_result(d, index[d.rule.code]) for d in kept],
    }
    if left_out:
        run["properties"] = {"truncated": left_out}
    return json.dumps({"$schema": SARIF_SCHEMA, "version": "2.1.0", "runs": [run]}, indent=2)


def _sarif_rule(r) -> dict:
    from mercmac.render.rules_page import url

    return {"id": r.code, "name": r.name, "shortDescription": {"text": r.summary},
            "fullDescription": {"text": r.explanation}, "help": {"text": r.explanation},
            "helpUri": url(r),
            "defaultConfiguration": {"level": _SARIF_LEVEL[r.severity]}}


def _sarif_result(d: Diagnostic, rule_index: int) -> dict:
    end_line, end_column = d.end
    region = {"startLine": d.span.line, "startColumn": d.span.column,
              "endLine": end_line, "endColumn": end_column}
    location = {"artifactLocation": {"uri": _uri(d.file)}, "region": region}
    result = {"ruleId": d.rule.code, "ruleIndex": rule_index, "level": _SARIF_LEVEL[d.severity],
              "message": {"text": d.message}, "locations": [{"physicalLocation": location}]}
    if d.fix is not None:
        result["fixes"] = [_sarif_fix(d)]
    return result


def _sarif_fix(d: Diagnostic) -> dict:
    """A result's fix (SARIF §3.55): its title, the one replacement, and its applicability
    as a property, as ruff writes it."""
    edit = d.fix.as_json()["edits"][0]
    deleted = {"startLine": edit["line"], "startColumn": edit["column"],
               "endLine": edit["end_line"], "endColumn": edit["end_column"]}
    return {"description": {"text": d.fix.title},
            "artifactChanges": [{"artifactLocation": {"uri": _uri(d.file)},
                                 "replacements": [{"deletedRegion": deleted,
                                                   "insertedContent": {"text": edit["content"]}}]}],
            "properties": {"applicability": str(d.fix.applicability)}}


def _uri(file: str) -> str:
    """A file as a URI: relative paths stay relative (to the repository, for GitHub).

    SARIF §3.4.3 takes RFC 3986 URIs: the name's file-system bytes, percent-encoded, so
    that a name that is not UTF-8 (`b\\xff.mcm`) becomes `b%FF.mcm`, not an encoding error.
    """
    import os
    from pathlib import Path
    from urllib.parse import quote

    if os.path.isabs(file):
        return Path(file).as_uri()  # file:///..., percent-encoded from os.fsencode too
    return quote(os.fsencode(file.replace("\\", "/")))


def rule_counts(diagnostics: Iterable[Diagnostic]) -> list[tuple[Diagnostic, int]]:
    """One diagnostic of each rule and severity with its count, most frequent first."""
    counts: dict[tuple[str, Severity], list] = {}
    for d in diagnostics:
        counts.setdefault((d.rule.code, d.severity), [d, 0])[1] += 1
    return sorted(((d, n) for d, n in counts.values()),
                  key=lambda dn: (-dn[1], dn[0].rule.code, dn[0].severity))


def write_statistics(diagnostics: list[Diagnostic], files: int,
                     stream: IO[str] | None = None) -> None:
    """`check --statistics`: how often each rule was found, and the closing count line."""
    lines: list[Line] = [[
        (f"{n:>6}  ", "bold"), (d.rule.code, _STYLE[d.severity]),
        (f"  {d.rule.name:<24}", "dim"), (f"  {d.severity}", ""),
    ] for d, n in rule_counts(diagnostics)]
    write_lines([*lines, summary_line(diagnostics, files)], stream)


def statistics_json(diagnostics: list[Diagnostic]) -> str:
    """`check --statistics --output-format json`: {"statistics": [{code, rule, severity, count}]}."""
    import json

    return json.dumps({"statistics": [
        {"code": d.rule.code, "rule": d.rule.name, "severity": str(d.severity), "count": n}
        for d, n in rule_counts(diagnostics)]}, indent=2)
