"""Parse tree -> AST: one function per rule of grammar.lark builds its node with its span.

Two readers call them, with the same span and children: `parse.read`, which builds the AST
while it reads a file that parses (several times faster than a tree, then a
Transformer), and lark's Transformer over the tree of a file with syntax errors, which only
lark's parser reads past (`parse.parse_partial`).
"""
from __future__ import annotations

import functools

from mercmac import mdtext
from mercmac.compiler import ast
from mercmac.compiler.parse import BROKEN, Lexeme, Parsed, parse_partial, paused_gc, read
from mercmac.compiler.parser_tables import Token, Transformer, v_args
from mercmac.diagnostics import Report
from mercmac.source import Span


def _number(tok: Lexeme) -> ast.Number | ast.Invalid:
    value = _read_number(tok.value)  # None: more than MAX_DIGITS digits
    if value is None:
        digits = len(tok.value.lstrip("+- \t0"))
        return ast.Invalid("argument-range", "digits", (("digits", digits),), tok.span)
    return ast.Number(value, tok.span)


# A file repeats its numbers: reading each once saves a quarter of building a command.
_read_number = functools.lru_cache(maxsize=4096)(mdtext.number)


def _through(span: Span, last: Lexeme) -> Span:
    """A one-line statement's span from its start to the end of its last token: the newline
    that ends it, and the blank lines after it, are not the statement's (an editor would
    underline the next line)."""
    return Span(span.line, span.column, last.span.end_line, last.span.end_column)


class _Nodes:
    """Each rule's node of its span and children (tokens as parse.Lexeme)."""

    def start(self, span, items):
        return ast.Module(tuple(i for i in items if i is not None))

    def raw_block(self, span, children):
        tok = children[0]
        raw = tok.value  # parse.RawLine: the commands as mercmac.mdtext read them
        if raw.problems:  # a broken line (parse_partial): left out, its error reported
            return None
        line, column = tok.span.line, tok.span.column
        header = Span(line, column, line, column + raw.header)
        at = column + raw.header
        commands = tuple(_raw_command(c, line, at) for c in raw.commands)
        return ast.RawBlock(ast.TOO_BIG if raw.slot is None else raw.slot, commands, header)

    def target(self, span, children):
        model = children[0].value.upper()
        return ast.Target(model if "-" in model else f"{model[0]}-{model[1:]}",
                          _through(span, children[0]))

    def const(self, span, children):
        name, value = children
        number = _number(value)
        kept = number.value if isinstance(number, ast.Number) else number
        return ast.Const(name.value, kept, _through(span, value))

    def macro(self, span, children):
        name, *rest = children
        pin = rest[0] if len(rest) == 2 else None
        return ast.MacroDef(name.value, pin, rest[-1], span)

    def pin(self, span, children):
        return _number(children[0])

    def autostart(self, span, children):
        return ast.Autostart(children[0], span)

    def block(self, span, stmts):
        return tuple(stmts)

    def call(self, span, children):
        return ast.Call(children[0].value, span)

    def goto(self, span, children):
        return ast.Goto(children[0].value, span)

    def when(self, span, children):
        *conditions, body = children
        # the block a broken line opened (parse.BROKEN): no conditions, its body still checked
        kept = tuple(c for c in conditions if not _broken(c.value))
        return ast.When(kept, body, span)

    def condition(self, span, children):
        return ast.Condition(_value(children[-1]), len(children) == 2, span)

    def repeat(self, span, children):
        return ast.Repeat(_value(children[0]), children[1], span)

    def every(self, span, children):
        return ast.Every(children[0], children[1], span)

    def period(self, span, children):
        tok = children[0]
        if tok.type == "NAME":
            return ast.Name(tok.value, tok.span)
        from mercmac.timespec import parse_duration

        try:
            return ast.Number(parse_duration(tok.value), tok.span)
        except (ValueError, OverflowError) as e:  # TimeSpecError is a ValueError
            return ast.Invalid("bad-argument", "duration", (("error", str(e)),), tok.span)

    def command(self, span, children):
        word = children[0]
        value = _value(children[1]) if len(children) > 1 else None
        return ast.Command(word.value, value, span, word.span)


def _broken(value) -> bool:
    return isinstance(value, ast.Name) and value.name == BROKEN


def _raw_command(c: mdtext.Written, line: int, at: int) -> ast.Command:
    """One command of a raw block, its columns counted from `at` (where the commands start)."""
    span = Span(line, at + c.start, line, at + c.end)
    value_span = Span(line, at + c.value_start, line, at + c.end)
    value = c.value
    if isinstance(value, int):
        value = ast.Number(value, value_span)
    elif isinstance(value, mdtext.TooLong):
        value = ast.Invalid("argument-range", "digits", (("digits", value.digits),), value_span)
    elif value is not None:
        value = ast.Name(value, value_span)
    return ast.Command(c.word, value, span, Span(line, at + c.start, line, at + c.word_end))


def _value(tok: Lexeme) -> ast.Value:
    if tok.type == "INT":
        return _number(tok)
    if tok.type == "SIGNED_NAME":  # `-FAR`, `- FAR`: grammar.lark
        return ast.Name(tok.value[1:].lstrip(" \t"), tok.span, tok.value[0])
    return ast.Name(tok.value, tok.span)


_NODES = _Nodes()
RULES = {name: getattr(_NODES, name) for name in vars(_Nodes) if not name.startswith("_")}


def _from_tree(rule, _data, children, meta):
    """lark's visit wrapper: a tree node's rule gets its span and children as `read` gives them."""
    span = None if meta.empty else Span(meta.line, meta.column, meta.end_line, meta.end_column)
    return rule(span, [Lexeme(c.type, c.value, Span(c.line, c.column, c.end_line, c.end_column))
                       if isinstance(c, Token) else c for c in children])


class _Tree(Transformer):
    """lark's parse tree (a file with syntax errors) -> the AST, by the same rules."""

    def __init__(self):
        super().__init__(visit_tokens=False)  # no token callbacks: skip a failed getattr per token
        for name, rule in RULES.items():
            setattr(self, name, v_args(wrapper=_from_tree)(rule))


_TREE = _Tree()


def build(tree) -> ast.Module:
    """The AST of a parse tree."""
    with paused_gc():
        return _TREE.transform(tree)


def parse_module(text: str, report: Report) -> Parsed:
    """Parsed with the AST of TEXT as its tree: read in one pass when the file parses, else
    by `parse_partial`, which reports every syntax error and reads past them."""
    with paused_gc():
        module = read(text, RULES)
    if module is not None:
        return Parsed(module, frozenset())
    parsed = parse_partial(text, report)
    return parsed if parsed.tree is None else parsed._replace(tree=build(parsed.tree))
