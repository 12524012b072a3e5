"""`mercmac explain`: the long story of a rule, or the list of all rules."""
from __future__ import annotations

from mercmac.diagnostics import RULES, rule
from mercmac.errors import UsageError
from mercmac.render.console import Line, write_lines

_SEVERITY_STYLE = {"error": "bold red", "warning": "bold yellow", "info": "bold cyan"}


def write_explanation(key: str) -> None:
    """Print one rule's code, name, default severity and explanation."""
    try:
        r = rule(key)
    except KeyError:
        close = [x.name for x in RULES if key.lower() in x.name or x.name in key.lower()]
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
    """One line per rule: code, severity, name, summary."""
    write_lines([[(f"{r.code}  ", "bold"), (f"{str(r.severity):<8}", _SEVERITY_STYLE[str(r.severity)]),
                  (f"{r.name:<24}", ""), (r.summary, "dim")] for r in RULES])
