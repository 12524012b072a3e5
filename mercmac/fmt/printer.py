"""The AST printer: a tree of mercmac.compiler.ast as .mcm text in `mercmac fmt`'s layout.

Spelling, blanks, indentation and comment columns are mercmac.fmt.layout's, as for a user's
file; a tree has no line breaks of its own, so the printer chooses them:

- a definition stands after a blank line, a macro's body on lines of its own;
- runs of simple statements (commands, `call`, `goto`) share a line, `MR 5000, WS 100`,
  while it stays under JOIN_WIDTH;
- a `when`, `repeat` or `every` whose body is one such line stands on one line,
  `when 1 { MR 5000 }`, under BLOCK_WIDTH.

Beside the tree's nodes the printer takes what only a writer of source has: `Comment` lines,
`Commented` nodes (a comment after their first line), `RawText` (a raw block whose line
does not read as commands: the parser keeps no such block) and `Run` (statements on one
line whatever its length: a stored line written as commands).
"""
from __future__ import annotations

import functools
from typing import NamedTuple

from mercmac import mdtext
from mercmac.compiler import ast
from mercmac.fmt.layout import Line, code, render

# Under these the decompiler's source always was: 70 characters of joined statements, a
# head and its one-line body under 72 (the block then fits in about 80 columns).
JOIN_WIDTH = 70
BLOCK_WIDTH = 72


class Comment(NamedTuple):
    """A line of comment only: `// MC07:`."""

    text: str  # with its `//`


class Commented(NamedTuple):
    """A node with a comment after its first line: `macro scan {   // MC05`."""

    node: object
    comment: str  # with its `//`


class RawText(NamedTuple):
    """A raw block whose line is kept as it was stored: `[MC05] EMxx`."""

    slot: int
    text: str


class Run(NamedTuple):
    """Simple statements on one line, however long."""

    body: tuple


def module(items) -> str:
    """The text of top-level items (ast.Module's, and the printer's own above)."""
    return "\n".join(map(_paragraph, _paragraphs(items)))


def _paragraphs(items) -> list[tuple]:
    """The items between blank lines: a definition starts a paragraph. Comments align within
    one (a blank line ends a run of them: mercmac.fmt.layout), so each is laid out alone."""
    out: list[list] = []
    for item in items:
        if not out or _definition(item):
            out.append([])
        out[-1].append(item)
    return [tuple(paragraph) for paragraph in out]


def _definition(item) -> bool:
    node = item.node if isinstance(item, Commented) else item
    return isinstance(node, (ast.RawBlock, RawText, ast.MacroDef, ast.Autostart))


# The decompiler prints a candidate per choice it tries, most paragraphs as they were.
@functools.lru_cache(maxsize=1024)
def _paragraph(items: tuple) -> str:
    return render([line for item in items for line in _item(item)])


def _item(item) -> list[Line]:
    match item:
        case Commented(node, comment):
            first, *rest = _item(node)
            return [first._replace(comment=comment), *rest]
        case Comment(text):
            return [Line(0, "", text)]
        case ast.MacroDef() | ast.Autostart():
            return _block(_head(item), item.body, 0, one_line=False)
        case _:
            return [Line(0, code(_tokens(item)), "")]


# -- statements ---------------------------------------------------------------------------------

class _Printed(NamedTuple):
    line: Line
    tokens: list | None  # a line of simple statements, which the next may join; else None


def _body(stmts, depth: int) -> list[_Printed]:
    out: list[_Printed] = []
    for stmt in stmts:
        if isinstance(stmt, (ast.Command, ast.Call, ast.Goto, Run)):
            _simple(out, _tokens(stmt), depth)
        elif isinstance(stmt, Comment):
            out.append(_Printed(Line(depth, "", stmt.text), None))
        else:
            out += [_Printed(line, None) for line in _statement(stmt, depth)]
    return out


def _simple(out: list[_Printed], tokens: list, depth: int) -> None:
    """A simple statement: on the line of the one before it while that stays short."""
    text = code(tokens)
    last = out[-1] if out else None
    if last is not None and last.tokens is not None and len(last.line.code) + len(text) < JOIN_WIDTH:
        joined = [("COMMA", ","), *tokens]
        line = last.line._replace(code=last.line.code + code(joined, last.tokens[-1][0]))
        out[-1] = _Printed(line, last.tokens + joined)
    else:
        out.append(_Printed(Line(depth, text, ""), tokens))


