"""Finding one's way in a program: hover, completion, definition, references, rename and
the outline, read off the document's check (mercmac.lsp.symbols, mercmac.lsp.completion)."""
from __future__ import annotations

from typing import TYPE_CHECKING

from lsprotocol import types as t

from mercmac.commands import MODELS, Mnemonic
from mercmac.lsp import completion as completion_rules, lowered, rig, symbols
from mercmac.lsp.document import Document
from mercmac.lsp.state import Features, Refusal, Seen, markdown, spot_of, uses_of
from mercmac.mdtext import slot_name
from mercmac.render import rules_page
from mercmac.source import Span

if TYPE_CHECKING:
    from mercmac.lsp.server import MercmacServer

features = Features()


@features.on(t.TEXT_DOCUMENT_HOVER)
def hover(ls: MercmacServer, params: t.HoverParams) -> t.Hover | None:
    """A mnemonic, a macro, const or slot (`[MCnn]`, `EMn`), a keyword, an `every`
    period; the explanation of each reported diagnostic under it."""
    document, seen, line, column = spot_of(ls, params)
    parts, spans = [], []
    for text, span in () if seen.rig else _meanings(seen, line, column):
        parts.append(text)
        spans.append(span)
    for d in seen.diagnostics:
        if symbols.inside(d.span, line, column):
            # the summary and where the long story is: the code links to it too
            parts.append(f"**{d.rule.code}** ({d.rule.name}): {d.rule.summary}. "
                         f"[The whole story]({rules_page.url(d.rule)}), also in a terminal: "
                         f"`mercmac explain {d.rule.code}`")
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
    use = symbols.use_at(uses_of(seen), line, column)
    command = symbols.command_at(items, line, column)
    if use is not None and use.kind == "slot":
        yield symbols.slot_help(use.slot, program), use.span
    elif use is not None:
        yield (symbols.macro_help(use.name, program, seen.errors > 0) if use.kind == "macro"
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


@features.on(t.TEXT_DOCUMENT_COMPLETION,
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
                                 documentation=markdown(symbols.KEYWORD_HELP[k]))
                for k in offer.keywords]
    if kind == "mnemonics":
        return [t.CompletionItem(label=m, kind=t.CompletionItemKind.Function, detail=hint,
                                 documentation=markdown(symbols.command_help(m)))
                for m, hint, _ in symbols.mnemonics()]
    if kind == "models":
        return [t.CompletionItem(label=m, kind=t.CompletionItemKind.EnumMember)
                for m in MODELS]
    if kind == "durations":
        return [t.CompletionItem(label=_duration(ms), kind=t.CompletionItemKind.Value,
                                 detail=f"{Mnemonic.WA}{ms}", documentation=markdown(
                                     symbols.duration_help(_duration(ms), ms)))
                for ms in completion_rules.DURATIONS]
    if kind == "macros":
        return [t.CompletionItem(label=m, kind=t.CompletionItemKind.Function, detail="macro")
                for m in macros]
    return [t.CompletionItem(label=name, kind=t.CompletionItemKind.Constant,
                             detail=f"const = {value}") for name, value in consts.items()]


def _duration(ms: int) -> str:
    return f"{ms // 1000}s" if ms % 1000 == 0 else f"{ms}ms"


def _same(ls: MercmacServer, params) -> tuple[str, Document, list[symbols.Use]]:
    """The document and every use of the name or slot under the cursor (none off one)."""
    document, seen, line, column = spot_of(ls, params)
    found = uses_of(seen)
    use = symbols.use_at(found, line, column)
    return params.text_document.uri, document, [] if use is None else symbols.same(found, use)


@features.on(t.TEXT_DOCUMENT_DEFINITION)
def definition(ls: MercmacServer, params: t.DefinitionParams) -> list[t.Location] | None:
    """Where a macro, const or slot is defined: `call scan` -> `macro scan`, `EM11` -> `[MC11]`."""
    uri, document, same = _same(ls, params)
    return [t.Location(uri=uri, range=document.range_of(u.span)) for u in same
            if u.defines] or None


@features.on(t.TEXT_DOCUMENT_REFERENCES)
def references(ls: MercmacServer, params: t.ReferenceParams) -> list[t.Location] | None:
    """Every use of a macro, const or slot: a slot's `EMn` and the calls of the macro there."""
    uri, document, same = _same(ls, params)
    declarations = params.context.include_declaration
    return [t.Location(uri=uri, range=document.range_of(u.span)) for u in same
            if declarations or not u.defines] or None


def _renamed(ls: MercmacServer, params) -> tuple[Document, list[symbols.Use], symbols.Use | None]:
    """The document, its uses, and the name (not slot) under the cursor."""
    document, seen, line, column = spot_of(ls, params)
    found = uses_of(seen)
    use = symbols.use_at(found, line, column)
    return document, found, None if use is None or use.kind == "slot" else use


@features.on(t.TEXT_DOCUMENT_PREPARE_RENAME)
def prepare_rename(ls: MercmacServer, params: t.PrepareRenameParams) -> t.Range | None:
    document, _, use = _renamed(ls, params)
    return None if use is None else document.range_of(use.span)


@features.on(t.TEXT_DOCUMENT_RENAME)
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


@features.on(t.TEXT_DOCUMENT_DOCUMENT_SYMBOL)
def document_symbols(ls: MercmacServer, params: t.DocumentSymbolParams) -> list[t.DocumentSymbol]:
    """Macros (with their slots after lowering), the autostart block, raw blocks, consts;
    a block with a syntax error too, as far as it parses."""
    from mercmac.compiler import ast

    seen = ls.checked(params.text_document.uri)
    document: Document = ls.workspace.get_text_document(params.text_document.uri)
    program = seen.compilation.program
    found = {u.span.line: u for u in uses_of(seen) if u.defines and u.kind != "slot"}
    out = []
    for item in seen.items:
        whole = document.range_of(item.span)
        pick = found.get(item.span.line)
        chosen = document.range_of(pick.span) if pick else whole
        if isinstance(item, (ast.MacroDef, ast.Autostart)):
            name = item.name if isinstance(item, ast.MacroDef) else "autostart"
            slots = lowered.of_macro(name, program) if program else []
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
