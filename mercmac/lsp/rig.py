"""Rigs in the editor: a rig file (`*.rig.toml`) gets what `check RIG` reports
on it, at its positions in the rig file; a `.mcm` that a rig names as a program (a rig file
in its folder or above) is checked with that controller's model, a `target` line that
differs from it is reported as the rig rule model-mismatch (MR006) reports it, and it gets
the rig rules `check RIG` reports in a program (SC in macro 0, an input nothing drives),
from the editor's text.

A rig is opened as every command opens it (mercmac.rig.open: no second reader or checker
here); this module only finds the rig a document belongs to and picks what belongs to the
document.
"""
from __future__ import annotations

import os
from typing import Callable, NamedTuple

from mercmac.compiler import Compilation, ast
from mercmac.compiler.checking import Choice
from mercmac.diagnostics import RULES, Diagnostic, Report
from mercmac.rig import is_rig_path
from mercmac.rig.load import RigFile
from mercmac.rig.model import Controller, Rig
from mercmac.source import Source, Span, read_source

# How many folders up from a program its rig may stand: a rig holds its programs in its
# own folder or below (paths relative to the rig file), and a walk to the root of a deep
# tree would read every rig file on the way at each keystroke.
MAX_LEVELS = 8

__all__ = ["is_rig_path", "Owner", "owner_of", "rig_diagnostics", "with_rig_model",
           "program_rig_diagnostics"]
# the rig rules (MR001-...): the rules of the table that are not the compiler's own (MM)
RIG_CODES = frozenset(r.code for r in RULES if not r.code.startswith("MM"))


class Owner(NamedTuple):
    """The rig file that names a program, and the controller the program runs on."""

    rig_file: RigFile
    controller: Controller

    @property
    def rig(self) -> Rig:
        return self.rig_file.rig


def rig_diagnostics(source: Source, choice: Choice) -> list[Diagnostic]:
    """What `check RIG` reports in the rig file itself (`source`: the editor's text, its name
    its path), under `choice`: its own findings, and those of a program that is the rig file
    (the programs' own belong to their files). Where `check` cannot read the rig (too large,
    a failure reading it or a program), one diagnostic at 1:1 says why: never a clean rig."""
    from mercmac.rig.open import open_rig

    here = os.path.realpath(source.name)

    def read(path: str) -> Source:  # the rig named as a program: its text as in the editor
        return source if os.path.realpath(path) == here else read_source(path)

    try:
        found = open_rig(source.name, text=source.text, read=read).checked(choice)
    except Exception as e:  # what stops `check` (or a bug) is said where the editor shows it
        return [_unchecked(source, e)]
    return [d for f in found if os.path.realpath(f.compilation.source.name) == here
            for d in f.diagnostics]


def _unchecked(source: Source, e: Exception) -> Diagnostic:
    """Why the rig in `source` could not be checked, at 1:1: `check`'s words for a file it
    cannot read, else the error, as checking reports a compiler bug."""
    from mercmac.rig.open import RigUnreadable

    report = Report(source.name)
    if isinstance(e, RigUnreadable):
        report.add("rig-file", Span(1, 1), "unread", why=e.why)
    else:
        detail = f"{type(e).__name__}: {e}"
        report.add("rig-file", Span(1, 1), "internal",
                   detail=detail if len(detail) <= 200 else detail[:200] + "...")
    return report.items[0]


def owner_of(path: str, open_text: Callable[[str], str | None]) -> Owner | None:
    """The rig in `path`'s folder or above that names it as a program, nearest first;
    `open_text(rig_path)` is the editor's text of a rig file that is open (unsaved edits
    count), None for one read from disk."""
    program = os.path.realpath(path)
    for folder in _folders(os.path.dirname(program)):
        for rig_path in _rig_files(folder):
            rig_file = _rig_file(rig_path, open_text(rig_path))
            rig = rig_file.rig if rig_file else None
            found = rig and next((c for c in rig.controllers
                                  if os.path.realpath(c.program) == program), None)
            if found:
                return Owner(rig_file, found)
    return None


def _folders(start: str):
    folder = start
    for _ in range(MAX_LEVELS):
        yield folder
        parent = os.path.dirname(folder)
        if parent == folder:
            return
        folder = parent


def _rig_files(folder: str) -> list[str]:
    try:
        with os.scandir(folder) as entries:
            return sorted(e.path for e in entries if is_rig_path(e.name) and e.is_file())
    except OSError:  # a folder we may not read: no rig of ours there
        return []


def _rig_file(path: str, text: str | None) -> RigFile | None:
    """The rig file at `path` (from `text` when open); None when it cannot be read."""
    from mercmac.rig.open import RigUnreadable, open_rig

    try:
        return open_rig(path, text=text).rig_file
    except RigUnreadable:
        return None


def programs_of(path: str, text: str) -> tuple[list[str], str | None]:
    """The program files the rig at `path` (`text`: its editor text) names, as `fmt RIG`
    formats them, or why they cannot be known."""
    from mercmac.rig.open import RigUnreadable, open_rig

    try:
        rig_file = open_rig(path, text=text).rig_file
    except RigUnreadable as e:
        return [], e.message
    if rig_file.rig is None:
        return [], "the rig file has errors (its diagnostics say which)"
    return [c.program for c in rig_file.rig.controllers], None


def program_rig_diagnostics(owner: Owner, source: Source, choice: Choice) -> list[Diagnostic]:
    """What the rig rules of `check RIG` report in the program `source` (the editor's text
    of the owner's controller's program; the rig's other programs as saved)."""
    from mercmac.rig.open import Opened

    program = os.path.realpath(owner.controller.program)

    def read(path: str) -> Source:
        return source if os.path.realpath(path) == program else read_source(path)

    _, *programs = Opened(owner.rig_file, read=read).checked(choice)
    return [d for found in programs if found.compilation.source is source
            for d in found.diagnostics if d.rule.code in RIG_CODES]


def with_rig_model(compilation: Compilation, owner: Owner, items: tuple) -> Compilation:
    """`compilation` (made with the controller's model as target) with model-mismatch on
    each `target` line that names another model, as `check RIG` reports it on the rig."""
    controller = owner.controller
    wrong = [i for i in items if isinstance(i, ast.Target)
             and i.model.upper() != controller.model]
    if not wrong:
        return compilation
    report = Report(compilation.report.file, list(compilation.report.items))
    for item in wrong:
        report.add("model-mismatch", item.span, controller=controller.name,
                   model=controller.model, target=item.model)
    return compilation._replace(report=report)
