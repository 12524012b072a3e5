"""Text -> parse tree, with every syntax error reported in one run.

Lark's exceptions are translated here and nowhere else. After an error the
rest of the offending line is skipped and the parser carries on in one pass
(lark's `on_error`): its stack is unwound to where a line may end, and the
line's unbalanced braces are replayed so that blocks still nest. Checking a
file therefore costs time in proportion to its size, however many errors it
holds.

The parser reads text with every line end written LF (mercmac.source.to_lf): a CR or
CRLF ends a line as LF does, with the same line and column numbers.

A file that parses is read by `read`, which runs grammar.lark's own tables and builds the
AST as it goes, several times faster than lark's parse and tree (once 67-81 s to
check a 500 KB line); lark's parser reads the others, as only it recovers from errors.
"""
from __future__ import annotations

import bisect
import contextlib
import functools
import gc
import re
from typing import NamedTuple

from mercmac import mdtext
from mercmac.commands import Mnemonic, lookup
from mercmac.compiler import parser_tables as lark
from mercmac.diagnostics import SAFE, UNSAFE, Fix, Report
from mercmac.source import Span, to_lf

# `when`/`repeat`/`every` blocks nested deeper cannot fit the controller: each level needs
# a macro or a condition of its own and there are 32 macros of 16 commands (MS176E §3.8).
MAX_NESTING = 32
_NESTED = ("when", "repeat", "every")

# Terminal names of grammar.lark as a person would call them.
_TERMINALS = {
    "_NL": "end of line", "COMMA": "','", "LBRACE": "'{'", "RBRACE": "'}'", "AT": "'@'",
    "EQUAL": "'='", "MNEMONIC": "a command", "NAME": "a name", "INT": "a number",
    "SIGNED_NAME": "a signed name such as -FAR",
    "RAW_HEADER": "[MCnn]", "MODEL": "C-663 or C-863", "DURATION": "a duration such as 20ms",
    "$END": "end of file", "NOT": "'not'", "AND": "'and'", "MACRO": "'macro'",
    "TARGET": "'target'", "CONST": "'const'", "AUTOSTART": "'autostart'", "WHEN": "'when'",
    "REPEAT": "'repeat'", "EVERY": "'every'", "CALL": "'call'", "GOTO": "'goto'",
}

# Named errors (lark's match_examples): the `syntax` message variant (its wording is in
# mercmac.diagnostics) and snippets that fail the same way.
_EXAMPLES = {
    "comma": ["macro a { MR5000 WS100 }\n", "macro a { TP TT }\n"],  # raw lines: mdtext
    "outside": [
        "MR5000\n", "TP\n", "macro a { }\nTP\n", "[MC01] TP\nTP\n", "target C-863\nTP\n",
        "const A = 1\nTP\n",
    ],
    "brace": ["macro a {\nTP\n", "autostart { TP\n"],
    "macro-header": [
        "macro { }\n", "macro 5 { }\n", "macro a 5 { }\n", "macro a @ { }\n",
    ],
}
_MNEMONIC_BEFORE = re.compile(r"(?<![A-Za-z])([A-Za-z]{2}\??)[ \t]*$")


@contextlib.contextmanager
def paused_gc():
    """Hold the cycle collector while a large tree is built: the parse makes no cycles worth
    collecting, and each collection rescans every node made so far (2x on a 1 MB file)."""
    was_on = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_on:
            gc.enable()


def parser():
    """The stand-alone LALR parser (lark's), built once per process."""
    return _parser().lark


@functools.cache
def _parser() -> _Parser:
    return _Parser()


class _Parser:
    """lark's parser of grammar.lark, and what a parse under way needs beside it: the recovery
    that reports its errors, and where the named errors' examples fail (`_label`)."""

    def __init__(self):
        self.lark = lark.Lark_StandAlone(lexer_callbacks={"RAW_LINE": self._raw_line})
        self.recovery: _Recovery | None = None  # of the parse under way
        self.examples: dict[str, set] | None = None

    def parse(self, text: str, recovery: _Recovery | None = None):
        """lark's tree of TEXT; RECOVERY (None: raise at the first error) hears every error."""
        outer, self.recovery = self.recovery, recovery  # an example is read amid a file
        try:
            return self.lark.parse(text, on_error=recovery)
        finally:
            self.recovery = outer

    def _raw_line(self, token):
        """Read a raw block's commands as the controller reads a stored line (mercmac.mdtext);
        its syntax errors are the parser's (one per line, and the file is not checked further)."""
        token.value = raw = _read_raw(str(token))
        if raw.problems and self.recovery is not None:
            self.recovery.raw_error(token, raw.problems[0])
        return token

    def example_keys(self) -> dict[str, set]:
        """label -> the (state, token) keys where its examples fail, found once."""
        if self.examples is None:
            self.examples = {label: set(map(self._fails_at, examples))
                             for label, examples in _EXAMPLES.items()}
        return self.examples

    def _fails_at(self, example: str):
        try:
            self.parse(example)  # no recovery: not the file's errors
        except lark.UnexpectedInput as e:
            return _key(e)
        return None