def _statement(stmt, depth: int) -> list[Line]:
    """A `when`, `repeat` or `every` (maybe Commented) as lines."""
    if isinstance(stmt, Commented):
        first, *rest = _statement(stmt.node, depth)
        return [first._replace(comment=stmt.comment), *rest]
    return _block(_head(stmt), stmt.body, depth, one_line=True)


def _block(head: list, body, depth: int, one_line: bool) -> list[Line]:
    inner = _body(body, depth + 1)
    if one_line and len(inner) == 1 and inner[0].tokens is not None:
        tokens = [*head, ("LBRACE", "{"), *inner[0].tokens, ("RBRACE", "}")]
        if len(code(head)) + len(inner[0].line.code) < BLOCK_WIDTH:
            return [Line(depth, code(tokens), "")]
    return [Line(depth, code([*head, ("LBRACE", "{")]), ""), *(p.line for p in inner),
            Line(depth, "}", "")]


# -- tokens -------------------------------------------------------------------------------------

def _head(node) -> list:
    """The tokens of a block's head: `when 1 and not 2`, `macro scan @5`."""
    match node:
        case ast.When(conditions):
            tokens = []
            for i, condition in enumerate(conditions):
                tokens += [("AND", "and")] * bool(i) + [("NOT", "not")] * condition.negated
                tokens.append(_value(condition.value))
            return [("WHEN", "when"), *tokens]
        case ast.Repeat(count):
            return [("REPEAT", "repeat"), _value(count)]
        case ast.Every(period):
            return [("EVERY", "every"), _period(period)]
        case ast.MacroDef(name, pin):
            return [("MACRO", "macro"), ("NAME", name)] + (
                [] if pin is None else [("AT", "@"), _value(pin)])
        case ast.Autostart():
            return [("AUTOSTART", "autostart")]
    raise TypeError(f"no block: {node!r}")


def _tokens(node) -> list:
    """The tokens of a line's node: a statement, a raw block, a declaration."""
    match node:
        case ast.Command(word, value):
            return [("MNEMONIC", word)] + ([] if value is None else [_value(value)])
        case ast.Call(name):
            return [("CALL", "call"), ("NAME", name)]
        case ast.Goto(name):
            return [("GOTO", "goto"), ("NAME", name)]
        case Run(body):
            return [t for i, stmt in enumerate(body) for t in [("COMMA", ",")] * bool(i) + _tokens(stmt)]
        case ast.RawBlock(slot, commands):
            return [("RAW_LINE", _raw(slot, ",".join(map(_stored, commands))))]
        case RawText(slot, text):
            return [("RAW_LINE", _raw(slot, text))]
        case ast.Target(model):
            return [("TARGET", "target"), ("MODEL", model)]
        case ast.Const(name, value):
            return [("CONST", "const"), ("NAME", name), ("EQUAL", "="), ("INT", str(value))]
    raise TypeError(f"no line: {node!r}")


def _value(value) -> tuple[str, str]:
    if isinstance(value, ast.Name):
        return ("SIGNED_NAME", value.sign + value.name) if value.sign else ("NAME", value.name)
    return ("INT", str(value.value))


def _period(period) -> tuple[str, str]:
    """`every 20ms`: the period's milliseconds as a duration, or the const that holds them."""
    return _value(period) if isinstance(period, ast.Name) else ("DURATION", f"{period.value}ms")


def _stored(command: ast.Command) -> str:
    """A raw block's command as MMCRun writes it, as fmt writes it: `EM9`, `SV FAST`."""
    word, value = command.word.upper(), command.value
    if isinstance(value, ast.Name):  # `SVFAST` would be another word
        return f"{word} {value.name.upper()}"
    return word if value is None else f"{word}{value.value}"


def _raw(slot: int, text: str) -> str:
    head = f"[{mdtext.slot_name(slot)}]"
    return f"{head} {text}" if text else head
