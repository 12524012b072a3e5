"""Views of a document that answer no question but show what it is: semantic tokens,
folding, signature help, a rig file's links to its programs, workspace symbols, and what
the controller will hold (inlay hints and "build" lenses, mercmac.lsp.lowered)."""
from __future__ import annotations

import os
from typing import TYPE_CHECKING

from lsprotocol import types as t
from pygls import uris

from mercmac.lsp import folding, links, lowered, rig, signature, tokens, workspace_symbols
from mercmac.lsp.document import Document
from mercmac.lsp.state import Features, markdown, name_of, path_of
from mercmac.source import Source

if TYPE_CHECKING:
    from mercmac.lsp.server import MercmacServer

features = Features()


@features.on(t.TEXT_DOCUMENT_SEMANTIC_TOKENS_FULL, tokens.LEGEND)
def semantic_tokens(ls: MercmacServer, params: t.SemanticTokensParams) -> t.SemanticTokens | None:
    """What each name, slot, mnemonic and number is (mercmac.lsp.tokens); none in a rig file."""
    uri = params.text_document.uri
    if rig.is_rig_path(uri):
        return None
    seen, document = ls.checked(uri), ls.workspace.get_text_document(uri)
    try:
        return t.SemanticTokens(data=tokens.encode(
            tokens.tokens(seen.items, seen.compilation.source), document))
    except Exception as e:  # a bug here must cost the colours, not the editor a failed request
        ls.say(f"semantic tokens of {name_of(uri)}: {type(e).__name__}: {e}"[:300])
        return t.SemanticTokens(data=[])


@features.on(t.TEXT_DOCUMENT_FOLDING_RANGE)
def folding_ranges(ls: MercmacServer, params: t.FoldingRangeParams) -> list[t.FoldingRange]:
    """Multi-line blocks and runs of `//` lines (mercmac.lsp.folding); none in a rig file."""
    uri = params.text_document.uri
    if rig.is_rig_path(uri):
        return []
    seen = ls.checked(uri)
    return [t.FoldingRange(start_line=f.start, end_line=f.end,
                           kind=t.FoldingRangeKind.Comment if f.comment else None)
            for f in folding.folds(seen.items, seen.compilation.source.text)]


@features.on(t.TEXT_DOCUMENT_SIGNATURE_HELP,
             t.SignatureHelpOptions(trigger_characters=[" ", ","]))
def signature_help(ls: MercmacServer, params: t.SignatureHelpParams) -> t.SignatureHelp | None:
    """The command whose argument is typed, for the file's model (mercmac.lsp.signature)."""
    uri = params.text_document.uri
    if rig.is_rig_path(uri):
        return None
    document: Document = ls.workspace.get_text_document(uri)
    offset = document.offset_at(params.position)
    text = document.source
    start = max(text.rfind("\n", 0, offset), text.rfind("\r", 0, offset)) + 1
    command = signature.command_typed(text[start:offset])
    if command is None:
        return None
    checker = ls.checkers.get(uri)
    model = signature.model_of(checker and checker.target, ls.checked(uri).items)
    said = signature.signature(command, model)
    return t.SignatureHelp(active_signature=0, active_parameter=0, signatures=[
        t.SignatureInformation(label=said.label, documentation=markdown(said.documentation),
                               parameters=[t.ParameterInformation(
                                   label=said.parameter, documentation=markdown(said.argument))])])


@features.on(t.TEXT_DOCUMENT_DOCUMENT_LINK)
def document_links(ls: MercmacServer, params: t.DocumentLinkParams) -> list[t.DocumentLink]:
    """In a rig file, each controller's `program` to its file (mercmac.lsp.links)."""
    uri = params.text_document.uri
    if not (rig.is_rig_path(uri) and uri.startswith("file:")):
        return []
    document: Document = ls.workspace.get_text_document(uri)
    return [t.DocumentLink(range=document.range_of(p.span), target=uris.from_fs_path(p.path),
                           tooltip=f"the program of controller {p.controller}")
            for p in links.programs(Source(path_of(uri), document.source))]


@features.on(t.WORKSPACE_SYMBOL)
def workspace_symbol(ls: MercmacServer, params: t.WorkspaceSymbolParams) -> list[t.WorkspaceSymbol]:
    """The macros and consts of the open programs and of the programs open rigs name."""
    opened, rigs = [], []
    for uri, document in list(ls.workspace.text_documents.items()):
        if rig.is_rig_path(uri):
            rigs += [Source(path_of(uri), document.source)] if uri.startswith("file:") else []
        else:
            seen = ls.checked(uri)
            opened.append(workspace_symbols.Opened(uri, seen.compilation.source, seen.items))
    skip = {os.path.realpath(uris.to_fs_path(o.uri)) for o in opened if o.uri.startswith("file:")}
    files = opened + workspace_symbols.rig_programs(rigs, skip)

    def document_of(file: workspace_symbols.Opened) -> Document:
        return (ls.workspace.text_documents.get(file.uri)
                or ls.workspace.unopened(file.uri, file.source.text))

    return workspace_symbols.workspace_symbols(files, params.query, document_of)


@features.on(t.TEXT_DOCUMENT_INLAY_HINT, t.InlayHintOptions(resolve_provider=False))
def inlay_hints(ls: MercmacServer, params: t.InlayHintParams) -> list[t.InlayHint]:
    """What the controller will hold (mercmac.lsp.lowered): the slot budget on the first
    line, the slot(s) of each macro header and of each block lowering hoists."""
    uri = params.text_document.uri
    seen = ls.checked(uri)
    if seen.rig:
        return []
    document: Document = ls.workspace.get_text_document(uri)
    first, last = params.range.start.line + 1, params.range.end.line + 1
    return [t.InlayHint(position=document.position(h.line, h.column), label=h.label,
                        kind=t.InlayHintKind.Type, padding_left=True,
                        tooltip=t.MarkupContent(kind=t.MarkupKind.Markdown, value=h.tooltip))
            for h in lowered.hints(seen.items, seen.compilation.program,
                                   seen.compilation.source.line)
            if first <= h.line <= last]


@features.on(t.TEXT_DOCUMENT_CODE_LENS, t.CodeLensOptions(resolve_provider=False))
def code_lenses(ls: MercmacServer, params: t.CodeLensParams) -> list[t.CodeLens]:
    """A "build" lens on each block: its MD lines as `mercmac build` writes them, which
    the client's `mercmac.copyBuild` copies; and a "simulate" lens on `autostart`, which
    the client's `mercmac.simulate` opens beside the editor (docs/editors.md, The language
    server)."""
    uri = params.text_document.uri
    seen = ls.checked(uri)
    if seen.rig:
        return []
    document: Document = ls.workspace.get_text_document(uri)

    def at(line: int) -> t.Range:
        return t.Range(document.position(line, 1), document.position(line, 1))

    # a lens with no lines to copy is a label: an empty command, which editors show unclickable
    found = [t.CodeLens(range=at(lens.line),
                        command=t.Command(title=lens.title,
                                          command=lowered.COPY_BUILD if lens.lines else "",
                                          arguments=[{"macro": lens.macro,
                                                      "lines": list(lens.lines)}]))
             for lens in lowered.lenses(seen.items, seen.compilation.program, seen.errors)]
    run = lowered.simulate(seen.items, seen.errors)
    if run is not None:
        found.insert(0, t.CodeLens(range=at(run.line), command=t.Command(
            title=run.title, command="" if seen.errors else lowered.SIMULATE,
            arguments=[{"uri": uri}])))
    return found