class NotParsed(ValueError):
    """A text that does not parse: where the parser stopped (1-based line and column)."""

    def __init__(self, line: int, column: int):
        super().__init__(f"syntax error at {line}:{column}")
        self.line, self.column = line, column


def tokens(text: str) -> list[tuple[str, str]]:
    """(terminal, text) of every token of TEXT as the parser reads it, its comments in their
    places and its line ends written LF; NotParsed where TEXT does not parse.

    What `mercmac fmt` rewrites. No tree is built: grammar.lark's own LALR table and
    contextual lexer (parser_tables) are run directly, about ten times faster than the
    parse, so that formatting stays linear and quick on a 1 MB file. One loop,
    kept whole: it runs once per token.
    """
    r = _recognizer()
    lexers, table, ignored, blanks = r.lexers, r.table, r.ignored, r.blanks  # locals: faster
    text = to_lf(text) + "\n"  # as `parse` reads it: the last line ends
    stack, out, pos, size = [r.start], [], 0, len(text)
    while pos < size:
        match, keywords = lexers[stack[-1]]
        m = match(text, pos)
        if m is None:
            raise _not_parsed(text, pos)
        kind = m.lastgroup
        value = m.group(kind)
        if kind in keywords:  # a NAME that is a keyword (lark's UnlessCallback)
            kind = keywords[kind].get(value, kind)
        if kind not in ignored:
            action = table[stack[-1]].get(kind)
            if action is not None and action[0]:  # a shift, the common case: no call
                stack.append(action[1])
            elif not _shift(stack, r, kind):
                raise _not_parsed(text, m.start(m.lastgroup))
        if kind not in blanks:
            out.append((kind, value))
        pos = m.end()
    if not _shift(stack, r, "$END"):
        raise _not_parsed(text, size - 1)  # where the file ends
    return out


def _shift(stack: list, r: _Recognizer, kind: str) -> bool:
    """Feed a token of this kind to the LALR automaton: the reductions it implies, then its
    shift (for `$END`: the reductions up to the end state); False where it does not fit."""
    while True:
        action = r.table[stack[-1]].get(kind)
        if action is None:
            return False
        shift, arg = action
        if shift:
            stack.append(arg)
            return True
        size, origin, _ = arg
        if size:
            del stack[-size:]
        stack.append(r.table[stack[-1]][origin][1])
        if stack[-1] == r.end:
            return True


class Lexeme(NamedTuple):
    """A token as the AST builder gets it, from `read` or from lark's tree (ast_builder)."""

    type: str  # its terminal in grammar.lark
    value: object  # its text; a RawLine for a raw block
    span: Span


_LF = re.compile("\n")


