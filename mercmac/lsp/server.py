"""`mercmac lsp`: the language server over stdio (pygls; the optional extra `lsp`).

Every open document is re-checked on open and on each change, and what it publishes is
what `mercmac check` reports: the same function (mercmac.compiler.checking) with the
same settings files, `// mercmac: ignore` comments and, as check's options, the
editor's workspace settings (mercmac.lsp.settings); only the compiling is incremental
(mercmac.lsp.recheck). The other features read that check's AST and lowered program
(mercmac.lsp.symbols, mercmac.lsp.completion). Documents keep the editor's lines and
convert every position, read or sent (mercmac.lsp.document); messages are read so that
a bad frame does not stop the server (mercmac.lsp.framing). Rig files get what `check
RIG` reports on them, and a rig's programs its models (mercmac.lsp.rig).
"""
from __future__ import annotations

import asyncio
import logging
import os
import sys
from typing import Callable

from lsprotocol import types as t
from pygls import uris
from pygls.capabilities import get_capability
from pygls.exceptions import JsonRpcException
from pygls.io_ import StdoutWriter
from pygls.lsp.server import LanguageServer

from mercmac import __version__, config
from mercmac.commands import MODELS, Mnemonic
from mercmac.compiler import Compilation, checking
from mercmac.diagnostics import DISPLAY_ONLY, SAFE, UNSAFE, Diagnostic, Fix, Report, Severity
from mercmac.errors import MercmacError, SettingsError
from mercmac.lsp import completion as completion_rules, framing, rig, settings, symbols
from mercmac.lsp.document import Document, Documents
from mercmac.lsp.recheck import Checked, Rechecker
from mercmac.mdtext import slot_name
from mercmac.render.report import capped
from mercmac.source import Source, Span, split_lines

_SEVERITY = {Severity.ERROR: t.DiagnosticSeverity.Error,
             Severity.WARNING: t.DiagnosticSeverity.Warning,
             Severity.INFO: t.DiagnosticSeverity.Information}
# Diagnostics sent per document: an editor lists them all, and past a thousand it slows
# down (a 2.5 MB file gave 288,000 of 700 bytes each) while no one reads them.
MAX_DIAGNOSTICS = 1000
SETTINGS_FILES = ("mercmac.toml", "pyproject.toml")  # mercmac.config reads these
ADD_TARGET = f"{t.CodeActionKind.Source.value}.addTarget"
# How long checks wait for the client's answer to workspace/configuration: editors answer
# at once; one that never does must not keep a file from being checked.
SETTINGS_WAIT_S = 5.0


class Refusal(JsonRpcException):
    """A request the server declines, with the reason (LSP RequestFailed): the user asked
    for something that cannot be done, and the server has no fault to log."""

    CODE = t.LSPErrorCodes.RequestFailed


class Seen:
    """The latest check of one open document: the re-checker's result and what `check`
    reports of it; the items of a file with syntax errors are read when first wanted.
    A rig file (`rig`) has diagnostics only: it is TOML, with no macros to navigate."""

    __slots__ = ("checked", "diagnostics", "_items", "rig")

    def __init__(self, checked: Checked, diagnostics: list[Diagnostic], rig: bool = False):
        self.checked, self.diagnostics, self._items, self.rig = checked, diagnostics, None, rig

    @property
    def compilation(self) -> Compilation:
        return self.checked.compilation

    @property
    def items(self) -> tuple:
        """The AST's items; with syntax errors, those of every block as far as it parses
        (the re-checker keeps only the blocks without errors), so that a block being
        typed stays in the outline."""
        if self.checked.module is not None or self.rig:
            return self.checked.items
        if self._items is None:
            self._items = symbols.partial_items(self.compilation.source.text)
        return self._items


