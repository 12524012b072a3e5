"""Syntax highlighting of `.mcm` (docs/language.md): a Pygments lexer, and the TextMate
grammar made from it.

`McmLexer` is registered under the `pygments.lexers` entry point, so rich, Sphinx and MkDocs
highlight `.mcm` files; `mercmac check` uses it for the source line of a diagnostic on a
colour terminal. Mnemonics come from the command table (mercmac.commands), and a raw block's
commands are read by mercmac.mdtext, as the compiler reads them: a word the controller does
not know is an Error token. `python -m mercmac.highlight --textmate` prints the grammar of
editors/vscode/syntaxes/mcm.tmLanguage.json.
"""
from __future__ import annotations

import json
import re
import sys

from pygments.lexer import RegexLexer, bygroups, default
from pygments.token import (Comment, Error, Keyword, Name, Number, Operator, Punctuation,
                            Whitespace)

from mercmac import mdtext
from mercmac.commands import COMMANDS, lookup
from mercmac.source import LINE_END

# The tokens of grammar.lark, as regular expressions both Pygments and Oniguruma read.
NAME = r"[A-Za-z_][A-Za-z0-9_.]*"
INT = r"[+-][ \t]*[0-9]+|[0-9]+"
WORD = r"[A-Za-z]+\??"  # MNEMONIC: a known one or not
DURATION = r"[0-9]+(?:\.[0-9]+)?[ \t]*(?i:ms|min|s|h|d)(?![A-Za-z0-9_])"
RAW_HEADER = mdtext.RAW_HEADER  # `[MCnn]`: the one pattern, grammar.lark's
MODEL = r"(?i:C-?[0-9]{3})"
COMMENT = r"//[^\r\n]*"


def _command(lexer, match):
    """A mnemonic of the table, or an Error: a word the controller does not know."""
    word = match.group()
    yield match.start(), Name.Builtin if lookup(word) else Error, word


def _raw_line(lexer, match):
    """`[MCnn] commands // comment`: the commands as mdtext reads a stored line."""
    yield match.start(1), Name.Label, match.group(1)
    body, at = match.group(2), match.start(2)
    code, slashes, comment = body.partition("//")
    yield from _raw_commands(code, at)
    if slashes:
        yield at + len(code), Comment.Single, slashes + comment


def _raw_commands(code: str, at: int):
    """Tokens for every character of a raw line's commands (mdtext.lex gives the spans)."""
    commands, problems = mdtext.lex(code)
    spans = [(p.start, p.end, Error) for p in problems]
    for c in commands:
        spans.append((c.start, c.word_end, Name.Builtin if lookup(c.word) else Error))
        if c.value_start < c.end:
            kind = Name.Constant if isinstance(c.value, str) else Number.Integer
            spans.append((c.value_start, c.end, kind))
    i = 0
    for start, end, kind in sorted(spans, key=lambda s: s[0]):
        if start < i:  # overlapping problem and command: the first one says it
            continue
        yield from _between(code[i:start], at + i)
        yield at + start, kind, code[start:end]
        i = end
    yield from _between(code[i:], at + i)


def _between(text: str, at: int):
    """Blanks, commas and whatever stray text lies between a raw line's commands."""
    for m in re.finditer(r"([ \t\f\v]+)|(,)|([^ \t\f\v,]+)", text):
        kind = Whitespace if m.group(1) else Punctuation if m.group(2) else Error
        yield at + m.start(), kind, m.group()


class McmLexer(RegexLexer):
    """Mercury macro programs (.mcm): MMCRun raw blocks and mercmac's high-level constructs."""

    name = "Mercury macros"
    aliases = ["mcm", "mercmac"]
    filenames = ["*.mcm"]
    mimetypes = ["text/x-mcm"]

    def __init__(self, **options):
        options.setdefault("stripnl", False)  # a leading blank line keeps its line number
        super().__init__(**options)

    tokens = {
        "root": [
            (r"[ \t\f]+", Whitespace),
            (LINE_END.pattern, Whitespace),  # LF, CRLF or a lone CR: mercmac.source
            (COMMENT, Comment.Single),
            (rf"({RAW_HEADER})([^\r\n]*)", _raw_line),
            (rf"(target)([ \t]+)({MODEL})\b", bygroups(Keyword.Declaration, Whitespace,
                                                       Keyword.Constant)),
            (rf"(const)([ \t]+)({NAME})", bygroups(Keyword.Declaration, Whitespace, Name.Constant)),
            (rf"(macro)([ \t]+)({NAME})", bygroups(Keyword.Declaration, Whitespace, Name.Function)),
            (rf"(@)([ \t]*)([0-9]+)", bygroups(Punctuation, Whitespace, Number.Integer)),
            (r"autostart\b", Keyword.Declaration),
            (rf"(call|goto)([ \t]+)({NAME})", bygroups(Keyword, Whitespace, Name.Function)),
            (r"(when|repeat|every)\b", Keyword, "operand"),
            (r"(and|not)\b", Operator.Word, "operand"),
            (INT, Number.Integer),
            (r"[{},]", Punctuation),
            (r"=", Operator),
            (WORD, _command, "argument"),
        ],
        # What follows `when`, `and`, `not`, `repeat`, `every`: a number, a duration, a const.
        "operand": [
            (r"[ \t]+", Whitespace),
            (r"not\b", Operator.Word),
            (DURATION, Number, "#pop"),
            (INT, Number.Integer, "#pop"),
            (NAME, Name.Constant, "#pop"),
            default("#pop"),
        ],
        # A native command's argument, on its line: `MR 5000`, `MR5000`, `SV FAST`, `MR -FAR`.
        "argument": [
            (r"[ \t]+", Whitespace),
            (INT, Number.Integer, "#pop"),
            (NAME, Name.Constant, "#pop"),
            (rf"([+-])([ \t]*)({NAME})", bygroups(Operator, Whitespace, Name.Constant), "#pop"),
            default("#pop"),
        ],
    }