def read(text: str, rules: dict):
    """What `rules` make of TEXT read bottom-up by grammar.lark's automaton, as `tokens`
    reads it: lark's parse, tree and Transformer in one pass, several times faster. None
    where TEXT does not read cleanly (a syntax error, a raw block whose commands do not read,
    blocks nested beyond MAX_NESTING, a NUL): `parse_partial` says why.

    `rules` maps each node of lark's tree to a function of the node's span and children,
    as a Transformer of lark's tree with positions gets them: the kept tokens (as Lexemes)
    and nodes, `_rule`s spliced in; a node spans its first token to its last, keywords and
    `_NL` included. Children wait in `out`; each stack entry records where its tokens start
    in the text and in `out`. One loop, kept whole: it runs once per token.
    """
    r = _recognizer()
    lexers, table, ignored, kept, where = r.lexers, r.table, r.ignored, r.kept, bisect.bisect_right
    new = tuple.__new__  # a NamedTuple without its Python-level __new__: half the cost
    text = to_lf(text) + "\n"  # as `parse_partial` reads it: the last line ends
    if "\x00" in text:
        return None
    lines = [0, *(m.end() for m in _LF.finditer(text))]  # where each line starts
    states, starts, marks, out = [r.start], [0], [0], []
    pos, size, depth, last, start, kind, value = 0, len(text), 0, 0, 0, "", ""
    while kind != "$END":
        if pos < size:
            match, keywords = lexers[states[-1]]
            m = match(text, pos)
            if m is None:
                return None
            kind = m.lastgroup
            pos = m.end()
            if kind in ignored:
                continue
            value, start = m.group(kind), m.start(kind)
            if kind in keywords:  # a NAME that is a keyword (lark's UnlessCallback)
                kind = keywords[kind].get(value, kind)
        else:
            kind = "$END"
        action = table[states[-1]].get(kind)
        while action is not None and not action[0]:  # the reductions this token implies
            n, origin, node = action[1]
            first = len(states) - n  # its first entry becomes the rule's (n > 0: _node)
            if n > 1:  # (one symbol, the common case, only changes its entry's state)
                del states[first + 1:], starts[first + 1:], marks[first + 1:]
            states[first] = table[states[first - 1]][origin][1]
            if node is not None:
                begin, mark = starts[first], marks[first]
                line, end = where(lines, begin), where(lines, last)
                column, end_column = begin - lines[line - 1] + 1, last - lines[end - 1] + 1
                span = new(Span, (line, column, end, end_column))
                children = out[mark:]
                del out[mark:]
                out.append(rules[node](span, children))
            action = table[states[-1]].get(kind)
        if action is None:
            return out[0] if kind == "$END" and states[-1] == r.end else None
        states.append(action[1])
        starts.append(start)
        marks.append(len(out))
        last = pos
        if kind in kept:
            if kind == "RAW_LINE":
                value = _read_raw(value)
                if value.problems:
                    return None
            line = where(lines, start)
            column = start - lines[line - 1] + 1
            span = new(Span, (line, column, line, column + pos - start))
            out.append(new(Lexeme, (kind, value, span)))
        elif kind == "LBRACE":  # deeper than the nesting limit: parse_partial reports it
            depth += 1
            if depth > MAX_NESTING + 1:  # a macro's block, and one per nested block
                return None
        elif kind == "RBRACE":
            depth -= 1
    return None


def _not_parsed(text: str, pos: int) -> NotParsed:
    while pos < len(text) and text[pos] in " \t\f":  # point at what follows the blanks
        pos += 1
    return NotParsed(text.count("\n", 0, pos) + 1, pos - text.rfind("\n", 0, pos))


class _Recognizer(NamedTuple):
    """grammar.lark's automaton as plain tables (see `tokens` and `read`)."""

    lexers: dict  # state -> (match function of its terminals, {word kind: {keyword: kind}})
    table: dict  # state -> {kind: (True, state) to shift, or (False, (size, rule, node)) to
    # reduce; `node` is the name of the tree node the rule makes, None for a `_rule`}
    start: int
    end: int
    ignored: frozenset  # terminals the parser skips: blanks and comments
    blanks: frozenset  # of those, the ones `tokens` leaves out
    kept: frozenset  # terminals a tree keeps (not `_NL`, not keywords and punctuation)


@functools.cache
def _recognizer() -> _Recognizer:
    """The automaton of the stand-alone parser, built once per process."""
    frontend = lark.Lark_StandAlone().parser
    ignored = frozenset(frontend.lexer_conf.ignore)
    parse_table = frontend.parser.parser.parse_table
    table = {state: {kind: (True, arg) if action is lark.Shift else
                     (False, (len(arg.expansion), arg.origin.name, _node(arg)))
                     for kind, (action, arg) in actions.items()}
             for state, actions in parse_table.states.items()}
    return _Recognizer(_Lexers(frontend.lexer.lexers), table, parse_table.start_states["start"],
                       parse_table.end_states["start"], ignored, ignored - {"COMMENT"},
                       _kept(frontend.parser_conf.rules))


def _node(rule) -> str | None:
    """The tree node a rule makes as lark's tree builder makes it (None: a `_rule`, whose
    children go to its parent's); `!rule`, `?rule` and `[x]` would change the tree."""
    options = rule.options
    # `start` may be empty, but a text ends in a line end, an `_NL`: `read` never reduces it
    assert rule.expansion or rule.origin.name == "start", "`read` reads no other empty rule"
    assert not (options.keep_all_tokens or options.expand1 or options.empty_indices), \
        "grammar.lark: `read` builds trees as lark does for plain rules only"
    return None if rule.origin.name.startswith("_") else rule.alias or rule.origin.name