class MercmacServer(LanguageServer):
    """The server and, per document, its re-checker and latest check."""

    def __init__(self):
        super().__init__("mercmac", __version__)
        self.checkers: dict[str, Rechecker] = {}
        self.checks: dict[str, Seen] = {}
        self.parsed: dict[str, Checked] = {}  # the re-checker's result of the check under way
        self.names: dict[str, tuple] = {}  # uri -> (macros, consts) of the last check that parsed
        self.stale: set[str] = set()  # changed since their last check
        self.options = checking.Options()  # the workspace settings, as check's options
        self.settling: set[asyncio.Task] = set()  # questions for the workspace settings
        self.told: set[str] = set()  # settings problems shown since the settings last changed
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
        if rig.is_rig_path(uri):  # its programs are checked with the models it names
            self.stale.update(u for u in self.workspace.text_documents
                              if not rig.is_rig_path(u))

    def check_stale(self) -> None:
        """Check what changed; what a failure left unchecked is checked next. While the
        workspace settings are asked for, wait for them: diagnostics that vanish a moment
        after a file opens would be noise."""
        if self.settling:
            return  # the answer checks what is stale then
        try:
            while self.stale:
                self.recheck(self.stale.pop())
        finally:
            if self.stale:
                asyncio.get_running_loop().call_soon(self.check_stale)

    def recheck(self, uri: str) -> Seen:
        """Check `uri` as `check` would, and publish what it reports."""
        self.stale.discard(uri)
        document: Document = self.workspace.get_text_document(uri)
        if rig.is_rig_path(uri):
            return self.recheck_rig(uri, document)
        self.parsed.pop(uri, None)
        choice, owner = self.choice(uri), self.owner(uri)
        if owner is not None:  # the rig says which controller, hence which model
            choice = choice._replace(target=owner.controller.model)
        source = Source(_name(uri), document.source)
        found = checking.check(source, choice,
                               lambda source, target: self._compile(uri, source, target, owner))
        if owner is not None:
            found = found._replace(diagnostics=found.diagnostics + self.rig_rules(owner, source,
                                                                                 choice))
        checked = self.parsed.pop(uri, None)
        if checked is None:  # a compiler bug, reported on the file: start afresh next time
            self.checkers.pop(uri, None)
            checked = Checked(found.compilation, None, ())
        seen = self.checks[uri] = Seen(checked, found.diagnostics)
        if checked.module is not None:
            self.names[uri] = symbols.names(checked.items)
        self.text_document_publish_diagnostics(t.PublishDiagnosticsParams(
            uri=uri, version=document.version,
            diagnostics=_diagnostics(found.diagnostics, document)))
        return seen

    def _compile(self, uri: str, source: Source, target: str | None,
                 owner: rig.Owner | None = None) -> Compilation:
        """The re-checker's compilation; its AST is kept for the other features. A program
        of a rig also gets the rig's model-mismatch on a `target` line of another model."""
        checker = self.checkers.get(uri)
        if checker is None or checker.target != target:
            checker = self.checkers[uri] = Rechecker(source.name, target)
        checked = self.parsed[uri] = checker.check(source.text)
        if owner is None:
            return checked.compilation
        return rig.with_rig_model(checked.compilation, owner, checked.items)

    def recheck_rig(self, uri: str, document: Document) -> Seen:
        """Check a rig file as `check RIG` would, and publish what it reports on the file."""
        source = Source(_path(uri), document.source)  # its programs are relative to it
        found = rig.rig_diagnostics(source, self.choice(uri))  # a failure: said at 1:1
        seen = self.checks[uri] = Seen(Checked(Compilation(source, Report(source.name), None),
                                               None, ()), found, rig=True)
        self.text_document_publish_diagnostics(t.PublishDiagnosticsParams(
            uri=uri, version=document.version, diagnostics=_diagnostics(found, document)))
        return seen

    def rig_rules(self, owner: rig.Owner, source: Source, choice) -> list[Diagnostic]:
        """The rig rules `check RIG` reports in a program of the rig (lsp/rig.py)."""
        try:
            return rig.program_rig_diagnostics(owner, source, choice)
        except Exception as e:  # a bug in the rig checks must not stop the file's own check
            self.say(f"checking the rig of {source.name}: {type(e).__name__}: {e}"[:300])
            return []

    def owner(self, uri: str) -> rig.Owner | None:
        """The rig that names the document at `uri` as a program (its open text counts)."""
        if not uri.startswith("file:"):
            return None

        def open_text(path: str) -> str | None:
            document = self.workspace.text_documents.get(uris.from_fs_path(path))
            return None if document is None else document.source

        try:
            return rig.owner_of(uris.to_fs_path(uri), open_text)
        except Exception as e:  # a bug in reading rigs must not stop the file's own check
            self.say(f"finding the rig of {_name(uri)}: {type(e).__name__}: {e}"[:300])
            return None

    def checked(self, uri: str) -> Seen:
        """The check of the document as it is now."""
        if uri in self.stale:
            return self.recheck(uri)
        return self.checks.get(uri) or self.recheck(uri)

    def choice(self, uri: str) -> checking.Choice:
        """The rules and model for a document: its settings file under the workspace
        settings. A settings file that `check` would refuse is shown, and passed over."""
        path = uris.to_fs_path(uri) if uri.startswith("file:") else None
        try:
            return checking.choice_for(path, self.options)
        except SettingsError as e:
            self.tell(f"{e.message} ({e.hint})" if e.hint else e.message)
            return checking.choice_for(None, self.options)

    def tell(self, message: str) -> None:
        """Show a problem with the settings to the user, once until the settings change."""
        if message not in self.told:
            self.told.add(message)
            self.window_show_message(t.ShowMessageParams(
                type=t.MessageType.Error, message=f"mercmac: {message}"))

    def use_settings(self, section) -> None:
        """Take the workspace's `mercmac` settings (their problems shown) and check again."""
        self.options, problems = settings.options_from(section)
        self.settings_changed()
        for problem in problems:
            self.tell(problem)

    def settings_changed(self) -> None:
        """Read the settings files again and re-check every open document."""
        config.forget()
        self.told.clear()
        self.stale.update(self.workspace.text_documents)
        if self.stale:
            asyncio.get_running_loop().call_soon(self.check_stale)

    def pull_settings(self) -> None:
        """Ask the client for the `mercmac` settings (workspace/configuration); checks
        wait for the answer (check_stale)."""
        task = asyncio.ensure_future(self._pull_settings())
        self.settling.add(task)
        task.add_done_callback(self.settling.discard)

    async def _pull_settings(self) -> None:
        params = t.ConfigurationParams(items=[t.ConfigurationItem(section=settings.SECTION)])
        try:
            answer = await asyncio.wait_for(self.workspace_configuration_async(params),
                                            SETTINGS_WAIT_S)
        except Exception as e:  # a client that cannot answer: the settings stay as they are
            self.say(f"workspace/configuration: {type(e).__name__}: {e}"[:300])
            answer = None
        self.settling.discard(asyncio.current_task())
        if answer is None:
            self.settings_changed()
        else:
            self.use_settings(answer[0] if answer else None)


