"""`mercmac lsp`: the language server over stdio (pygls; the optional extra `lsp`).

Every open document is re-checked on open and on each change by the same checker as
`mercmac check` (mercmac.lsp.recheck); the other features read that check's AST and
lowered program (mercmac.lsp.symbols). LSP positions are 0-based, spans 1-based.
Documents keep the editor's lines (mercmac.lsp.document), and messages are read so that
a bad frame does not stop the server (mercmac.lsp.framing).
"""
from __future__ import annotations

import asyncio
import logging
import re
import sys
from typing import Callable

from lsprotocol import types as t
from pygls.exceptions import JsonRpcException
from pygls.io_ import StdoutWriter
from pygls.lsp.server import LanguageServer

from mercmac import __version__
from mercmac.diagnostics import Report, Severity
from mercmac.errors import MercmacError
from mercmac.lsp import framing, symbols
from mercmac.lsp.document import Document, Documents
from mercmac.lsp.recheck import Checked, Rechecker
from mercmac.render.report import capped
from mercmac.source import LINE_END, Source, Span, split_lines

_SEVERITY = {Severity.ERROR: t.DiagnosticSeverity.Error,
             Severity.WARNING: t.DiagnosticSeverity.Warning,
             Severity.INFO: t.DiagnosticSeverity.Information}
_QUOTED = re.compile(r"'([^']+)'")
# Diagnostics sent per document: an editor lists them all, and past a thousand it slows
# down (a 2.5 MB file gave 288,000 of 700 bytes each, issue 20) while no one reads them.
MAX_DIAGNOSTICS = 1000


class MercmacServer(LanguageServer):
    """The server and, per document, its re-checker and latest check."""

    def __init__(self):
        super().__init__("mercmac", __version__)
        self.checkers: dict[str, Rechecker] = {}
        self.checks: dict[str, Checked] = {}
        self.names: dict[str, tuple] = {}  # uri -> (macros, consts) of the last check that parsed
        self.stale: set[str] = set()  # changed since their last check
        self.say: Callable[[str], None] = lambda message: None

    def start_io(self, stdin=None, stdout=None) -> None:
        """Serve over stdio until the client says `exit` or the input ends; input that
        ends inside a message is a MercmacError (the editor restarts the server)."""
        self.protocol.set_writer(StdoutWriter(stdout or sys.stdout.buffer))
        try:
            problem = asyncio.run(framing.serve(stdin or sys.stdin.buffer, self.deliver,
                                                self.say))
        finally:
            self.shutdown()
        if problem:
            raise MercmacError(f"language server: {problem}")

    def deliver(self, data: dict) -> None:
        """Hand one message to pygls; one it cannot take is said, and a request answered."""
        try:
            message = self.protocol.structure_message(data)
        except JsonRpcException as e:  # pygls would drop it and leave the request unanswered
            self.say(f"{data.get('method', 'a message')!s:.60}: {e.message}")
            if "id" in data and "method" in data:  # pygls has no public way to answer it
                self.protocol._send_response(data["id"], error=e.to_response_error())
            return
        if isinstance(message, dict):
            self.say("a JSON object that is no JSON-RPC 2.0 message: skipped")
            return
        try:
            self.protocol.handle_message(message)
        except Exception as e:  # a bug in a handler: say it, serve the next message
            self.say(f"{type(e).__name__}: {e}")

    def changed(self, uri: str) -> None:
        """Check `uri` once the messages read so far are handled: the edits that came while
        a long check ran are checked once, at their last version."""
        if not self.stale:
            asyncio.get_running_loop().call_soon(self.check_stale)
        self.stale.add(uri)

    def check_stale(self) -> None:
        """Check what changed; what a failure left unchecked is checked next."""
        try:
            while self.stale:
                self.recheck(self.stale.pop())
        finally:
            if self.stale:
                asyncio.get_running_loop().call_soon(self.check_stale)

    def recheck(self, uri: str) -> Checked:
        self.stale.discard(uri)
        document = self.workspace.get_text_document(uri)
        text = document.source
        checker = self.checkers.setdefault(uri, Rechecker(_name(uri)))
        try:
            checked = checker.check(text)
        except Exception as e:  # a compiler bug: say so on the file, as `check` does (issue 7)
            self.checkers.pop(uri, None)
            checked = _internal(Source(_name(uri), text), e)
        self.checks[uri] = checked
        if checked.module is not None:
            self.names[uri] = symbols.names(checked.items)
        self.text_document_publish_diagnostics(t.PublishDiagnosticsParams(
            uri=uri, version=document.version,
            diagnostics=_diagnostics(checked.compilation.report)))
        return checked

    def checked(self, uri: str) -> Checked:
        """The check of the document as it is now."""
        if uri in self.stale:
            return self.recheck(uri)
        return self.checks.get(uri) or self.recheck(uri)