# -- the TextMate grammar of editors/vscode --------------------------------------------------

def _alternation() -> str:
    """Every mnemonic of the table, longest first so `FA?` wins over `FA`."""
    return "|".join(re.escape(m) for m in sorted(COMMANDS, key=lambda m: (-len(m), m)))


def textmate() -> dict:
    """The TextMate grammar (scope source.mcm): the lexer's rules in Oniguruma's syntax."""
    known = rf"(?<![A-Za-z0-9_.?])(?i:{_alternation()})(?![A-Za-z?])"
    argument = rf"(?:[ \t]*(?:({INT})|(?:([+-])[ \t]*)?({NAME})))?"  # `MR -FAR`: a signed const
    command = {"match": rf"({known}){argument}",
               "captures": {"1": {"name": "support.function.mnemonic.mcm"},
                            "2": {"name": "constant.numeric.integer.mcm"},
                            "3": {"name": "keyword.operator.sign.mcm"},
                            "4": {"name": "variable.other.constant.mcm"}}}
    unknown = {"match": rf"(?<![A-Za-z0-9_.?]){WORD}", "name": "invalid.illegal.unknown-command.mcm"}
    number = {"match": rf"(?<![A-Za-z0-9_.])(?:{INT})", "name": "constant.numeric.integer.mcm"}
    comment = {"match": COMMENT, "name": "comment.line.double-slash.mcm"}
    return {
        "$schema": "https://raw.githubusercontent.com/martinring/tmlanguage/master/tmlanguage.json",
        "name": "Mercury macros",
        "scopeName": "source.mcm",
        "fileTypes": ["mcm"],
        "comment": "Generated by `python -m mercmac.highlight --textmate` from mercmac/commands.py; "
                   "do not edit.",
        "patterns": [{"include": "#comment"}, {"include": "#raw"}, {"include": "#declaration"},
                     {"include": "#statement"}],
        "repository": {
            "comment": comment,
            "raw": {
                "begin": rf"^[ \t]*({RAW_HEADER})",
                "beginCaptures": {"1": {"name": "entity.name.tag.macro-slot.mcm"}},
                "end": r"(?=$)",
                "name": "meta.raw-block.mcm",
                "patterns": [{"include": "#comment"}, command,
                             {"match": ",", "name": "punctuation.separator.mcm"},
                             {"match": r"[^ \t,/]+|/", "name": "invalid.illegal.mcm"}],
            },
            "declaration": {"patterns": [
                {"match": rf"\b(target)[ \t]+({MODEL})\b",
                 "captures": {"1": {"name": "storage.type.target.mcm"},
                              "2": {"name": "support.constant.model.mcm"}}},
                {"match": rf"\b(const)[ \t]+({NAME})",
                 "captures": {"1": {"name": "storage.type.const.mcm"},
                              "2": {"name": "variable.other.constant.mcm"}}},
                {"match": rf"\b(macro)[ \t]+({NAME})(?:[ \t]*(@)[ \t]*([0-9]+))?",
                 "captures": {"1": {"name": "storage.type.macro.mcm"},
                              "2": {"name": "entity.name.function.mcm"},
                              "3": {"name": "punctuation.definition.slot.mcm"},
                              "4": {"name": "constant.numeric.integer.mcm"}}},
                {"match": r"\bautostart\b", "name": "storage.type.autostart.mcm"},
            ]},
            "statement": {"patterns": [
                {"match": rf"\b(call|goto)[ \t]+({NAME})",
                 "captures": {"1": {"name": "keyword.control.mcm"},
                              "2": {"name": "entity.name.function.mcm"}}},
                {"match": rf"\b(when|repeat|every|and)\b(?:[ \t]+(not)\b)?"
                          rf"(?:[ \t]+(?:({DURATION})|({INT})|({NAME})))?",
                 "captures": {"1": {"name": "keyword.control.mcm"},
                              "2": {"name": "keyword.operator.logical.mcm"},
                              "3": {"name": "constant.numeric.duration.mcm"},
                              "4": {"name": "constant.numeric.integer.mcm"},
                              "5": {"name": "variable.other.constant.mcm"}}},
                {"match": r"[{}]", "name": "punctuation.section.block.mcm"},
                {"match": ",", "name": "punctuation.separator.mcm"},
                {"match": "=", "name": "keyword.operator.assignment.mcm"},
                command, unknown, number,
            ]},
        },
    }


def textmate_json() -> str:
    """The grammar as editors/vscode/syntaxes/mcm.tmLanguage.json holds it."""
    return json.dumps(textmate(), indent=2) + "\n"


if __name__ == "__main__":
    if sys.argv[1:] != ["--textmate"]:
        sys.exit("usage: python -m mercmac.highlight --textmate > editors/vscode/syntaxes/mcm.tmLanguage.json")
    sys.stdout.write(textmate_json())
