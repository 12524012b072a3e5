"""Workspace symbols: the macros and consts defined in the open `.mcm` documents and in
every program an open rig file names (read from disk when it is not open), where they are
defined; a query keeps the names that hold its letters in order, in any case (`scn` finds
`scan`, `SC` too).

A file from disk is read as far as it parses (symbols.partial_items), as the outline reads
an open file with syntax errors.
"""
from __future__ import annotations

import os
from typing import Callable, Iterable, NamedTuple

from lsprotocol import types as t
from pygls import uris

from mercmac.lsp import links, symbols
from mercmac.source import Source, Span, read_source

_KINDS = {"macro": t.SymbolKind.Function, "const": t.SymbolKind.Constant}


class Opened(NamedTuple):
    """A file whose symbols are listed: its URI, text and items (AST or partial)."""

    uri: str
    source: Source
    items: tuple


def wanted(query: str, name: str) -> bool:
    """Whether `name` holds the letters of `query` in order, in any case."""
    letters = iter(name.lower())
    return all(c in letters for c in query.lower())


def defined(opened: Opened, query: str) -> list[tuple[str, str, Span]]:
    """(kind, name, span) of each macro and const `opened` defines that the query wants."""
    return [(u.kind, u.name, u.span) for u in symbols.uses(opened.items, opened.source)
            if u.defines and u.kind in _KINDS and wanted(query, u.name)]


def rig_programs(rigs: Iterable[Source], skip: set[str]) -> list[Opened]:
    """The programs the rig files `rigs` name, read from disk, but those whose real path
    is in `skip` (open already) or that cannot be read; each once."""
    found = []
    for rig in rigs:
        for program in links.programs(rig):
            real = os.path.realpath(program.path)
            if real in skip:
                continue
            skip.add(real)
            try:
                source = read_source(program.path)
            except (OSError, ValueError):  # gone, unreadable or not text: nothing of it
                continue
            found.append(Opened(uris.from_fs_path(program.path), source,
                                symbols.partial_items(source.text)))
    return found


def workspace_symbols(files: list[Opened], query: str,
                      document_of: Callable[[Opened], object]) -> list[t.WorkspaceSymbol]:
    """The symbols of `files` that the query wants, at the positions `document_of(file)`
    (a mercmac.lsp.document.Document of its text) gives."""
    out = []
    for opened in files:
        found = defined(opened, query)
        document = document_of(opened) if found else None
        container = os.path.basename(opened.source.name) or opened.uri
        out += [t.WorkspaceSymbol(name=name, kind=_KINDS[kind], container_name=container,
                                  location=t.Location(uri=opened.uri,
                                                      range=document.range_of(span)))
                for kind, name, span in found]
    return out