def _internal(source: Source, error: Exception) -> Checked:
    from mercmac.compiler import Compilation
    from mercmac.diagnostics import Report

    report = Report(source.name)
    report.add("syntax", Span(1, 1, 1, 2), "internal", detail=f"{type(error).__name__}: {error}"[:200])
    return Checked(Compilation(source, report, None), None, ())


def _name(uri: str) -> str:
    return uri.rsplit("/", 1)[-1] or uri


def _range(span: Span) -> t.Range:
    end_line = span.end_line or span.line
    end_column = span.end_column or span.column + 1
    return t.Range(t.Position(span.line - 1, span.column - 1),
                   t.Position(end_line - 1, end_column - 1))


def _spot(position: t.Position) -> tuple[int, int]:
    return position.line + 1, position.character + 1


def _diagnostics(report: Report) -> list[t.Diagnostic]:
    """The first MAX_DIAGNOSTICS of `report` as `check` orders them, and how many more."""
    shown, left_out = capped(report.items, MAX_DIAGNOSTICS)
    out = [_diagnostic(d) for d in shown]
    for count in left_out.values():
        out.append(t.Diagnostic(
            range=t.Range(t.Position(0, 0), t.Position(0, 0)), source="mercmac",
            severity=t.DiagnosticSeverity.Information,
            message=f"{count:,} more diagnostics not shown (the first {MAX_DIAGNOSTICS:,} "
                    "are); `mercmac check --max-diagnostics 0` lists them all"))
    return out


def _diagnostic(d) -> t.Diagnostic:
    """A diagnostic whose code is the rule's; `data` carries `mercmac explain` of it."""
    return t.Diagnostic(
        range=_range(d.span), message=d.message, severity=_SEVERITY[d.severity],
        code=d.rule.code, source="mercmac",
        data={"rule": d.rule.name, "explain": f"{d.rule.code} {d.rule.name}: {d.rule.summary}\n\n"
                                              f"{d.rule.explanation}"})


server = MercmacServer()


@server.feature(t.INITIALIZE)
def initialize(ls: MercmacServer, params: t.InitializeParams) -> None:
    """Keep documents with the editor's lines: pygls has just made its workspace."""
    ls.workspace.__class__ = Documents


@server.feature(t.TEXT_DOCUMENT_DID_OPEN)
def did_open(ls: MercmacServer, params: t.DidOpenTextDocumentParams) -> None:
    ls.changed(params.text_document.uri)


@server.feature(t.TEXT_DOCUMENT_DID_CHANGE)
def did_change(ls: MercmacServer, params: t.DidChangeTextDocumentParams) -> None:
    ls.changed(params.text_document.uri)


@server.feature(t.TEXT_DOCUMENT_DID_CLOSE)
def did_close(ls: MercmacServer, params: t.DidCloseTextDocumentParams) -> None:
    uri = params.text_document.uri
    ls.stale.discard(uri)
    for table in (ls.checkers, ls.checks, ls.names):
        table.pop(uri, None)
    ls.text_document_publish_diagnostics(t.PublishDiagnosticsParams(uri=uri, diagnostics=[]))


@server.feature(t.TEXT_DOCUMENT_HOVER)
def hover(ls: MercmacServer, params: t.HoverParams) -> t.Hover | None:
    """A mnemonic, a macro or const name; the explanation of a diagnostic's rule under it."""
    checked = ls.checked(params.text_document.uri)
    line, column = _spot(params.position)
    parts = []
    command = symbols.command_at(checked.items, line, column)
    use = symbols.use_at(_uses(ls, params.text_document.uri), line, column)
    if command is not None:
        parts.append(symbols.command_help(command.word) or f"unknown command '{command.word}'")
    elif use is not None and use.kind == "macro":
        parts.append(symbols.macro_help(use.name, checked.compilation.program))
    elif use is not None:
        parts.append(symbols.const_help(use.name, checked.items))
    for d in checked.compilation.report.items:
        if symbols.inside(d.span, line, column):
            parts.append(f"**{d.rule.code}** ({d.rule.name}): {d.rule.summary}\n\n"
                         f"```text\n{d.rule.explanation}\n```")
    if not parts:
        return None
    return t.Hover(contents=t.MarkupContent(kind=t.MarkupKind.Markdown,
                                            value="\n\n---\n\n".join(parts)))


def _uses(ls: MercmacServer, uri: str) -> list[symbols.Use]:
    checked = ls.checked(uri)
    return symbols.uses(checked.items, checked.compilation.source)


@server.feature(t.TEXT_DOCUMENT_COMPLETION,
                t.CompletionOptions(trigger_characters=[" "]))