def _name(uri: str) -> str:
    return uri.rsplit("/", 1)[-1] or uri


def _path(uri: str) -> str:
    """The file's path for a `file:` URI, else its name."""
    return (uris.to_fs_path(uri) or _name(uri)) if uri.startswith("file:") else _name(uri)


def _diagnostics(found: list[Diagnostic], document: Document) -> list[t.Diagnostic]:
    """The first MAX_DIAGNOSTICS of `found` as `check` orders them, and how many more."""
    shown, left_out = capped(found, MAX_DIAGNOSTICS)
    out = [_diagnostic(d, document) for d in shown]
    for count in left_out.values():
        out.append(t.Diagnostic(
            range=t.Range(t.Position(0, 0), t.Position(0, 0)), source="mercmac",
            severity=t.DiagnosticSeverity.Information,
            message=f"{count:,} more diagnostics not shown (the first {MAX_DIAGNOSTICS:,} "
                    "are); `mercmac check --max-diagnostics 0` lists them all"))
    return out


def _diagnostic(d: Diagnostic, document: Document) -> t.Diagnostic:
    """A diagnostic whose code is the rule's; `data` carries `mercmac explain` of it."""
    return t.Diagnostic(
        range=document.range_of(d.span), message=d.message, severity=_SEVERITY[d.severity],
        code=d.rule.code, source="mercmac",
        data={"rule": d.rule.name, "explain": f"{d.rule.code} {d.rule.name}: {d.rule.summary}\n\n"
                                              f"{d.rule.explanation}"})


server = MercmacServer()


@server.feature(t.INITIALIZE)
def initialize(ls: MercmacServer, params: t.InitializeParams) -> None:
    """Keep documents with the editor's lines: pygls has just made its workspace."""
    ls.workspace.__class__ = Documents


