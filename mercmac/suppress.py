"""Which diagnostics a user has turned off: by rule (`--select`/`--ignore`, settings) or by
a comment on the line (`// mercmac: ignore[nested-call]`); and which hazards of the
simulator a line's comment accepts (`// mercmac: expect[soft-limit-clamp]`, read here with
the same rules and reported alike when it cannot be read; docs/simulator.md, "Hazards").

Only `check` and the language server (mercmac.compiler.checking) read these: `build`, `sim`
and `flash` still refuse a file with errors.
A syntax error is never turned off, as in ruff: the rest of its file was not checked.
A comment that cannot be read turns nothing off and is reported (`invalid-suppression`,
as ruff's RUF102 reports a `# noqa` with a code it does not know).
"""
from __future__ import annotations

import re
import reprlib
from typing import Iterable, NamedTuple

from mercmac.diagnostics import RULES, Diagnostic, Report, rule
from mercmac.errors import SettingsError
from mercmac.source import Source, Span, split_lines

# `// mercmac: ignore` (every rule) or `// mercmac: ignore[MM011, undefined-macro]`, in any
# case. Matched inside a line's comment only, and without backtracking: the codes run to
# the first `]` or the end of the line (group 2 empty: unclosed), so a line of repeated
# `//` or `[` costs one pass (a lazy `//.*?` before it was quadratic).
_DIRECTIVE = re.compile(r"\bmercmac:[ \t]*ignore\b(?:[ \t]*\[([^\]]*)(\]?))?", re.IGNORECASE)
_EXPECT = re.compile(r"\bmercmac:[ \t]*expect\b(?:[ \t]*\[([^\]]*)(\]?))?", re.IGNORECASE)
_MENTION = re.compile("mercmac", re.IGNORECASE)
_KEPT = "syntax"


class Silenced(NamedTuple):
    """What the comments of one line turn off, read once per line: every rule, or these
    codes; the hazard rules it expects (names); and the diagnostics of the directives that
    could not be read."""

    every: bool
    codes: frozenset[str]
    problems: tuple[Diagnostic, ...]
    expects: frozenset[str] = frozenset()


def rule_set(keys: Iterable[str], option: str) -> frozenset[str]:
    """The codes of the rules named by codes or names (each may hold several, comma-separated)."""
    found = set()
    for key in (k.strip() for item in keys for k in item.split(",")):
        if not key:
            continue
        try:
            found.add(rule(key).code)
        except KeyError:
            raise SettingsError(f"{option}: no rule {reprlib.repr(key)}",
                                hint="`mercmac explain` lists the codes and names") from None
    return frozenset(found)


def selection(keys: Iterable[str], option: str) -> frozenset[str]:
    """rule_set for a selection, refused when it names no rule: it would report nothing
    and pass, which is never what `--select ''` or `select = []` meant."""
    codes = rule_set(keys, option)
    if not codes:
        raise SettingsError(f"{option} names no rule, so nothing would be reported",
                            hint="name rules by code or name (MM011, undefined-macro); "
                                 "leave the selection out to report every rule")
    return codes


def chosen(select: frozenset[str] | None, ignore: frozenset[str]) -> frozenset[str]:
    """The codes of the rules to report: the selected ones (all without a selection) less the ignored."""
    codes = set(r.code for r in RULES) if select is None else set(select)
    return frozenset((codes - ignore) | {rule(_KEPT).code})


def kept(diagnostics: Iterable[Diagnostic], rules: frozenset[str],
         source: Source) -> list[Diagnostic]:
    """The diagnostics of the rules coded `rules` that no comment on their line turns off,
    with the `invalid-suppression` warnings of the comments that cannot be read."""
    comments = silenced_lines(source)
    problems = [p for line in comments.values() for p in line.problems]
    return [d for d in [*diagnostics, *problems]
            if d.rule.code in rules and not _silenced(d, comments.get(d.span.line))]


def silenced_lines(source: Source) -> dict[int, Silenced]:
    """Line number -> what its comments turn off, for the lines that have a directive."""
    if not _MENTION.search(source.text):  # most files: one scan, no split
        return {}
    found = {}
    for number, text in enumerate(split_lines(source.text), 1):
        start = text.find("//")
        if start >= 0 and _MENTION.search(text, start):
            line = _read(source.name, number, text, start)
            if line is not None:
                found[number] = line
    return found


def _read(file: str, number: int, text: str, start: int) -> Silenced | None:
    """The directives in the comment of one line (it starts at `start`); None without any."""
    every, codes, report = False, set(), Report(file)
    matches = list(_DIRECTIVE.finditer(text, start))
    for m in matches:
        where = Span(number, m.start() + 1, number, m.end() + 1)
        if m.group(1) is None:
            every = True
        elif not m.group(2):
            report.add("invalid-suppression", where, "unclosed")
        else:
            codes |= _codes(m.group(1), where, report)
    expects = set()
    for m in _EXPECT.finditer(text, start):
        where = Span(number, m.start() + 1, number, m.end() + 1)
        if m.group(1) is None or not m.group(2) or not m.group(1).strip(", \t"):
            report.add("invalid-suppression", where, "expect-form")
        else:
            expects |= _hazards(m.group(1), where, report)
        matches.append(m)
    return Silenced(every, frozenset(codes), tuple(report.items),
                    frozenset(expects)) if matches else None


def expected_hazards(source: Source) -> dict[int, frozenset[str]]:
    """Line number -> the hazard rules (names) its comment expects: the simulator shows
    them there as accepted, and counts them not (Program.expected)."""
    return {n: line.expects for n, line in silenced_lines(source).items() if line.expects}


def _hazards(keys: str, where: Span, report: Report) -> set[str]:
    """The hazard rules named in an `expect[...]` (codes or names, any case); each name
    that is no hazard rule is reported and accepts nothing."""
    from mercmac.hazards import named

    found = set()
    for key in filter(None, (k.strip() for k in keys.split(","))):
        name = named(key)
        if name is None:
            report.add("invalid-suppression", where, "expect-unknown", key=reprlib.repr(key))
        else:
            found.add(name)
    return found


def _codes(keys: str, where: Span, report: Report) -> set[str]:
    """The codes named in one directive's brackets (codes or names, any case); each
    name that is no rule, or an empty list, is reported and turns nothing off."""
    codes = set()
    for key in filter(None, (k.strip() for k in keys.split(","))):
        try:
            codes.add(rule(key).code)
        except KeyError:
            report.add("invalid-suppression", where, "unknown", key=reprlib.repr(key))
    if not keys.strip(", \t"):
        report.add("invalid-suppression", where, "empty")
    return codes


def _silenced(d: Diagnostic, line: Silenced | None) -> bool:
    if line is None or d.rule.name == _KEPT:
        return False
    return line.every or d.rule.code in line.codes