def completion(ls: MercmacServer, params: t.CompletionParams) -> t.CompletionList:
    """Mnemonics with their argument, keywords, macro names and consts."""
    uri = params.text_document.uri
    document = ls.workspace.get_text_document(uri)
    lines = document.lines
    line = lines[params.position.line] if params.position.line < len(lines) else ""
    before = line[:params.position.character]
    macros, consts = ls.names.get(uri) or symbols.names(ls.checked(uri).items)
    items = [t.CompletionItem(label=m, kind=t.CompletionItemKind.Function, detail="macro")
             for m in macros]
    if re.search(r"\b(call|goto)\s+\w*$", before):
        return t.CompletionList(is_incomplete=False, items=items)
    items += [t.CompletionItem(label=name, kind=t.CompletionItemKind.Constant,
                               detail=f"const = {value}") for name, value in consts.items()]
    items += [t.CompletionItem(label=k, kind=t.CompletionItemKind.Keyword)
              for k in symbols.KEYWORDS]
    items += [t.CompletionItem(label=m, kind=t.CompletionItemKind.Function, detail=hint,
                               documentation=t.MarkupContent(
                                   kind=t.MarkupKind.Markdown, value=symbols.command_help(m)))
              for m, hint, _ in symbols.mnemonics()]
    return t.CompletionList(is_incomplete=False, items=items)


def _same_name(ls: MercmacServer, params) -> tuple[str, list]:
    """The document and every use of the macro or const under the cursor (none off a name)."""
    uri = params.text_document.uri
    found = _uses(ls, uri)
    use = symbols.use_at(found, *_spot(params.position))
    if use is None:
        return uri, []
    return uri, [u for u in found if (u.kind, u.name) == (use.kind, use.name)]


@server.feature(t.TEXT_DOCUMENT_DEFINITION)
def definition(ls: MercmacServer, params: t.DefinitionParams) -> list[t.Location] | None:
    uri, same = _same_name(ls, params)
    return [t.Location(uri=uri, range=_range(u.span)) for u in same if u.defines] or None


@server.feature(t.TEXT_DOCUMENT_REFERENCES)
def references(ls: MercmacServer, params: t.ReferenceParams) -> list[t.Location] | None:
    uri, same = _same_name(ls, params)
    declarations = params.context.include_declaration
    return [t.Location(uri=uri, range=_range(u.span)) for u in same
            if declarations or not u.defines] or None


@server.feature(t.TEXT_DOCUMENT_PREPARE_RENAME)
def prepare_rename(ls: MercmacServer, params: t.PrepareRenameParams) -> t.Range | None:
    use = symbols.use_at(_uses(ls, params.text_document.uri), *_spot(params.position))
    return None if use is None else _range(use.span)


@server.feature(t.TEXT_DOCUMENT_RENAME)
def rename(ls: MercmacServer, params: t.RenameParams) -> t.WorkspaceEdit | None:
    """Rename a macro or a const at its definition and every use."""
    uri = params.text_document.uri
    found = _uses(ls, uri)
    use = symbols.use_at(found, *_spot(params.position))
    if use is None:
        return None
    new = params.new_name
    if not symbols.NAME.match(new) or new in symbols.KEYWORDS:
        raise ValueError(f"'{new}' is not a name: a letter or '_', then letters, digits, "
                         "'_' or '.' (not a keyword)")
    if any(u.defines and u.kind == use.kind and u.name == new for u in found):
        raise ValueError(f"a {use.kind} named '{new}' exists already")
    edits = [t.TextEdit(range=_range(u.span), new_text=new) for u in found
             if (u.kind, u.name) == (use.kind, use.name)]
    return t.WorkspaceEdit(changes={uri: edits})


@server.feature(t.TEXT_DOCUMENT_DOCUMENT_SYMBOL)
def document_symbols(ls: MercmacServer, params: t.DocumentSymbolParams) -> list[t.DocumentSymbol]:
    """Macros (with their slots after lowering), the autostart block, raw blocks, consts."""
    from mercmac.compiler import ast

    checked = ls.checked(params.text_document.uri)
    program = checked.compilation.program
    found = {u.span.line: u for u in symbols.uses(checked.items, checked.compilation.source)
             if u.defines}
    out = []
    for item in checked.items:
        whole = _range(item.span)
        if isinstance(item, (ast.MacroDef, ast.Autostart)):
            name = item.name if isinstance(item, ast.MacroDef) else "autostart"
            slots = symbols.slots_of(name, program) if program else []
            pick = found.get(item.span.line)
            out.append(t.DocumentSymbol(
                name=name, kind=t.SymbolKind.Function, range=whole,
                selection_range=_range(pick.span) if pick else whole,
                detail=", ".join(f"MC{m.slot:02d}" for m in slots),
                children=[t.DocumentSymbol(name=f"MC{m.slot:02d}", kind=t.SymbolKind.Field,
                                           range=whole, selection_range=whole, detail=m.line)
                          for m in slots]))
        elif isinstance(item, ast.RawBlock):
            out.append(t.DocumentSymbol(name=f"MC{item.slot:02d}", kind=t.SymbolKind.Function,
                                        range=whole, selection_range=whole, detail="raw block"))
        elif isinstance(item, ast.Const):
            pick = found.get(item.span.line)
            span = pick.span if pick else item.span
            out.append(t.DocumentSymbol(name=item.name, kind=t.SymbolKind.Constant,
                                        range=_range(span), selection_range=_range(span),
                                        detail=f"= {item.value}"))
    return out


