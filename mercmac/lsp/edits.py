"""What changes a document: formatting (a program, or a rig's programs as `fmt RIG`
formats them) and the code actions (every fix `check` knows, and adding a `target`)."""
from __future__ import annotations

import os
from typing import TYPE_CHECKING

from lsprotocol import types as t
from pygls import uris
from pygls.capabilities import get_capability

from mercmac.diagnostics import DISPLAY_ONLY, SAFE, UNSAFE, Fix
from mercmac.lsp import rig
from mercmac.lsp.document import Document
from mercmac.lsp.state import Features, Seen, lsp_diagnostic, name_of, path_of
from mercmac.source import Span

if TYPE_CHECKING:
    from mercmac.lsp.server import MercmacServer

features = Features()


ADD_TARGET = f"{t.CodeActionKind.Source.value}.addTarget"


@features.on(t.TEXT_DOCUMENT_FORMATTING)
def formatting(ls: MercmacServer, params: t.DocumentFormattingParams) -> list[t.TextEdit] | None:
    """The whole document as `mercmac fmt` writes it (one edit), or no edit; for a rig
    file, its programs (as `fmt RIG`), the TOML left as written."""
    document: Document = ls.workspace.get_text_document(params.text_document.uri)
    if rig.is_rig_path(params.text_document.uri):
        format_rig_programs(ls, params.text_document.uri, document)
        return []
    format_text = formatter()
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


def format_rig_programs(ls: MercmacServer, uri: str, document: Document) -> None:
    """Format the programs the rig names, as `mercmac fmt RIG` does, through one workspace
    edit (the editor's text of an open one, else the file's); say what was done or why not."""
    paths, problem = rig.programs_of(path_of(uri), document.source)
    if problem is None and not get_capability(ls.client_capabilities,
                                              "workspace.apply_edit", False):
        problem = "this editor cannot apply edits to other files (workspace/applyEdit)"
    if problem is not None:
        ls.window_show_message(t.ShowMessageParams(
            type=t.MessageType.Warning,
            message=f"mercmac: cannot format the programs of {name_of(uri)}: {problem}"))
        return
    changes, said = {}, []
    for path in dict.fromkeys(os.path.realpath(p) for p in paths):
        program = uris.from_fs_path(path)
        edit, note = _formatted(ls, program, path)
        if edit is not None:
            changes[program] = [edit]
        said.append(note)
    if changes:
        ls.workspace_apply_edit(t.ApplyWorkspaceEditParams(
            edit=t.WorkspaceEdit(changes=changes), label=f"Format the programs of {name_of(uri)}"))
    ls.window_show_message(t.ShowMessageParams(
        type=t.MessageType.Info, message=f"mercmac: {name_of(uri)}: {'; '.join(said)} "
                                         "(the rig file itself is left as written)"))


def _formatted(ls: MercmacServer, uri: str, path: str) -> tuple[t.TextEdit | None, str]:
    """The edit that formats one program (None when there is none), and what to say of it."""
    from mercmac.fmt import FormatError, load
    from mercmac.source import read_bytes

    name = os.path.basename(path)
    document = ls.workspace.text_documents.get(uri)
    try:
        text = document.source if document else load(read_bytes(path))[0]
        formatted = formatter()(text)
    except FormatError as e:
        return None, f"{name} left as written: {e.message}"
    except (OSError, UnicodeDecodeError) as e:
        return None, f"{name} left as written: cannot read it ({type(e).__name__}: {e})"
    if formatted == text:
        return None, f"{name} is formatted already"
    whole = document or ls.workspace.unopened(uri, text)
    return t.TextEdit(range=t.Range(t.Position(0, 0), whole.end()), new_text=formatted), \
        f"{name} formatted"


@features.on(t.TEXT_DOCUMENT_CODE_ACTION,
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
                             diagnostics=[lsp_diagnostic(d, document)],
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