def _kept(rules) -> frozenset:
    """The terminals lark keeps in its trees: named ones not written `_NAME`."""
    symbols = [s for rule in rules for s in rule.expansion if s.is_term]
    kept = frozenset(s.name for s in symbols if not s.filter_out)
    assert not kept & {s.name for s in symbols if s.filter_out}, "a terminal kept in one rule only"
    return kept


class _Lexers(dict):
    """state -> its lexer (see `_lexer`), compiled when a text first reaches the state: a
    file of a few lines reaches a third of them, and `check` starts sooner."""

    def __init__(self, lexers: dict):
        super().__init__()
        self.lexers = lexers  # lark's, by state

    def __missing__(self, state: int) -> tuple:
        self[state] = found = _lexer(self.lexers[state])
        return found


@functools.lru_cache(maxsize=None)  # states with the same terminals share lark's lexer
def _lexer(lexer) -> tuple:
    """One state's lexer: blanks before a token are skipped in the same match."""
    (pattern,) = [m.pattern for m in lexer.scanner._mres]  # one regex: 25 terminals fit
    keywords = {kind: {t.pattern.value: t.name for t in callback.scanner.terminals}
                for kind, callback in lexer.callback.items()}
    assert not any(t.pattern.flags for c in lexer.callback.values() for t in c.scanner.terminals), \
        "grammar.lark's keywords are plain strings: a word is one exactly as written"
    return re.compile(r"[ \t\f]*(?:" + pattern + ")").match, keywords


class RawLine(NamedTuple):
    """A `[MCnn] ...` line read by mdtext: the value of its RAW_LINE token."""

    slot: int | None  # None: more than MAX_DIGITS digits
    header: int  # length of `[MCnn]`: the commands start there
    commands: list[mdtext.Written]
    problems: list[mdtext.Problem]


def _read_raw(text: str) -> RawLine:
    """A RAW_LINE token's commands as mercmac.mdtext reads them."""
    found = mdtext.listed(text)  # grammar.lark's RAW_LINE starts with mdtext.RAW_HEADER
    body = found.body.split("//", 1)[0]  # a comment may end the line
    commands, problems = mdtext.lex(body)
    return RawLine(found.slot, found.header, commands, problems)


class Parsed(NamedTuple):
    """What parsing a file gives: the tree of what parsed, and the lines that did not."""

    tree: object | None  # (ast_builder.parse_module: the AST) None: nothing usable (a
    # binary file, or recovery gave up mid-file)
    broken: frozenset[int]  # lines with a syntax error: left out of `tree`
    failed: bool = False  # any syntax error (a missing '}' at the end breaks no line)


def parse(text: str, report: Report):
    """The parse tree of `text`, or None after reporting every syntax error."""
    parsed = parse_partial(text, report)
    return None if parsed.failed else parsed.tree


def parse_partial(text: str, report: Report) -> Parsed:
    """Report every syntax error and return the tree of the rest.

    A broken line is left out of the tree: what it held up to the error is
    dropped with it by the builder's caller (diagnostics on broken lines are the
    parser's), a `{` it opened is replaced by a block of no kind (an `ast.When`
    without conditions, or a macro named BROKEN) so that its body is still read,
    and a raw block whose commands do not read is left out. A file that ends
    inside a block is closed as if its braces were there.
    """
    text = to_lf(text)
    nul = text.find("\x00")
    if nul >= 0:
        span = _span_at(text, nul)
        report.add("syntax", span, "binary")
        return Parsed(None, frozenset({span.line}), True)
    recovery = _Recovery(report, text)
    try:
        with paused_gc():
            tree = _parser().parse(text + "\n", recovery)
    except lark.UnexpectedInput as e:  # reported; recovery stopped
        tree = _finish(e) if recovery.at_end else None
    finally:
        recovery.flush()
    broken = frozenset(recovery.lines)
    if tree is not None and text.count("{") > MAX_NESTING:
        _limit_nesting(tree, report)
    return Parsed(tree, broken, recovery.failed)


# The name of a block that a broken line opened (see _resume): no name can be written so.
BROKEN = " broken"