@server.feature(t.TEXT_DOCUMENT_FORMATTING)
def formatting(ls: MercmacServer, params: t.DocumentFormattingParams) -> list[t.TextEdit] | None:
    """The whole document as `mercmac fmt` writes it (one edit), or no edit."""
    format_text = formatter()
    document: Document = ls.workspace.get_text_document(params.text_document.uri)
    text = document.source
    try:
        formatted = format_text(text)
    except Exception:  # a file the formatter refuses (syntax errors): leave it as it is
        return None
    if formatted == text:
        return []
    return [t.TextEdit(range=t.Range(t.Position(0, 0), document.end()), new_text=formatted)]


def formatter():
    """`format_text(text) -> str` of `mercmac fmt`."""
    from mercmac.fmt import format_text

    return format_text


@server.feature(t.TEXT_DOCUMENT_CODE_ACTION,
                t.CodeActionOptions(code_action_kinds=[t.CodeActionKind.QuickFix]))
def code_actions(ls: MercmacServer, params: t.CodeActionParams) -> list[t.CodeAction]:
    """The fixes that are safe: a "did you mean" replacement, a missing `target` line."""
    uri = params.text_document.uri
    checked = ls.checked(uri)
    source = checked.compilation.source
    wanted = params.range
    out = []
    for d in checked.compilation.report.items:
        r = _range(d.span)
        if (r.end.line, r.end.character) < (wanted.start.line, wanted.start.character) or (
                (r.start.line, r.start.character) > (wanted.end.line, wanted.end.character)):
            continue
        fix = _replacement(d, source)
        if fix is not None:
            edit, new = fix
            out.append(t.CodeAction(
                title=f"Replace with '{new}'", kind=t.CodeActionKind.QuickFix,
                diagnostics=[_diagnostic(d)], is_preferred=True,
                edit=t.WorkspaceEdit(changes={uri: [edit]})))
    if not symbols.has_target(checked.items, source.text):
        at = t.Position(symbols.target_line(source.text), 0)
        found = LINE_END.search(source.text)
        end = found.group() if found else "\n"  # the file's own line end, as an editor would
        for model in ("C-863", "C-663"):
            out.append(t.CodeAction(
                title=f"Add `target {model}`", kind=t.CodeActionKind.QuickFix,
                edit=t.WorkspaceEdit(changes={uri: [t.TextEdit(
                    range=t.Range(at, at), new_text=f"target {model}{end}")]})))
    return out


def _replacement(d, source: Source) -> tuple[t.TextEdit, str] | None:
    """The edit a "did you mean" message proposes: its first quoted name, replaced."""
    new = symbols.suggestion(d.message)
    old = _QUOTED.search(d.message)
    if new is None or old is None or d.span.end_line not in (0, d.span.line):
        return None
    line = source.line(d.span.line)
    start = line.find(old.group(1), d.span.column - 1, d.span.end_column - 1)
    if start < 0:
        return None
    span = Span(d.span.line, start + 1, d.span.line, start + 1 + len(old.group(1)))
    return t.TextEdit(range=_range(span), new_text=new), new


def main(say: Callable[[str], None]) -> None:
    """Serve over stdio; `say` tells stderr (the editor's log) what went wrong, one line
    each: pygls logs whole tracebacks, and the log wants the cause."""
    def tell(message: str) -> None:
        say(f"language server: {message}")

    server.say = tell
    logging.getLogger().addHandler(_Said(tell))
    server.start_io()


class _Said(logging.Handler):
    """pygls's and asyncio's warnings and errors, one line each through `say`."""

    def __init__(self, say: Callable[[str], None]):
        super().__init__(logging.WARNING)
        self.say = say

    def emit(self, record: logging.LogRecord) -> None:
        text = split_lines(record.getMessage())[0][:300]
        if record.exc_info and record.exc_info[1] is not None:
            error = record.exc_info[1]
            text += f": {type(error).__name__}: {error}"[:300]
        self.say(text)