@server.feature(t.INITIALIZED)
def initialized(ls: MercmacServer, params: t.InitializedParams) -> None:
    """Watch the settings files where the client can, and ask for the workspace settings."""
    capabilities = ls.client_capabilities
    if get_capability(capabilities, "workspace.did_change_watched_files.dynamic_registration",
                      False):
        asked = ls.client_register_capability(t.RegistrationParams(registrations=[
            t.Registration(id="mercmac-settings-files",
                           method=t.WORKSPACE_DID_CHANGE_WATCHED_FILES,
                           register_options=t.DidChangeWatchedFilesRegistrationOptions(watchers=[
                               t.FileSystemWatcher(glob_pattern=f"**/{name}")
                               for name in SETTINGS_FILES]))]))
        asked.add_done_callback(lambda answer: answer.cancelled() or not answer.exception()
                                or ls.say(f"client/registerCapability: {answer.exception()}"))
    if get_capability(capabilities, "workspace.configuration", False):
        ls.pull_settings()


@server.feature(t.WORKSPACE_DID_CHANGE_CONFIGURATION)
def did_change_configuration(ls: MercmacServer, params: t.DidChangeConfigurationParams) -> None:
    """New workspace settings: asked for where the client answers, else those it sent."""
    if get_capability(ls.client_capabilities, "workspace.configuration", False):
        ls.pull_settings()
    else:
        sent = params.settings
        ls.use_settings(sent.get(settings.SECTION) if isinstance(sent, dict) else None)


@server.feature(t.WORKSPACE_DID_CHANGE_WATCHED_FILES)
def did_change_watched_files(ls: MercmacServer, params: t.DidChangeWatchedFilesParams) -> None:
    ls.settings_changed()


@server.feature(t.TEXT_DOCUMENT_DID_OPEN)
def did_open(ls: MercmacServer, params: t.DidOpenTextDocumentParams) -> None:
    config.forget()  # a settings file may have changed since the last one was opened
    ls.changed(params.text_document.uri)


@server.feature(t.TEXT_DOCUMENT_DID_CHANGE)
def did_change(ls: MercmacServer, params: t.DidChangeTextDocumentParams) -> None:
    ls.changed(params.text_document.uri)


@server.feature(t.TEXT_DOCUMENT_DID_SAVE)
def did_save(ls: MercmacServer, params: t.DidSaveTextDocumentParams) -> None:
    """A save is when clients without file watchers get settings files read again."""
    if os.path.basename(params.text_document.uri) in SETTINGS_FILES:
        ls.settings_changed()
    else:
        config.forget()
        ls.changed(params.text_document.uri)
        # a rig's checks read its programs as saved
        ls.stale.update(u for u in ls.workspace.text_documents if rig.is_rig_path(u))


@server.feature(t.TEXT_DOCUMENT_DID_CLOSE)
def did_close(ls: MercmacServer, params: t.DidCloseTextDocumentParams) -> None:
    uri = params.text_document.uri
    ls.stale.discard(uri)
    for table in (ls.checkers, ls.checks, ls.names):
        table.pop(uri, None)
    ls.text_document_publish_diagnostics(t.PublishDiagnosticsParams(uri=uri, diagnostics=[]))


def _at(ls: MercmacServer, params) -> tuple[Document, Seen, int, int]:
    """The document, its check, and the 1-based line and column of the request's position."""
    uri = params.text_document.uri
    seen = ls.checked(uri)
    document: Document = ls.workspace.get_text_document(uri)
    return (document, seen, *document.spot(params.position))


def _uses(seen: Seen) -> list[symbols.Use]:
    if seen.rig:  # a rig file names no macros or consts
        return []
    return symbols.uses(seen.items, seen.compilation.source, seen.compilation.program)


@server.feature(t.TEXT_DOCUMENT_HOVER)
def hover(ls: MercmacServer, params: t.HoverParams) -> t.Hover | None:
    """A mnemonic, a macro, const or slot (`[MCnn]`, `EMn`), a keyword, an `every`
    period; the explanation of each reported diagnostic under it."""
    document, seen, line, column = _at(ls, params)
    parts, spans = [], []
    for text, span in () if seen.rig else _meanings(seen, line, column):
        parts.append(text)
        spans.append(span)
    for d in seen.diagnostics:
        if symbols.inside(d.span, line, column):
            parts.append(f"**{d.rule.code}** ({d.rule.name}): {d.rule.summary}\n\n"
                         f"```text\n{d.rule.explanation}\n```")
            spans.append(d.span)
    if not parts:
        return None
    return t.Hover(contents=t.MarkupContent(kind=t.MarkupKind.Markdown,
                                            value="\n\n---\n\n".join(parts)),
                   range=document.range_of(spans[0]))


