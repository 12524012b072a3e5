"""The canonical layout of a .mcm file: `mercmac fmt` (SPEC §5, issue 10).

The formatter works on the token stream of grammar.lark's own parser, with the
comments the lexer skips collected beside it, so it rewrites only the blanks
between tokens and the spelling of a few tokens, never the program:

- mnemonics upper case, one space between a mnemonic or keyword and its argument
  (`MR 5000`, `when 1 and not 2`, `every 20ms`), `, ` between statements, `{ ... }`
  with a space inside on one line, `@20` and `= 5` as SPEC §1 writes them;
- 4 spaces of indentation per open brace; the user's line breaks and commas stay,
  runs of blank lines are kept up to MAX_BLANK_LINES, none at the start or the end;
- a comment stays where it stands: on a line of its own (indented with the code),
  or after the code of its line, three spaces after it (as in the examples);
- a raw `[MCnn]` block is written as MMCRun saves it (MS176E §3.8.6, Example 4):
  `[MC05] BF,DP200,DI,DD200`, upper case, no blanks, the user's signs kept (`EM+9`).
  A block with a syntax error in its commands (`EMxx`) keeps them as written;
- the file's line endings stay: CRLF when its first line ends in CRLF, else LF.

A file that does not parse is not formatted: `format_text` raises FormatError.
"""
from __future__ import annotations

import re
from typing import Iterator, NamedTuple

from mercmac import mdtext
from mercmac.errors import MercmacError

INDENT = "    "
# MMCRun leaves three blank lines after its header comment (MS176E §3.8.6, Example 4).
MAX_BLANK_LINES = 3
# The examples' house style: three spaces between code and its comment.
COMMENT_GAP = "   "

_HEADER = re.compile(r"\[[ \t]*MC([^\]]*)\]", re.IGNORECASE)
_BLANKS = re.compile(r"[ \t\f\v]+")
# Tokens written with their blanks dropped; MNEMONIC and MODEL also upper case.
_SQUEEZE = {"INT", "DURATION", "MNEMONIC", "MODEL"}
_UPPER = {"MNEMONIC", "MODEL"}
_NO_SPACE_BEFORE = {"COMMA"}
_NO_SPACE_AFTER = {"AT"}


class FormatError(MercmacError):
    """A file that cannot be formatted because it does not parse; nothing was changed."""


class _Line(NamedTuple):
    depth: int
    code: str
    comment: str


def format_text(text: str) -> str:
    """TEXT in the canonical layout; FormatError when it does not parse."""
    newline = "\r\n" if _crlf(text) else "\n"
    items = _items(text)
    lines = list(_lines(items))
    out = _render(lines)
    formatted = out.replace("\n", newline)
    _same_program(text, formatted)
    return formatted


def _crlf(text: str) -> bool:
    """True when the first line ends in CRLF (MMCRun is a Windows program)."""
    end = text.find("\n")
    return end > 0 and text[end - 1] == "\r"


# -- tokens -------------------------------------------------------------------------------------

def _tokens(text: str) -> tuple[list, list]:
    """The parser's tokens and the skipped comments of TEXT; FormatError when it does not parse."""
    from mercmac.compiler import parser_tables as lark

    if "\x00" in text:
        raise FormatError("the file holds NUL characters: not text")
    comments: list = []
    parser = lark.Lark_StandAlone(lexer_callbacks={"COMMENT": comments.append})
    tokens = []
    try:
        interactive = parser.parse_interactive(text + "\n")  # as mercmac.compiler.parse reads it
        for token in interactive.iter_parse():
            tokens.append(token)
        interactive.feed_eof(tokens[-1] if tokens else None)
    except lark.LarkError as e:
        line, column = getattr(e, "line", "?"), getattr(e, "column", "?")
        raise FormatError(f"syntax error at {line}:{column}; not formatted",
                          hint="`mercmac check` says what is wrong") from None
    return tokens, comments


def _items(text: str) -> list:
    """Tokens and comments in the order they stand."""
    tokens, comments = _tokens(text)
    return sorted(tokens + comments, key=lambda t: t.start_pos)


def _lines(items: list) -> Iterator[_Line | None]:
    """The formatted lines; None for a blank line."""
    depth = 0
    line_depth = 0
    parts: list[str] = []
    previous = None
    comment = ""
    leading = False
    started = False  # a line of code or comment has been written: blank lines count
    for item in items:
        kind = item.type
        if kind == "_NL":
            if parts or comment:
                yield _Line(line_depth, _join(parts), comment)
            blanks = min(item.value.count("\n") - 1, MAX_BLANK_LINES)
            if started:
                yield from [None] * blanks
            parts, comment, previous = [], "", None
            continue
        started = True
        if kind == "COMMENT":
            comment = item.value.rstrip()
            if not parts:
                line_depth = depth
            continue
        if not parts:
            line_depth, leading = depth, True
        leading = leading and kind == "RBRACE"
        if leading:  # closing braces that open the line dedent it
            line_depth -= 1
        if kind == "RAW_LINE":
            code, comment = _raw_line(item.value)
            parts.append(code)
        else:
            parts.append(_space(previous, kind) + _spell(kind, item.value))
        depth += {"LBRACE": 1, "RBRACE": -1}.get(kind, 0)
        previous = kind
    if parts or comment:
        yield _Line(line_depth, _join(parts), comment)


