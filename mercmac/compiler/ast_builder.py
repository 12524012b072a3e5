"""Parse tree -> AST. The Transformer builds dataclasses with spans and nothing else."""
from __future__ import annotations

from mercmac import mdtext
from mercmac.compiler import ast
from mercmac.compiler.parser_tables import Token, Transformer, v_args
from mercmac.compiler.parse import BROKEN, paused_gc
from mercmac.source import Span


def _span(meta) -> Span:
    return Span(meta.line, meta.column, meta.end_line, meta.end_column)


def _tspan(tok: Token) -> Span:
    return Span(tok.line, tok.column, tok.end_line, tok.end_column)


def _number(tok: Token) -> ast.Number | ast.Invalid:
    value = mdtext.number(tok.value)  # None: more than MAX_DIGITS digits
    if value is None:
        digits = len(tok.value.lstrip("+- \t0"))
        return ast.Invalid("argument-range", "digits", (("digits", digits),), _tspan(tok))
    return ast.Number(value, _tspan(tok))


@v_args(meta=True)
class _Build(Transformer):
    def __init__(self):
        super().__init__(visit_tokens=False)  # no token callbacks: skip a failed getattr per token
        for name in _RULES:  # lark's v_args makes a wrapper at every access: bind each once
            setattr(self, name, getattr(self, name))

    def start(self, meta, items):
        return ast.Module(tuple(i for i in items if i is not None))

    def raw_block(self, meta, children):
        tok = children[0]
        raw = tok.value  # parse.RawLine: the commands as mercmac.mdtext read them
        if raw.problems:  # a broken line (parse_partial): left out, its error reported
            return None
        header = Span(tok.line, tok.column, tok.line, tok.column + raw.header)
        at = tok.column + raw.header
        commands = tuple(_raw_command(c, tok.line, at) for c in raw.commands)
        return ast.RawBlock(ast.TOO_BIG if raw.slot is None else raw.slot, commands, header)

    def target(self, meta, children):
        model = children[0].value.upper()
        return ast.Target(model if "-" in model else f"{model[0]}-{model[1:]}", _span(meta))

    def const(self, meta, children):
        name, value = children
        number = _number(value)
        kept = number.value if isinstance(number, ast.Number) else number
        return ast.Const(name.value, kept, _span(meta))

    def macro(self, meta, children):
        name, *rest = children
        pin = rest[0] if len(rest) == 2 else None
        return ast.MacroDef(name.value, pin, rest[-1], _span(meta))

    def pin(self, meta, children):
        return _number(children[0])

    def autostart(self, meta, children):
        return ast.Autostart(children[0], _span(meta))

    def block(self, meta, stmts):
        return tuple(stmts)

    def call(self, meta, children):
        return ast.Call(children[0].value, _span(meta))

    def goto(self, meta, children):
        return ast.Goto(children[0].value, _span(meta))

    def when(self, meta, children):
        *conditions, body = children
        # the block a broken line opened (parse.BROKEN): no conditions, its body still checked
        kept = tuple(c for c in conditions if not _broken(c.value))
        return ast.When(kept, body, _span(meta))

    def condition(self, meta, children):
        return ast.Condition(_value(children[-1]), len(children) == 2, _span(meta))

    def repeat(self, meta, children):
        return ast.Repeat(_value(children[0]), children[1], _span(meta))

    def every(self, meta, children):
        return ast.Every(children[0], children[1], _span(meta))

    def period(self, meta, children):
        tok = children[0]
        if tok.type == "NAME":
            return ast.Name(tok.value, _tspan(tok))
        from mercmac.timespec import parse_duration

        try:
            return ast.Number(parse_duration(tok.value), _tspan(tok))
        except (ValueError, OverflowError) as e:  # TimeSpecError is a ValueError
            return ast.Invalid("bad-argument", "duration", (("error", str(e)),), _tspan(tok))

    def command(self, meta, children):
        word = children[0]
        value = _value(children[1]) if len(children) > 1 else None
        return ast.Command(word.value, value, _span(meta), _tspan(word))


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


def _value(tok: Token) -> ast.Value:
    if tok.type == "INT":
        return _number(tok)
    return ast.Name(tok.value, _tspan(tok))


_RULES = [name for name in vars(_Build) if not name.startswith("_")]
_BUILDER = _Build()


def build(tree) -> ast.Module:
    """The AST of a parse tree."""
    with paused_gc():
        return _BUILDER.transform(tree)
