"""`mercmac lsp`: the language server over stdio (pygls; the optional extra `lsp`).

Every open document is re-checked on open and on each change, and what it publishes is
what `mercmac check` reports: the same function (mercmac.compiler.checking) with the
same settings files, `// mercmac: ignore` comments and, as check's options, the
editor's workspace settings (mercmac.lsp.settings); only the compiling is incremental
(mercmac.lsp.recheck). The features read that check's AST and lowered program; they
live in mercmac.lsp.navigate (hover, completion, names), mercmac.lsp.edits (formatting,
fixes) and mercmac.lsp.views (tokens, folding, hints, lenses, links), each registered here,
with what they share in mercmac.lsp.state. Documents keep the editor's lines and
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
from mercmac.compiler import Compilation, checking
from mercmac.diagnostics import Diagnostic, Report
from mercmac.errors import MercmacError, SettingsError
from mercmac.lsp import edits, framing, navigate, rig, settings, symbols, views
from mercmac.lsp.document import Document, Documents
from mercmac.lsp.recheck import Checked, Rechecker
from mercmac.lsp.state import Refusal, Seen, lsp_diagnostics, name_of, path_of
from mercmac.source import Source, split_lines

SETTINGS_FILES = ("mercmac.toml", "pyproject.toml")  # mercmac.config reads these
# How long checks wait for the client's answer to workspace/configuration: editors answer
# at once; one that never does must not keep a file from being checked.
SETTINGS_WAIT_S = 5.0


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
        source = Source(name_of(uri), document.source)
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
            diagnostics=lsp_diagnostics(found.diagnostics, document)))
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
        source = Source(path_of(uri), document.source)  # its programs are relative to it
        found = rig.rig_diagnostics(source, self.choice(uri))  # a failure: said at 1:1
        seen = self.checks[uri] = Seen(Checked(Compilation(source, Report(source.name), None),
                                               None, ()), found, rig=True)
        self.text_document_publish_diagnostics(t.PublishDiagnosticsParams(
            uri=uri, version=document.version, diagnostics=lsp_diagnostics(found, document)))
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
            self.say(f"finding the rig of {name_of(uri)}: {type(e).__name__}: {e}"[:300])
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


for _features in (navigate.features, edits.features, views.features):
    _features.register(server)


def main(say: Callable[[str], None]) -> None:
    """Serve over stdio; `say` tells stderr (the editor's log) what went wrong, one line
    each: pygls logs whole tracebacks, and the log wants the cause."""
    def tell(message: str) -> None:
        say(f"language server: {message}")

    server.say = tell
    logging.getLogger().addHandler(_Said(tell))
    server.start_io()


# pygls's warning when the client cancels a request already answered: editors do it all
# the time (a hover the cursor left), and nothing went wrong.
_ANSWERED_CANCEL = 'Cancel notification for unknown message id "%s"'


class _Said(logging.Handler):
    """pygls's and asyncio's warnings and errors, one line each through `say`."""

    def __init__(self, say: Callable[[str], None]):
        super().__init__(logging.WARNING)
        self.say = say

    def emit(self, record: logging.LogRecord) -> None:
        error = record.exc_info[1] if record.exc_info else None
        if isinstance(error, Refusal) or record.msg == _ANSWERED_CANCEL:
            return  # answered to the client; nothing went wrong here
        text = split_lines(record.getMessage())[0][:300]
        if error is not None:
            text += f": {type(error).__name__}: {error}"[:300]
        self.say(text)