def _space(previous: str | None, kind: str) -> str:
    if previous is None or kind in _NO_SPACE_BEFORE or previous in _NO_SPACE_AFTER:
        return ""
    return " "


def _spell(kind: str, value: str) -> str:
    """A token as the canonical layout writes it."""
    if kind in _SQUEEZE:
        value = _BLANKS.sub("", value)
    if kind in _UPPER:
        value = value.upper()
    if kind == "DURATION":
        value = value.lower()  # units read in any case (mercmac.timespec)
    return value


def _join(parts: list[str]) -> str:
    return "".join(parts)


def _render(lines: list[_Line | None]) -> str:
    while lines and lines[-1] is None:
        lines.pop()
    out = []
    for line in lines:
        if line is None:
            out.append("")
        elif not line.code:
            out.append(INDENT * max(line.depth, 0) + line.comment)
        else:
            gap = COMMENT_GAP if line.comment else ""
            out.append(INDENT * max(line.depth, 0) + line.code + gap + line.comment)
    return "".join(line + "\n" for line in out)


# -- raw blocks ---------------------------------------------------------------------------------

def _raw_line(text: str) -> tuple[str, str]:
    """A `[MCnn] ...` line as MMCRun writes it, and the comment that ends it."""
    header = _HEADER.match(text)
    rest = text[header.end():]
    body, slash, comment = rest.partition("//")
    comment = (slash + comment).rstrip()
    slot = mdtext.number(header.group(1))
    head = f"[MC{slot:02d}]" if slot is not None else "[MC" + _BLANKS.sub("", header.group(1)) + "]"
    body = _raw_body(body)
    return (f"{head} {body}" if body else head), comment


def _raw_body(body: str) -> str:
    """The commands upper case with their blanks dropped (`MR FAST` keeps one: `MRFAST` would
    be another word), each only where it reads the same; a line with a syntax error as written."""
    written = body.strip(mdtext.BLANKS)
    if any(p.rule == "syntax" for p in mdtext.parse_line(body, stored=False).problems):
        return written  # the user's text, to be fixed by hand: `mercmac check` points into it
    compact = ",".join(_raw_command(piece) for piece in body.split(","))
    return compact if _read(compact) == _read(body) else written


def _raw_command(piece: str) -> str:
    """One command of a raw block as MMCRun writes it: `em + 9` -> `EM+9`."""
    for candidate in (mdtext.canonical(piece), " ".join(piece.upper().split())):
        if _read(candidate) == _read(piece):
            return candidate
    return piece.strip(mdtext.BLANKS)


def _read(body: str):
    """What a raw block's commands say: (mnemonic, argument) each, and the syntax problems."""
    items, problems = mdtext.lex(body)
    return ([(item.word.upper(), item.value.upper() if isinstance(item.value, str) else item.value)
             for item in items],
            [(p.rule, p.variant, p.values) for p in problems])


# -- the guard ----------------------------------------------------------------------------------

def _same_program(before: str, after: str) -> None:
    """The formatted text must read as the same tokens (blanks and line breaks aside), or
    the formatter has a bug: refuse rather than change a program (black's --safe)."""
    if _meaning(before) != _meaning(after):
        raise FormatError("internal error: formatting would change the program; not formatted",
                          hint="please report this file")


def _meaning(text: str) -> list:
    tokens, comments = _tokens(text)
    meaning = [c.value.rstrip() for c in comments]
    for token in tokens:
        if token.type == "_NL":
            continue
        if token.type == "RAW_LINE":
            header = _HEADER.match(token.value)
            body, _, comment = token.value[header.end():].partition("//")
            meaning.append((mdtext.number(header.group(1)), _read(body), comment.rstrip()))
        else:
            meaning.append((token.type, _spell(token.type, token.value)))
    return meaning


# -- files --------------------------------------------------------------------------------------

def load(data: bytes) -> tuple[str, str]:
    """A file's text as `mercmac check` reads it, and the codec that writes it back as it was
    (MMCRun writes Windows-1252; Notepad may save UTF-16 with a BOM)."""
    from mercmac.source import decode

    text = decode(data)
    for bom, codec in ((b"\xef\xbb\xbf", "utf-8-sig"), (b"\xff\xfe\x00\x00", "utf-32"),
                       (b"\x00\x00\xfe\xff", "utf-32"), (b"\xff\xfe", "utf-16"),
                       (b"\xfe\xff", "utf-16")):
        if data.startswith(bom):
            return text, codec
    for codec in ("utf-8", "utf-16-le", "utf-16-be"):
        try:
            if data.decode(codec) == text:
                return text, codec
        except UnicodeDecodeError:
            continue
    return text, "cp1252"
