"""`mercmac explain`: the long story of a check or a runtime hazard, or the list of all."""
from __future__ import annotations

from mercmac import diagnostics
from mercmac.diagnostics import Rule
from mercmac.errors import UsageError
from mercmac.render.console import Line, write_lines
from mercmac.vm import hazards

_SEVERITY_STYLE = {"error": "bold red", "warning": "bold yellow", "info": "bold cyan"}
# The checks of `mercmac check` (MMnnn), then the hazards `mercmac sim` reports (MHnnn).
ALL: tuple[Rule, ...] = diagnostics.RULES + hazards.RULES
_BY_KEY = {r.code: r for r in ALL} | {r.name: r for r in ALL}


def find(key: str) -> Rule:
    """A check or hazard by code or name, case-insensitively; KeyError if unknown."""
    return _BY_KEY.get(key) or _BY_KEY.get(key.upper()) or _BY_KEY[key.lower()]


def write_explanation(key: str) -> None:
    """Print one rule's code, name, default severity and explanation."""
    try:
        r = find(key)
    except KeyError:
        close = [x.name for x in ALL if key.lower() in x.name or x.name in key.lower()]
        hint = f"did you mean {close[0]}?" if close else "run `mercmac explain` for the list"
        raise UsageError(f"no rule '{key}'", hint=hint) from None
    severity = str(r.severity)
    lines: list[Line] = [
        [(f"{r.code} ", "bold"), (r.name, "bold"), (f" ({severity})", _SEVERITY_STYLE[severity])],
        [(r.summary, "italic")],
        [("", "")],
    ]
    lines += [[(text, "")] for text in r.explanation.splitlines()]
    write_lines(lines)


def write_rule_list() -> None:
    """One line per rule: code, severity, name, summary; the checks, then the hazards."""
    write_lines([_list_line(r) for r in diagnostics.RULES] + [[("", "")]]
                + [[("runtime hazards, reported by `mercmac sim`:", "bold")]]
                + [_list_line(r) for r in hazards.RULES])


def _list_line(r: Rule) -> Line:
    return [(f"{r.code}  ", "bold"), (f"{str(r.severity):<8}", _SEVERITY_STYLE[str(r.severity)]),
            (f"{r.name:<24}", ""), (r.summary, "dim")]