def _meanings(seen: Seen, line: int, column: int):
    """(hover text, span) of what stands at (line, column): a slot, name, command,
    `every` period or keyword."""
    program, items = seen.compilation.program, seen.items
    use = symbols.use_at(_uses(seen), line, column)
    command = symbols.command_at(items, line, column)
    if use is not None and use.kind == "slot":
        yield symbols.slot_help(use.slot, program), use.span
    elif use is not None:
        yield (symbols.macro_help(use.name, program) if use.kind == "macro"
               else symbols.const_help(use.name, items)), use.span
    if command is not None:
        yield (symbols.command_help(command.word) or f"unknown command '{command.word}'",
               command.word_span)
    period = symbols.period_at(items, line, column)
    if period is not None:
        written = seen.compilation.source.line(line)[period.span.column - 1:
                                                     period.span.end_column - 1]
        yield symbols.duration_help(written.strip(), period.value), period.span
    keyword = symbols.keyword_at(seen.compilation.source.line(line), column)
    if keyword is not None:
        word, start = keyword
        yield symbols.KEYWORD_HELP[word], Span(line, start, line, start + len(word))


@server.feature(t.TEXT_DOCUMENT_COMPLETION,
                t.CompletionOptions(trigger_characters=[" ", ","]))
def completion(ls: MercmacServer, params: t.CompletionParams) -> t.CompletionList:
    """The words that may stand at the cursor (mercmac.lsp.completion)."""
    uri = params.text_document.uri
    if rig.is_rig_path(uri):  # TOML: no macro words to offer
        return t.CompletionList(is_incomplete=False, items=[])
    document: Document = ls.workspace.get_text_document(uri)
    offset = document.offset_at(params.position)
    text = document.source
    start = max(text.rfind("\n", 0, offset), text.rfind("\r", 0, offset)) + 1
    offer = completion_rules.offer(text[start:offset], completion_rules.depth_at(text[:offset]))
    names = ([], {})
    if {"macros", "consts"} & set(offer.kinds):  # of the last check that parsed
        names = ls.names.get(uri) or symbols.names(ls.checked(uri).items)
    return t.CompletionList(is_incomplete=False, items=[
        item for kind in offer.kinds for item in _items(kind, offer, names)])


def _items(kind: str, offer, names) -> list[t.CompletionItem]:
    macros, consts = names
    if kind == "keywords":
        return [t.CompletionItem(label=k, kind=t.CompletionItemKind.Keyword,
                                 documentation=_markdown(symbols.KEYWORD_HELP[k]))
                for k in offer.keywords]
    if kind == "mnemonics":
        return [t.CompletionItem(label=m, kind=t.CompletionItemKind.Function, detail=hint,
                                 documentation=_markdown(symbols.command_help(m)))
                for m, hint, _ in symbols.mnemonics()]
    if kind == "models":
        return [t.CompletionItem(label=m, kind=t.CompletionItemKind.EnumMember)
                for m in MODELS]
    if kind == "durations":
        return [t.CompletionItem(label=_duration(ms), kind=t.CompletionItemKind.Value,
                                 detail=f"{Mnemonic.WA}{ms}", documentation=_markdown(
                                     symbols.duration_help(_duration(ms), ms)))
                for ms in completion_rules.DURATIONS]
    if kind == "macros":
        return [t.CompletionItem(label=m, kind=t.CompletionItemKind.Function, detail="macro")
                for m in macros]
    return [t.CompletionItem(label=name, kind=t.CompletionItemKind.Constant,
                             detail=f"const = {value}") for name, value in consts.items()]


def _duration(ms: int) -> str:
    return f"{ms // 1000}s" if ms % 1000 == 0 else f"{ms}ms"


def _markdown(text: str | None) -> t.MarkupContent | None:
    return None if text is None else t.MarkupContent(kind=t.MarkupKind.Markdown, value=text)