def _finish(e):
    """The tree of a file that ended inside blocks, its blocks closed; None if it cannot be."""
    ip = getattr(e, "interactive_parser", None)
    token = getattr(e, "token", None)
    if ip is None or token is None:
        return None
    state = ip.parser_state
    try:
        for _ in range(2 * len(state.state_stack) + 4):
            if _ends(state):
                return ip.feed_eof(token)
            kind = "RBRACE" if _accepts(state, "RBRACE") else "_NL"
            if not _accepts(state, kind):
                return None
            state.feed_token(lark.Token.new_borrow_pos(kind, "}" if kind == "RBRACE" else "\n",
                                                       token))
    except lark.UnexpectedInput:
        return None
    return None


def _span_at(text: str, index: int) -> Span:
    line = text.count("\n", 0, index) + 1
    column = index - text.rfind("\n", 0, index)
    return Span(line, column, line, column + 1)


class _Recovery:
    """lark's `on_error`: report the error, skip the rest of its line and carry on."""

    def __init__(self, report: Report, text: str = ""):
        self.report = report
        self.text = text
        self.failed = False
        self.at_end = False  # stopped at the end of the file (not mid-file)
        self.lines: set[int] = set()  # the broken lines
        self.last: tuple[int, int] | None = None  # (line, position) of the last error
        self.first = len(report.items)
        self.raw: dict[int, tuple] = {}  # line -> a raw block's syntax error, reported at the end

    def raw_error(self, token, problem) -> None:
        """A syntax error in a raw block's commands: kept unless the parser fails on its line."""
        self.failed = True
        self.lines.add(token.line)
        column = token.column + token.value.header
        span = Span(token.line, column + problem.start, token.line, column + problem.end)
        self.raw[token.line] = (span, problem.variant, dict(problem.values))

    def flush(self) -> None:
        """Report the raw blocks' errors among the parser's, in line order."""
        if not self.raw:
            return
        for line, (span, variant, values) in self.raw.items():
            self.report.add("syntax", span, variant, **values)
        self.report.items[self.first:] = sorted(self.report.items[self.first:],
                                                key=lambda d: d.span.line)

    def __call__(self, e) -> bool:
        self.failed = True
        lexer = e.interactive_parser.lexer_thread.state
        text, position = lexer.text.text, lexer.line_ctr.char_pos
        line = _error_line(e, text)
        if (line, position) == self.last:  # no progress: give up rather than loop
            return False
        self.raw.pop(line, None)  # one error per line: the parser's
        if not _at_end(e):  # a missing '}' at the end: the last line may well be whole
            self.lines.add(line)
        if self.last is None or self.last[0] != line or _at_end(e):  # one error per line
            hint = _hint(e, text, line)
            if hint is not None:
                self.report.add("syntax", hint[0], hint[1], **hint[2])
            else:
                variant, values = _message(e, line, _before(e, text))
                self.report.add("syntax", _error_span(e, line), variant, **values)
        self.last = (line, position)
        if _at_end(e):
            self.at_end = True
            return False
        try:
            return _resume(e, lexer, text, position)
        except lark.UnexpectedInput:  # the replayed braces do not fit: stop here
            return False


def _resume(e, lexer, text: str, position: int) -> bool:
    """Skip to the end of the line, unwind the stack until a line may end, replay braces."""
    token = getattr(e, "token", None)
    at_newline = token is not None and token.type == "_NL"
    end = position if at_newline else text.find("\n", position)
    end = len(text) if end < 0 else end
    start = token.start_pos if token is not None and not at_newline else position
    code = text[start:end].split("//", 1)[0]  # braces in the skipped text, comments aside
    lexer.line_ctr.feed(text[position:end])
    state = e.interactive_parser.parser_state
    while not _accepts(state, "_NL"):
        if len(state.state_stack) == 1:
            return False
        state.state_stack.pop()
        state.value_stack.pop()
    counter = lexer.line_ctr
    where = token if token is not None else lark.Token(
        "_NL", "", position, counter.line, counter.column, counter.line, counter.column, position)
    opens, closes = code.count("{"), code.count("}")
    if opens > closes:  # a block was opened: open one in its place so that its '}' still fits
        state.feed_token(lark.Token.new_borrow_pos("_NL", "\n", where))
        top = _accepts(state, "MACRO")  # `macro _ {` at the top, `when _ {` in a block
        head = (("MACRO", "macro"), ("NAME", BROKEN)) if top else (
            ("WHEN", "when"), ("NAME", BROKEN))
        for kind, value in (*head, ("LBRACE", "{")):
            state.feed_token(lark.Token.new_borrow_pos(kind, value, where))
    for _ in range(closes - opens):
        if not _accepts(state, "RBRACE"):
            break
        state.feed_token(lark.Token.new_borrow_pos("RBRACE", "}", where))
    if at_newline:  # the lexer has consumed it
        state.feed_token(token)
    return True


