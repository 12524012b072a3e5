"""`mercmac explain`: the long story of a check or a runtime hazard, or the list of all;
what a native command does (`mercmac explain MR`)."""
from __future__ import annotations

from mercmac import diagnostics
from mercmac.diagnostics import Rule
from mercmac.errors import InputError
from mercmac.names import printable
from mercmac.render.console import Line, write_lines
from mercmac import hazards

_SEVERITY_STYLE = {"error": "bold red", "warning": "bold yellow", "info": "bold cyan"}
# The checks of `mercmac check` (MMnnn), then the hazards `mercmac sim` reports (MHnnn).
ALL: tuple[Rule, ...] = diagnostics.RULES + hazards.RULES
_BY_KEY = {r.code: r for r in ALL} | {r.name: r for r in ALL}
# No rule name or mnemonic is longer; a longer word gets no 'did you mean' (nor its cost).
_LONGEST = 40


def find(key: str) -> Rule:
    """A check or hazard by code or name, case-insensitively; KeyError if unknown."""
    return _BY_KEY.get(key) or _BY_KEY.get(key.upper()) or _BY_KEY[key.lower()]


def write_explanation(key: str) -> None:
    """Print what KEY names: a rule (code, name, severity, story), a native command (what
    `mercmac commands` and the editor's hover say of it), a keyword of the language (`when`),
    or both when a word is both (none
    is today: rule names are kebab-case words, mnemonics two letters); for a word people
    write for a command (`LED`, `wait`: compiler/guesses.py), what to write instead."""
    from mercmac.commands import lookup

    lines: list[Line] = []
    from mercmac.render.commands import keyword_explanation

    for part in (_rule_lines(key), _command_lines(lookup(key)), keyword_explanation(key)):
        lines += ([[("", "")]] if lines and part else []) + part
    write_lines(lines or _guess_lines(key))


def _rule_lines(key: str) -> list[Line]:
    try:
        r = find(key)
    except KeyError:
        return []
    severity = str(r.severity)
    lines: list[Line] = [
        [(f"{r.code} ", "bold"), (r.name, "bold"), (f" ({severity})", _SEVERITY_STYLE[severity])],
        [(r.summary, "italic")],
        [("", "")],
    ]
    return lines + [[(text, "")] for text in r.explanation.splitlines()]


def _command_lines(command) -> list[Line]:
    from mercmac.render.commands import explanation

    return explanation(command) if command is not None else []


def _guess_lines(key: str) -> list[Line]:
    """What to write for a word that is no command (`LED`); InputError for any other word."""
    from mercmac.compiler import guesses

    said = guesses.hint(key)
    if said is None:
        raise InputError(f"no rule or command '{printable(key)}'", hint=_nearest(key))
    section = guesses.guess(key).section
    return [[(key, "bold"), (": no command or keyword; ", ""), (said, "")]] + \
        ([[(f"({section})", "dim")]] if section else [])


def _nearest(key: str) -> str:
    """'did you mean ...?' among the rules and the commands; else where the lists are."""
    from mercmac.commands import COMMANDS
    from mercmac.suggest import question, suggest

    low = key.lower()
    close = suggest(key, [r.name for r in ALL] + list(COMMANDS), max(1, len(key) // 3)) \
        if len(key) <= _LONGEST else None
    if close is None and len(low) >= 3:  # `nested` for nested-call
        close = next((r.name for r in ALL if low in r.name or r.name in low), None)
    return question(close) or "`mercmac explain` lists the rules, `mercmac commands` the commands"


def write_rule_list() -> None:
    """One line per rule: code, severity, name, summary; the checks, then the hazards."""
    write_lines([_list_line(r) for r in diagnostics.RULES] + [[("", "")]]
                + [[("runtime hazards, reported by `mercmac sim`:", "bold")]]
                + [_list_line(r) for r in hazards.RULES])


def _list_line(r: Rule) -> Line:
    return [(f"{r.code}  ", "bold"), (f"{str(r.severity):<8}", _SEVERITY_STYLE[str(r.severity)]),
            (f"{r.name:<24}", ""), (r.summary, "dim")]