def _same(ls: MercmacServer, params) -> tuple[str, Document, list[symbols.Use]]:
    """The document and every use of the name or slot under the cursor (none off one)."""
    document, seen, line, column = _at(ls, params)
    found = _uses(seen)
    use = symbols.use_at(found, line, column)
    return params.text_document.uri, document, [] if use is None else symbols.same(found, use)


@server.feature(t.TEXT_DOCUMENT_DEFINITION)
def definition(ls: MercmacServer, params: t.DefinitionParams) -> list[t.Location] | None:
    """Where a macro, const or slot is defined: `call scan` -> `macro scan`, `EM11` -> `[MC11]`."""
    uri, document, same = _same(ls, params)
    return [t.Location(uri=uri, range=document.range_of(u.span)) for u in same
            if u.defines] or None


@server.feature(t.TEXT_DOCUMENT_REFERENCES)
def references(ls: MercmacServer, params: t.ReferenceParams) -> list[t.Location] | None:
    """Every use of a macro, const or slot: a slot's `EMn` and the calls of the macro there."""
    uri, document, same = _same(ls, params)
    declarations = params.context.include_declaration
    return [t.Location(uri=uri, range=document.range_of(u.span)) for u in same
            if declarations or not u.defines] or None


def _renamed(ls: MercmacServer, params) -> tuple[Document, list[symbols.Use], symbols.Use | None]:
    """The document, its uses, and the name (not slot) under the cursor."""
    document, seen, line, column = _at(ls, params)
    found = _uses(seen)
    use = symbols.use_at(found, line, column)
    return document, found, None if use is None or use.kind == "slot" else use


@server.feature(t.TEXT_DOCUMENT_PREPARE_RENAME)
def prepare_rename(ls: MercmacServer, params: t.PrepareRenameParams) -> t.Range | None:
    document, _, use = _renamed(ls, params)
    return None if use is None else document.range_of(use.span)


@server.feature(t.TEXT_DOCUMENT_RENAME)
def rename(ls: MercmacServer, params: t.RenameParams) -> t.WorkspaceEdit | None:
    """Rename a macro or a const at its definition and every use; a name that cannot be
    is refused with the reason (RequestFailed)."""
    document, found, use = _renamed(ls, params)
    if use is None:
        return None
    new = params.new_name
    if not symbols.NAME.match(new) or new in symbols.KEYWORDS:
        raise Refusal(f"'{new}' is not a name: a letter or '_', then letters, digits, "
                      "'_' or '.' (not a keyword)")
    if any(u.defines and u.kind == use.kind and u.name == new for u in found):
        raise Refusal(f"a {use.kind} named '{new}' exists already")
    edits = [t.TextEdit(range=document.range_of(u.span), new_text=new) for u in found
             if (u.kind, u.name) == (use.kind, use.name)]
    return t.WorkspaceEdit(changes={params.text_document.uri: edits})


@server.feature(t.TEXT_DOCUMENT_DOCUMENT_SYMBOL)
def document_symbols(ls: MercmacServer, params: t.DocumentSymbolParams) -> list[t.DocumentSymbol]:
    """Macros (with their slots after lowering), the autostart block, raw blocks, consts;
    a block with a syntax error too, as far as it parses."""
    from mercmac.compiler import ast

    seen = ls.checked(params.text_document.uri)
    document: Document = ls.workspace.get_text_document(params.text_document.uri)
    program = seen.compilation.program
    found = {u.span.line: u for u in _uses(seen) if u.defines and u.kind != "slot"}
    out = []
    for item in seen.items:
        whole = document.range_of(item.span)
        pick = found.get(item.span.line)
        chosen = document.range_of(pick.span) if pick else whole
        if isinstance(item, (ast.MacroDef, ast.Autostart)):
            name = item.name if isinstance(item, ast.MacroDef) else "autostart"
            slots = symbols.slots_of(name, program) if program else []
            out.append(t.DocumentSymbol(
                name=name, kind=t.SymbolKind.Function, range=whole, selection_range=chosen,
                detail=", ".join(slot_name(m.slot) for m in slots),
                children=[t.DocumentSymbol(name=slot_name(m.slot), kind=t.SymbolKind.Field,
                                           range=whole, selection_range=whole, detail=m.line)
                          for m in slots]))
        elif isinstance(item, ast.RawBlock):
            out.append(t.DocumentSymbol(name=slot_name(item.slot), kind=t.SymbolKind.Function,
                                        range=whole, selection_range=whole, detail="raw block"))
        elif isinstance(item, ast.Const):
            out.append(t.DocumentSymbol(name=item.name, kind=t.SymbolKind.Constant,
                                        range=chosen, selection_range=chosen,
                                        detail=f"= {item.value}"))
    return out