def _ends(state) -> bool:
    """Whether the file may end here (the reductions `$END` implies lead to the end state)."""
    states, end = state.parse_conf.states, state.parse_conf.end_state
    stack = list(state.state_stack)
    while stack[-1] != end:
        action = states[stack[-1]].get("$END")
        if action is None or action[0] is lark.Shift:
            return False
        rule = action[1]
        if rule.expansion:
            del stack[-len(rule.expansion):]
        stack.append(states[stack[-1]][rule.origin.name][1])
    return True


def _accepts(state, kind: str) -> bool:
    """Whether the parser would shift a token of this kind, after the reductions it implies
    (an LALR table also lists kinds that only a later state refuses)."""
    states = state.parse_conf.states
    stack = list(state.state_stack)
    while True:
        action = states[stack[-1]].get(kind)
        if action is None:
            return False
        what, rule = action
        if what is lark.Shift:
            return True
        if rule.expansion:
            del stack[-len(rule.expansion):]
        stack.append(states[stack[-1]][rule.origin.name][1])


def _limit_nesting(tree, report: Report) -> None:
    """Report blocks nested beyond MAX_NESTING and empty them, so that nothing downstream
    recurses that deep. Iterative: the tree may be thousands of levels deep."""
    stack = [(tree, 0)]
    while stack:
        node, depth = stack.pop()
        for child in getattr(node, "children", ()):
            if not hasattr(child, "data"):
                continue
            level = depth + (child.data in _NESTED)
            if level > MAX_NESTING:
                line, column = child.meta.line, child.meta.column
                report.add("slot-range", Span(line, column, line, column + len(child.data)),
                           "nesting", depth=MAX_NESTING)
                child.children[-1].children = []
            else:
                stack.append((child, level))


KEYWORDS = ("target", "const", "macro", "autostart", "call", "goto", "when", "repeat", "every",
            "not", "and")
_STATEMENT_WORD = re.compile(r"(?:^|[,{}])[ \t]*([A-Za-z_][A-Za-z0-9_]*)")
_WORD = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_NUMBER_BEFORE = re.compile(r"(?<![A-Za-z])([A-Za-z]{2})[ \t]*([+-]?[ \t]*\d+)[ \t]*$")
_UNIT = re.compile(r"(ms|s|min|h|d|mm|um|nm|cm|m|deg|counts?|cts|steps?)(?![A-Za-z0-9_])",
                   re.IGNORECASE)
_IN_MS = (Mnemonic.WA, Mnemonic.WS)  # commands whose argument is milliseconds (MS176E §6.4)


def keyword_candidates(word: str) -> list[str]:
    """The keywords a misspelled word may mean, likeliest first: one or two edits away
    (mercmac.suggest), or, past three letters, its letters shuffled. One alone is a safe
    fix (docs/checks.md, "Fixes")."""
    from mercmac.suggest import candidates

    low = word.lower()
    if low in KEYWORDS:  # `When 1`: keywords are lower case
        return [low] if word != low else []
    if len(low) < 3:
        return []
    near = candidates(low, KEYWORDS, limit=1 if len(low) < 4 else 2)
    if not near and len(low) > 3:
        near = [k for k in KEYWORDS if sorted(low) == sorted(k)]
    return near


