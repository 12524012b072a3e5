"""Text -> parse tree, with every syntax error reported in one run.

Lark's exceptions are translated here and nowhere else. After an error the
offending line is blanked (its braces kept, so that blocks still nest) and
the file is parsed again, so several broken lines give several diagnostics.
"""
from __future__ import annotations

import re

from mercmac.commands import lookup
from mercmac.compiler import parser_tables as lark
from mercmac.diagnostics import Report
from mercmac.source import Span

MAX_RECOVERIES = 50

_PARSER = None

# Terminal names of grammar.lark as a person would call them.
_TERMINALS = {
    "_NL": "end of line", "COMMA": "','", "LBRACE": "'{'", "RBRACE": "'}'", "AT": "'@'",
    "EQUAL": "'='", "MNEMONIC": "a command", "NAME": "a name", "INT": "a number",
    "RAW_HEADER": "[MCnn]", "MODEL": "C-663 or C-863", "DURATION": "a duration such as 20ms",
    "$END": "end of file", "NOT": "'not'", "AND": "'and'", "MACRO": "'macro'",
    "TARGET": "'target'", "CONST": "'const'", "AUTOSTART": "'autostart'", "WHEN": "'when'",
    "REPEAT": "'repeat'", "EVERY": "'every'", "CALL": "'call'", "GOTO": "'goto'",
}

# Named errors (lark's match_examples): a label and snippets that fail the same way.
_EXAMPLES = {
    "commands are separated by commas": [
        "[MC01] MR5000 WS100\n", "[MC01] TP TT\n", "macro a { MR5000 WS100 }\n",
        "macro a { TP TT }\n",
    ],
    "a command must stand in a [MCnn] block or in a macro/autostart block": [
        "MR5000\n", "TP\n", "macro a { }\nTP\n", "[MC01] TP\nTP\n", "target C-863\nTP\n",
        "const A = 1\nTP\n",
    ],
    "a block needs its closing '}'": ["macro a {\nTP\n", "autostart { TP\n"],
    "'macro' needs a name, an optional @slot and a block: macro NAME @5 { ... }": [
        "macro { }\n", "macro 5 { }\n", "macro a 5 { }\n", "macro a @ { }\n",
    ],
}
_MNEMONIC_BEFORE = re.compile(r"([A-Za-z]{2}\??)[ \t]*$")


def parser():
    """The stand-alone LALR parser, built once per process."""
    global _PARSER
    if _PARSER is None:
        _PARSER = lark.Lark_StandAlone()
    return _PARSER


def parse(text: str, report: Report):
    """The parse tree of `text`, or None after reporting every syntax error."""
    lines = text.split("\n")
    blanked: set[int] = set()
    failed = False
    for _ in range(MAX_RECOVERIES):
        try:
            tree = parser().parse("\n".join(lines) + "\n")
            return None if failed else tree
        except lark.UnexpectedInput as e:
            failed = True
            line = _error_line(e, len(lines))
            if line not in blanked:
                report.add("syntax", _error_span(e, line), _message(e, line, lines))
            if _at_end(e) or line > len(lines):
                return None
            if line in blanked:  # the repaired line still fails: drop it
                lines[line - 1] = ""
            else:
                blanked.add(line)
                lines[line - 1] = _repair(lines, line - 1)
    return None


def _at_end(e) -> bool:
    return isinstance(e, lark.UnexpectedEOF) or getattr(getattr(e, "token", None), "type", "") == "$END"


def _error_line(e, count: int) -> int:
    line = getattr(e, "line", -1)
    return line if isinstance(line, int) and line > 0 else count


def _error_span(e, line: int) -> Span:
    column = getattr(e, "column", 1)
    column = column if isinstance(column, int) and column > 0 else 1
    token = getattr(e, "token", None)
    width = len(str(token).strip()) if token is not None and token.type not in ("_NL", "$END") else 1
    return Span(line, column, line, column + max(width, 1))


def _code(line: str) -> str:
    return line.split("//", 1)[0]


def _repair(lines: list[str], index: int) -> str:
    """A broken line blanked, with its braces kept so that blocks still nest."""
    code = _code(lines[index])
    opens, closes = code.count("{"), code.count("}")
    if opens > closes:
        depth = sum(_code(l).count("{") - _code(l).count("}") for l in lines[:index])
        return "macro _ {" if depth <= 0 else "when 1 {"
    return "}" * (closes - opens)


def _message(e, line: int, lines: list[str]) -> str:
    label = _label(e)
    if label:
        return label
    before = ""
    if 0 < line <= len(lines):
        before = lines[line - 1][: max(getattr(e, "column", 1) - 1, 0)]
    found = _found(e)
    if found == "'.'" and before[-1:].isdigit():
        return "arguments are whole numbers (counts, steps, ms); there is no decimal point"
    m = _MNEMONIC_BEFORE.search(before)
    command = lookup(m.group(1)) if m else None
    if command is not None and (isinstance(e, lark.UnexpectedCharacters) or found != "end of line"):
        return f"{command.expects()}, found {found}"
    expected = _expected(e)
    return f"unexpected {found}" + (f"; expected {expected}" if expected else "")


def _label(e) -> str | None:
    """The label of an example that fails in the same parser state on the same token.

    Like lark's `match_examples`, but by LALR state alone: lark also compares
    stack depth, so an example would only match at the top of a file.
    """
    key = _key(e)
    if key is None:
        return None
    for label, key_set in _example_keys().items():
        if key in key_set:
            return label
    return None


def _key(e):
    state = getattr(e, "state", None)
    token = getattr(e, "token", None)
    if token is None or not hasattr(state, "position"):
        return None
    return state.position, token.type


_KEYS: dict[str, set] | None = None


def _example_keys() -> dict[str, set]:
    global _KEYS
    if _KEYS is None:
        _KEYS = {}
        for label, examples in _EXAMPLES.items():
            keys = _KEYS.setdefault(label, set())
            for example in examples:
                try:
                    parser().parse(example)
                except lark.UnexpectedInput as ex:
                    keys.add(_key(ex))
    return _KEYS


def _found(e) -> str:
    if isinstance(e, lark.UnexpectedCharacters):
        return repr(e.char)
    token = getattr(e, "token", None)
    if token is None or token.type == "$END":
        return "end of file"
    if token.type == "_NL":
        return "end of line"
    return repr(str(token))


def _expected(e) -> str:
    names = getattr(e, "expected", None) or getattr(e, "allowed", None) or ()
    words = sorted({_TERMINALS.get(n, n.lower()) for n in names if not n.startswith("__")})
    if len(words) > 6:
        words = words[:6] + ["..."]
    return ", ".join(words)
