"""The canonical layout of a .mcm file: `mercmac fmt` (docs/cli.md).

The formatter works on the token stream of grammar.lark's own parser, with the
comments the lexer skips collected beside it, so it rewrites only the blanks
between tokens and the spelling of a few tokens, never the program:

- mnemonics upper case, one space between a mnemonic or keyword and its argument
  (`MR 5000`, `when 1 and not 2`, `every 20ms`), `, ` between statements, `{ ... }`
  with a space inside on one line, `@20` and `= 5` as docs/language.md writes them;
- 4 spaces of indentation per open brace; the user's line breaks and commas stay,
  runs of blank lines are kept up to MAX_BLANK_LINES, none at the start or the end;
- a comment stays where it stands: on a line of its own (indented with the code),
  or after the code of its line. Trailing comments of consecutive lines stand in one
  column, three spaces after the longest code of the run (as gofmt aligns them, with the
  examples' gap); a blank line, a line of comment only, a line without a comment, or one
  whose code is longer than ALIGN_WIDTH ends the run. Unlike gofmt, lines of different
  depth align too, so that a block's opening line and its statements can be commented
  side by side (the README's tour);
- a raw `[MCnn]` block is written as MMCRun saves it (MS176E §3.8.6, Example 4):
  `[MC05] BF,DP200,DI,DD200`, upper case, no blanks, the user's signs kept (`EM+9`).
  A block with a syntax error in its commands (`EMxx`) keeps them as written;
- the file's line ends stay: every line ends with the file's most common line end
  (LF, CRLF or CR: mercmac.source.LINE_END; the first one on a tie), LF when it has none.

The spelling, blanks, indentation and comment columns are mercmac.fmt.layout's, which the
AST printer (mercmac.fmt.printer) shares; this module reads a user's file into lines.
A file that does not parse is not formatted: `format_text` raises FormatError.
`load` reads a file's bytes as text only when writing that text back gives the same bytes:
a byte its encoding does not have is an error, never a U+FFFD written back.
"""
from __future__ import annotations

import re
from typing import Iterator

from mercmac import mdtext
from mercmac.errors import MercmacError
from mercmac.fmt.layout import Line, render, space, spell
from mercmac.source import LINE_END, Encoding, to_lf

# MMCRun leaves three blank lines after its header comment (MS176E §3.8.6, Example 4).
MAX_BLANK_LINES = 3

_BLANKS = re.compile(r"[ \t\f\v]+")


class FormatError(MercmacError):
    """A file that cannot be formatted because it does not parse; nothing was changed."""


def format_text(text: str) -> str:
    """TEXT in the canonical layout, with TEXT's line ends; FormatError when it does not parse."""
    from mercmac.compiler.parse import paused_gc

    newline = _line_end(text)
    text = to_lf(text)
    reads = _Reads()
    with paused_gc():  # a token per few bytes, none in a cycle: see paused_gc
        items = _items(text)
        formatted = render(list(_lines(items, reads)))
        if formatted != text:  # the same text reads the same: the guard has nothing to see
            _same_program(items, formatted, reads)
    return formatted if newline == "\n" else formatted.replace("\n", newline)


def _line_end(text: str) -> str:
    """The file's line end: the most common of LF, CRLF and CR (the first on a tie), so a
    stray CR does not turn a file around; LF when it has none."""
    first = LINE_END.search(text)
    if first is None:
        return "\n"
    crlf = text.count("\r\n")
    counts = {"\n": text.count("\n") - crlf, "\r\n": crlf, "\r": text.count("\r") - crlf}
    return max(counts, key=lambda end: (counts[end], end == first.group()))


# -- tokens -------------------------------------------------------------------------------------

def _items(text: str) -> list[tuple[str, str]]:
    """The parser's tokens and the comments, in the order they stand (mercmac.compiler.parse);
    FormatError when TEXT does not parse."""
    from mercmac.compiler.parse import NotParsed, tokens

    if "\x00" in text:
        raise FormatError("the file holds NUL characters: not text")
    try:
        return tokens(text)
    except NotParsed as e:
        raise FormatError(f"syntax error at {e.line}:{e.column}; not formatted",
                          hint="`mercmac check` says what is wrong") from None


def _lines(items: list, reads: _Reads) -> Iterator[Line | None]:
    """The formatted lines; None for a blank line."""
    depth = 0
    line_depth = 0
    parts: list[str] = []
    previous = None
    comment = ""
    leading = False
    started = False  # a line of code or comment has been written: blank lines count
    for kind, value in items:
        if kind == "_NL":
            if parts or comment:
                yield Line(line_depth, "".join(parts), comment)
            blanks = min(value.count("\n") - 1, MAX_BLANK_LINES)
            if started:
                yield from [None] * blanks
            parts, comment, previous = [], "", None
            continue
        started = True
        if kind == "COMMENT":
            comment = value.rstrip()
            if not parts:
                line_depth = depth
            continue
        if not parts:
            line_depth, leading = depth, True
        leading = leading and kind == "RBRACE"
        if leading:  # closing braces that open the line dedent it
            line_depth -= 1
        if kind == "RAW_LINE":
            code, comment = _raw_line(value, reads)
            parts.append(code)
        else:
            parts.append(space(previous, kind) + spell(kind, value))
        depth += _DEPTH.get(kind, 0)
        previous = kind
    if parts or comment:
        yield Line(line_depth, "".join(parts), comment)


