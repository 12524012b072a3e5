"""`check --fix`: the safe fixes of what `check` reports, applied to the text.

    source --check--> findings with Fix data --applied, checked again--> fixed text

A fix is data on its diagnostic (mercmac.diagnostics.Fix, made where the check finds the
problem), with its applicability: only safe fixes are made unless `unsafe` (--unsafe-fixes)
adds the guesses; display-only ones never are. The language server offers the same fixes
as quick fixes, and the `target` line as a source action (`target_fix`). Fixes are made pass after pass on the text the
last pass made; a pass that would make the file parse worse is not made, so a file is
fixed as a whole or not at all. A file is read and written byte for byte as `fmt` does
(mercmac.source.decode_exact, mercmac.outfile): its encoding, byte-order mark and line
ends stay.
"""
from __future__ import annotations

import re
from typing import NamedTuple

from mercmac.compiler import checking
from mercmac.compiler.checking import Choice, Findings, Options
from mercmac.diagnostics import SAFE, Applicability, Diagnostic, Fix
from mercmac.errors import InputError
from mercmac.source import LINE_END, Source, Span, split_lines

# Each pass checks the text the last one made: a fix may bring out another (`cal scna`
# becomes `call scna`, and then 'scna' is a macro name that means 'scan'). Bounded: fixes
# that undo each other would never settle.
MAX_PASSES = 10


class Made(NamedTuple):
    """One fix made, and the finding it resolves (None for the `target` line added)."""

    fix: Fix
    diagnostic: Diagnostic | None


class Fixed(NamedTuple):
    """What fixing one source did: the text before and after, the fixes made, the check of
    the text after, and of the text before."""

    before: str
    after: str
    made: list[Made]
    findings: Findings
    first: Findings

    def left(self, applicability: Applicability) -> list[Diagnostic]:
        """The findings after that have a fix of this applicability (not made)."""
        return [d for d in self.findings.diagnostics
                if d.fix is not None and d.fix.applicability is applicability]


class FileFixed(NamedTuple):
    """What fixing one file did, and why the fixes were not written when they were not
    (then the file is as it was, and `findings` are its own)."""

    fixed: Fixed
    refused: InputError | None = None

    @property
    def findings(self) -> Findings:
        return self.fixed.first if self.refused else self.fixed.findings


def fix_file(path: str, chosen: Options = Options(), *, write: bool = True,
             unsafe: bool = False) -> FileFixed:
    """Fix the file at PATH ('-': standard input, which is never written) under its
    settings and `chosen`, the unsafe fixes too if `unsafe`, and write it back byte for
    byte but for the fixes, if `write`; OSError when it cannot be read."""
    from mercmac import outfile
    from mercmac.source import decode, read_bytes

    data = read_bytes(path)
    before = None if path == "-" else outfile.snapshot(path, data)
    name = "<stdin>" if path == "-" else path
    fixed = fix(Source(name, decode(data)), checking.choice_for(path, chosen), unsafe=unsafe)
    if not fixed.made:
        return FileFixed(fixed)
    try:
        encoding = _encoding(data, name)
        if write:
            outfile.write_bytes(path, encoding.write(fixed.after), expect=before)
    except InputError as e:  # OutputError: read-only, changed meanwhile, ...
        return FileFixed(fixed, InputError(f"{e.message}; not fixed", hint=e.hint))
    return FileFixed(fixed)


def _encoding(data: bytes, name: str):
    """The file's encoding, that writes its text back as these bytes; InputError naming
    the first byte that does not read (a U+FFFD is never written back)."""
    from mercmac.source import EncodingError, decode_exact

    try:
        return decode_exact(data)[1]
    except EncodingError as e:
        raise InputError(f"cannot fix {name}: {e.message}",
                         hint="fix that byte, or save the file in one encoding") from None


