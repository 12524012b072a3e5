"""Which diagnostics a user has turned off: by rule (`--select`/`--ignore`, settings) or by
a comment on the line (`// mercmac: ignore[nested-call]`).

Only `check` reads these: `build`, `sim` and `flash` still refuse a file with errors.
A syntax error is never turned off, as in ruff: the rest of its file was not checked.
"""
from __future__ import annotations

import re
from typing import Iterable

from mercmac.diagnostics import RULES, Diagnostic, rule
from mercmac.errors import UsageError
from mercmac.source import Source

# `// mercmac: ignore` (every rule) or `// mercmac: ignore[MM011, undefined-macro]`.
_COMMENT = re.compile(r"//.*?\bmercmac:[ \t]*ignore\b(?:[ \t]*\[([^\]]*)\])?", re.IGNORECASE)
_KEPT = "syntax"


def rule_set(keys: Iterable[str], option: str) -> frozenset[str]:
    """The codes of the rules named by codes or names (each may hold several, comma-separated)."""
    found = set()
    for key in (k.strip() for item in keys for k in item.split(",")):
        if not key:
            continue
        try:
            found.add(rule(key).code)
        except KeyError:
            raise UsageError(f"{option}: no rule {key!r}",
                             hint="`mercmac explain` lists the codes and names") from None
    return frozenset(found)


def chosen(select: frozenset[str] | None, ignore: frozenset[str]) -> frozenset[str]:
    """The codes of the rules to report: the selected ones (all without a selection) less the ignored."""
    codes = set(r.code for r in RULES) if select is None else set(select)
    return frozenset((codes - ignore) | {rule(_KEPT).code})


def kept(diagnostics: Iterable[Diagnostic], rules: frozenset[str],
         source: Source) -> list[Diagnostic]:
    """The diagnostics of the rules coded `rules` that no comment on their line turns off."""
    out = []
    for d in diagnostics:
        if d.rule.code in rules and not _silenced(d, source.line(d.span.line)):
            out.append(d)
    return out


def _silenced(d: Diagnostic, text: str) -> bool:
    if d.rule.name == _KEPT or "mercmac" not in text:
        return False
    for match in _COMMENT.finditer(text):
        if match.group(1) is None:
            return True
        keys = {k.strip().lower() for k in match.group(1).split(",")}
        if d.rule.code.lower() in keys or d.rule.name in keys:
            return True
    return False