@server.feature(t.TEXT_DOCUMENT_FORMATTING)
def formatting(ls: MercmacServer, params: t.DocumentFormattingParams) -> list[t.TextEdit] | None:
    """The whole document as `mercmac fmt` writes it (one edit), or no edit."""
    if rig.is_rig_path(params.text_document.uri):  # `fmt RIG` leaves the TOML as written
        return None
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
                t.CodeActionOptions(code_action_kinds=[t.CodeActionKind.QuickFix, ADD_TARGET]))
def code_actions(ls: MercmacServer, params: t.CodeActionParams) -> list[t.CodeAction]:
    """The fixes of the reported diagnostics in the range (the Fix data of each, as
    `check --fix` makes them); in a file without `target`, a source action that adds one."""
    uri = params.text_document.uri
    seen, document = ls.checked(uri), ls.workspace.get_text_document(uri)
    wanted = (document.spot(params.range.start), document.spot(params.range.end))
    out = []
    if _wanted(params.context.only, t.CodeActionKind.QuickFix):
        out += [t.CodeAction(title=fix_label(d.fix), kind=t.CodeActionKind.QuickFix,
                             diagnostics=[_diagnostic(d, document)],
                             is_preferred=d.fix.applicability is SAFE,
                             edit=_edit(uri, document, d.fix))
                for d in seen.diagnostics if d.fix is not None and _touches(d.span, *wanted)]
    if _wanted(params.context.only, ADD_TARGET) and not seen.rig:
        out += _add_target(uri, seen, document)
    return out


# What a quick fix's title adds for each applicability (docs/editors.md): a safe fix is
# preferred (the editor's "auto fix" takes it); the others say what they are.
_LABELS = {SAFE: "", UNSAFE: " (unsafe: a guess, check what it changes)",
           DISPLAY_ONLY: " (suggestion: check --fix never makes it)"}


def fix_label(fix: Fix) -> str:
    """The title the editor shows for a fix: 'Replace with 'WA' (unsafe: a guess, ...)'."""
    return fix.title + _LABELS[fix.applicability]


def _edit(uri: str, document: Document, fix: Fix) -> t.WorkspaceEdit:
    return t.WorkspaceEdit(changes={uri: [t.TextEdit(range=document.range_of(fix.span),
                                                     new_text=fix.replacement)]})


def _wanted(only: list[str] | None, kind: str) -> bool:
    """Whether the client asked for actions of `kind` (a kind covers its sub-kinds)."""
    return only is None or any(kind == k or kind.startswith(f"{k}.") for k in only)


def _touches(span: Span, start: tuple[int, int], end: tuple[int, int]) -> bool:
    """Whether `span` and the range from `start` to `end` (1-based) meet."""
    span_end = (span.end_line or span.line, span.end_column or span.column + 1)
    return not (span_end < start or (span.line, span.column) > end)


def _add_target(uri: str, seen: Seen, document: Document) -> list[t.CodeAction]:
    """`target C-863` / `target C-663` after the leading comments, when the file has none
    (mercmac.compiler.fixing.target_fix). No rule reports a missing target (the model
    checks just wait for one), so it is a source action, not a quick fix on every line."""
    from mercmac.compiler.fixing import target_fix

    text = seen.compilation.source.text
    fixes = [target_fix(text, model) for model in ("C-863", "C-663")]
    return [t.CodeAction(title=fix.title, kind=ADD_TARGET, edit=_edit(uri, document, fix))
            for fix in fixes if fix is not None]


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
        error = record.exc_info[1] if record.exc_info else None
        if isinstance(error, Refusal):  # answered to the client; nothing went wrong here
            return
        text = split_lines(record.getMessage())[0][:300]
        if error is not None:
            text += f": {type(error).__name__}: {error}"[:300]
        self.say(text)