def fix(source: Source, choice: Choice, *, unsafe: bool = False) -> Fixed:
    """`source` with the safe fixes of what `check` reports made (the unsafe ones too if
    `unsafe`), then a `target` line for the model chosen (`--target`, or the settings)
    when the text names none."""
    first = checking.check(source, choice)
    findings, made = first, []
    for _ in range(MAX_PASSES):
        wanted = [Made(d.fix, d) for d in findings.diagnostics
                  if d.fix is not None and d.fix.applicability.applied(unsafe)]
        better = _better(findings, wanted, choice)
        if better is None:
            break
        findings, made = better[0], made + better[1]
    added = target_fix(findings.compilation.source.text, choice.target)
    if added is not None:
        better = _better(findings, [Made(added, None)], choice)
        if better is not None:
            findings, made = better[0], made + better[1]
    return Fixed(source.text, findings.compilation.source.text, made, findings, first)


def _better(before: Findings, wanted: list[Made],
            choice: Choice) -> tuple[Findings, list[Made]] | None:
    """The check of the text with the fixes `wanted` made, and those made; None when none
    could be, or when they would add a syntax error (a fix must not break the file)."""
    text, made = apply(before.compilation.source.text, wanted)
    if not made:
        return None
    after = checking.check(Source(before.compilation.source.name, text), choice)
    return None if _broken(after) > _broken(before) else (after, made)


def _broken(findings: Findings) -> int:
    """How many syntax errors the compiler found, reported or not."""
    return sum(d.rule.name == "syntax" for d in findings.compilation.report.items)


def apply(text: str, wanted: list[Made]) -> tuple[str, list[Made]]:
    """`text` with the fixes made in the order of the text, and those made. A fix that
    overlaps one made before it is left for the next pass, which checks whether it still
    applies; the same fix twice is made once."""
    starts = [0, *(m.end() for m in LINE_END.finditer(text))]
    placed = sorted((_offsets(text, starts, m.fix.span), i) for i, m in enumerate(wanted))
    out, made, at = [], [], 0
    for (start, end), i in placed:
        if start < at or (made and made[-1].fix == wanted[i].fix):
            continue
        out += [text[at:start], wanted[i].fix.replacement]
        made.append(wanted[i])
        at = end
    out.append(text[at:])
    return "".join(out), made


def _offsets(text: str, starts: list[int], span: Span) -> tuple[int, int]:
    """Where `span` starts and ends in `text` (its end column exclusive; a span without
    an end marks one character, as Diagnostic.end reads it)."""
    end = (span.end_line, span.end_column) if span.end_line else (span.line, span.column + 1)
    return _offset(text, starts, span.line, span.column), _offset(text, starts, *end)


def _offset(text: str, starts: list[int], line: int, column: int) -> int:
    """The index of a 1-based line and column; past the end of its line, that end."""
    if line > len(starts):
        return len(text)
    line_end = starts[line] if line < len(starts) else len(text)
    return min(starts[line - 1] + column - 1, line_end)


# -- the target line ----------------------------------------------------------------------------

# `target` is a keyword: outside a comment, it is the statement that names the model.
_TARGET = re.compile(r"(?<![A-Za-z0-9_.])target(?![A-Za-z0-9_])")


def has_target(text: str) -> bool:
    """Whether the text names its model (`target C-863`) outside a comment."""
    return any(_TARGET.search(line.split("//", 1)[0]) for line in split_lines(text))


def target_fix(text: str, model: str | None) -> Fix | None:
    """`target MODEL` on a line of its own after the leading comments and blank lines, with
    the file's own line end; None when the text names a model or none is chosen. No rule
    reports a missing target (the model checks wait for one), so it is no diagnostic's."""
    if model is None or has_target(text):
        return None
    found = LINE_END.search(text)
    end = found.group() if found else "\n"
    lines = split_lines(text)
    code = next((n for n, line in enumerate(lines, 1)
                 if line.strip() and not line.lstrip().startswith("//")), None)
    if code is not None:
        at, new = Span(code, 1, code, 1), f"target {model}{end}"
    else:  # comments and blank lines only: after the last one
        last = len(lines[-1]) + 1
        at, new = Span(len(lines), last, len(lines), last), \
            f"{end if lines[-1] else ''}target {model}{end}"
    return Fix(at, new, f"Add `target {model}`", SAFE)  # the model the user named