def _hint(e, text: str, line: int):
    """(span, variant, values) of a syntax error that has a likely cause: a misspelled
    keyword (its values hold the `fix`), `or` between conditions, a unit after a number;
    else None."""
    token = getattr(e, "token", None)
    position = token.start_pos if token is not None else getattr(e, "pos_in_stream", None)
    if not isinstance(position, int) or position < 0 or position > len(text):
        return None
    start = text.rfind("\n", 0, position) + 1
    end = text.find("\n", position)
    end = len(text) if end < 0 else end
    if token is not None and token.type == "_NL":
        position = min(position, end)
    code = text[start:end].split("//", 1)[0]
    here = position - start
    row = text.count("\n", 0, start) + 1
    if row != line:
        return None
    starts = [m for m in _STATEMENT_WORD.finditer(code) if m.start(1) <= here]
    if starts and lookup(starts[-1].group(1)) is None:  # `if 1 {`, `wait 100ms`, `loop {`
        from mercmac.compiler import guesses

        m = starts[-1]
        guessed = guesses.syntax_hint(m.group(1), code[m.end(1):])
        if guessed is not None:
            return Span(row, m.start(1) + 1, row, m.end(1) + 1), *guessed
    for m in _STATEMENT_WORD.finditer(code):  # `whne 1 {`, `macor scan {`
        word = m.group(1)
        if m.start(1) > here or lookup(word) is not None:
            continue
        near = keyword_candidates(word)
        if near:
            span = Span(row, m.start(1) + 1, row, m.end(1) + 1)
            sure = SAFE if len(near) == 1 else UNSAFE
            return span, "keyword", {"word": word, "keyword": near[0],
                                     "fix": Fix.replacing(span, near[0], sure)}
    word = _WORD.match(code, here) if here < len(code) else None
    before = code[:here]
    if word is not None and word.group().lower() == "or" and re.search(r"\bwhen\b", before):
        span = Span(row, here + 1, row, word.end() + 1)
        return span, "or", {}
    number = _NUMBER_BEFORE.search(before)
    unit = _UNIT.match(code, here) if number is not None else None
    if unit is not None and lookup(number.group(1)) is not None:
        mnemonic = lookup(number.group(1)).mnemonic
        span = Span(row, number.start(2) + 1, row, unit.end() + 1)
        written = number.group(2).replace(" ", "").replace("\t", "") + unit.group()
        if mnemonic in _IN_MS and unit.group().lower() in ("ms", "s", "min", "h", "d"):
            from mercmac.timespec import parse_duration

            try:
                ms = parse_duration(written)
            except (ValueError, OverflowError):
                ms = None
            if ms is not None:
                return span, "milliseconds", {"command": mnemonic, "written": written, "ms": ms}
        return span, "unit", {"command": mnemonic, "written": written}
    return None


def _at_end(e) -> bool:
    return isinstance(e, lark.UnexpectedEOF) or getattr(getattr(e, "token", None), "type", "") == "$END"


def _error_line(e, text: str) -> int:
    line = getattr(e, "line", -1)
    return line if isinstance(line, int) and line > 0 else text.count("\n")


def _error_span(e, line: int) -> Span:
    column = getattr(e, "column", 1)
    column = column if isinstance(column, int) and column > 0 else 1
    token = getattr(e, "token", None)
    width = len(str(token).strip()) if token is not None and token.type not in ("_NL", "$END") else 1
    return Span(line, column, line, column + max(width, 1))


def _before(e, text: str, limit: int = 80) -> str:
    """The text of the error's line before the error (at most `limit` characters)."""
    token = getattr(e, "token", None)
    position = token.start_pos if token is not None else getattr(e, "pos_in_stream", None)
    if not isinstance(position, int) or position < 0:
        return ""
    start = max(text.rfind("\n", 0, position) + 1, position - limit)
    return text[start:position]


def _message(e, line: int, before: str) -> tuple[str, dict]:
    """The `syntax` message variant for this error and the values it names."""
    label = _label(e)
    if label:
        return label, {}
    found = _found(e)
    if isinstance(e, lark.UnexpectedCharacters) and not e.char.isascii():
        return "ascii", {"found": found}
    if found == "'.'" and before[-1:].isdigit():
        return "decimal", {}
    m = _MNEMONIC_BEFORE.search(before)
    command = lookup(m.group(1)) if m else None
    if command is not None and (isinstance(e, lark.UnexpectedCharacters) or found != "end of line"):
        return "argument", {"expects": command.expects(), "found": found}
    expected = _expected(e)
    return ("expected", {"found": found, "expected": expected}) if expected else (
        "unexpected", {"found": found})


def _label(e) -> str | None:
    """The variant of an example that fails in the same parser state on the same token.

    Like lark's `match_examples`, but by LALR state alone: lark also compares
    stack depth, so an example would only match at the top of a file.
    """
    key = _key(e)
    if key is None:
        return None
    for label, key_set in _parser().example_keys().items():
        if key in key_set:
            return label
    return None


def _key(e):
    state = getattr(e, "state", None)
    token = getattr(e, "token", None)
    if token is None or not hasattr(state, "position"):
        return None
    return state.position, token.type


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
