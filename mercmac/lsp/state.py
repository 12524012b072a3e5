"""What the server keeps of each document and what every feature of it uses: the check
of a document (Seen), the position a request is at, a document's name and path, and the
diagnostics as the editor gets them. Features live in mercmac.lsp.navigate, .edits and
.views; each module lists its handlers (`features`), which mercmac.lsp.server registers.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Callable

from lsprotocol import types as t
from pygls import uris
from pygls.exceptions import JsonRpcException

from mercmac.compiler import Compilation
from mercmac.diagnostics import Diagnostic, Severity
from mercmac.lsp import symbols
from mercmac.lsp.document import Document
from mercmac.lsp.recheck import Checked
from mercmac.render import rules_page
from mercmac.render.report import capped

if TYPE_CHECKING:
    from mercmac.lsp.server import MercmacServer


class Features:
    """The handlers of one module, with the LSP method and options of each: registered on
    the server by mercmac.lsp.server (pygls's `feature`), so that features live in modules
    of their own without importing the server."""

    def __init__(self):
        self.handlers: list[tuple[str, object, Callable]] = []

    def on(self, method: str, options=None) -> Callable[[Callable], Callable]:
        def add(handler: Callable) -> Callable:
            self.handlers.append((method, options, handler))
            return handler
        return add

    def register(self, server) -> None:
        for method, options, handler in self.handlers:
            server.feature(method, options)(handler)


_SEVERITY = {Severity.ERROR: t.DiagnosticSeverity.Error,
             Severity.WARNING: t.DiagnosticSeverity.Warning,
             Severity.INFO: t.DiagnosticSeverity.Information}


# Diagnostics sent per document: an editor lists them all, and past a thousand it slows
# down (a 2.5 MB file gave 288,000 of 700 bytes each) while no one reads them.
MAX_DIAGNOSTICS = 1000


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
    def errors(self) -> int:
        """How many errors `check` reports: with one, `build` writes nothing."""
        return sum(d.severity is Severity.ERROR for d in self.diagnostics)

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


def name_of(uri: str) -> str:
    return uri.rsplit("/", 1)[-1] or uri


def path_of(uri: str) -> str:
    """The file's path for a `file:` URI, else its name."""
    return (uris.to_fs_path(uri) or name_of(uri)) if uri.startswith("file:") else name_of(uri)


def lsp_diagnostics(found: list[Diagnostic], document: Document) -> list[t.Diagnostic]:
    """The first MAX_DIAGNOSTICS of `found` as `check` orders them, and how many more."""
    shown, left_out = capped(found, MAX_DIAGNOSTICS)
    out = [lsp_diagnostic(d, document) for d in shown]
    for count in left_out.values():
        out.append(t.Diagnostic(
            range=t.Range(t.Position(0, 0), t.Position(0, 0)), source="mercmac",
            severity=t.DiagnosticSeverity.Information,
            message=f"{count:,} more diagnostics not shown (the first {MAX_DIAGNOSTICS:,} "
                    "are); `mercmac check --max-diagnostics 0` lists them all"))
    return out


def lsp_diagnostic(d: Diagnostic, document: Document) -> t.Diagnostic:
    """A diagnostic whose code is the rule's, linked to the rule's `mercmac explain` text
    (docs/rules.md); `data` carries that text too."""
    return t.Diagnostic(
        range=document.range_of(d.span), message=d.message, severity=_SEVERITY[d.severity],
        code=d.rule.code, source="mercmac",
        code_description=t.CodeDescription(href=rules_page.url(d.rule)),
        data={"rule": d.rule.name, "explain": f"{d.rule.code} {d.rule.name}: {d.rule.summary}\n\n"
                                              f"{d.rule.explanation}"})


def spot_of(ls: MercmacServer, params) -> tuple[Document, Seen, int, int]:
    """The document, its check, and the 1-based line and column of the request's position."""
    uri = params.text_document.uri
    seen = ls.checked(uri)
    document: Document = ls.workspace.get_text_document(uri)
    return (document, seen, *document.spot(params.position))


def uses_of(seen: Seen) -> list[symbols.Use]:
    if seen.rig:  # a rig file names no macros or consts
        return []
    return symbols.uses(seen.items, seen.compilation.source, seen.compilation.program)


def markdown(text: str | None) -> t.MarkupContent | None:
    return None if text is None else t.MarkupContent(kind=t.MarkupKind.Markdown, value=text)