_DEPTH = {"LBRACE": 1, "RBRACE": -1}


# -- raw blocks ---------------------------------------------------------------------------------

class _Reads(dict):
    """What raw blocks' commands say (`_read`), each text read once per file: the layout and
    the guard read the same lines (a 1 MB line is read twice, not six times)."""

    def __missing__(self, body: str):
        self[body] = found = _read(body)
        return found


def _raw_line(text: str, reads: _Reads) -> tuple[str, str]:
    """A `[MCnn] ...` line as MMCRun writes it, and the comment that ends it."""
    found = mdtext.listed(text)  # grammar.lark's RAW_LINE starts with mdtext.RAW_HEADER
    body, slash, comment = found.body.partition("//")
    comment = (slash + comment).rstrip()
    if found.slot is not None:
        head = f"[{mdtext.slot_name(found.slot)}]"
    else:  # more digits than any number: as written, blanks dropped
        head = "[MC" + _BLANKS.sub("", text[1:found.header - 1])[2:] + "]"
    body = _raw_body(body, reads)
    return (f"{head} {body}" if body else head), comment


def _raw_body(body: str, reads: _Reads) -> str:
    """The commands upper case with their blanks dropped (`MR FAST` keeps one: `MRFAST` would
    be another word), each only where it reads the same; a line with a syntax error as written."""
    written = body.strip(mdtext.BLANKS)
    meaning = reads[body]
    if meaning[1] or _placeholder(meaning[0]):
        return written  # the user's text, to be fixed by hand: `mercmac check` points into it
    compact = mdtext.canonical(body)  # what almost every line reads as: one pass over it
    if reads[compact] != meaning:
        compact = ",".join(_raw_command(piece, reads) for piece in body.split(","))
    return compact if reads[compact] == meaning else written


def _placeholder(commands: list) -> bool:
    """A placeholder such as `EMxx` (MS176E Example 3): a syntax error that the command
    table finds, not the lexer (mdtext.validate)."""
    return any(f.rule == "syntax" for word, value in commands
               for f in mdtext.validate(word, value, stored=False).findings)


def _raw_command(piece: str, reads: _Reads) -> str:
    """One command of a raw block as MMCRun writes it: `em + 9` -> `EM+9`."""
    for candidate in (mdtext.canonical(piece), " ".join(piece.upper().split())):
        if reads[candidate] == reads[piece]:
            return candidate
    return piece.strip(mdtext.BLANKS)


def _read(body: str):
    """What a raw block's commands say: (mnemonic, argument) each, and the syntax problems."""
    items, problems = mdtext.lex(body)
    return ([(item.word.upper(), item.value.upper() if isinstance(item.value, str) else item.value)
             for item in items],
            [(p.rule, p.variant, p.values) for p in problems])


# -- the guard ----------------------------------------------------------------------------------

def _same_program(items: list, formatted: str, reads: _Reads) -> None:
    """The formatted text must read as the same tokens (blanks and line breaks aside), each
    already in its canonical spelling, or the formatter has a bug: refuse rather than change
    a program (black's --safe)."""
    if _meaning(items, reads) != _meaning(_items(formatted), reads, spelled=False):
        raise FormatError("internal error: formatting would change the program; not formatted",
                          hint="please report this file")


def _meaning(items: list, reads: _Reads, spelled: bool = True) -> tuple[list, list]:
    """The comments, and each token in its canonical spelling (SPELLED; formatted text has it
    already) or, for a raw block, its slot, what its commands say and its comment."""
    comments = [value.rstrip() for kind, value in items if kind == "COMMENT"]
    code = [_raw_meaning(value, reads) if kind == "RAW_LINE" else
            (kind, spell(kind, value) if spelled else value)
            for kind, value in items if kind not in _LAYOUT]
    return comments, code


_LAYOUT = frozenset({"_NL", "COMMENT"})


def _raw_meaning(line: str, reads: _Reads) -> tuple:
    found = mdtext.listed(line)
    body, _, comment = found.body.partition("//")
    return found.slot, reads[body], comment.rstrip()


# -- files --------------------------------------------------------------------------------------

def load(data: bytes) -> tuple[str, Encoding]:
    """A file's text, and the encoding that writes it back as it was (MMCRun writes
    Windows-1252; Notepad may save UTF-16 with a BOM); FormatError when writing the text
    back would not give these bytes (a byte the encoding does not have)."""
    from mercmac.source import EncodingError, decode_exact

    try:
        return decode_exact(data)
    except EncodingError as e:
        raise FormatError(f"{e.message}; not formatted",
                          hint="fix that byte, or save the file in one encoding") from None
