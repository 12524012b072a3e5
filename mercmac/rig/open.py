"""Opening a rig: the one way every command reads, locates, checks and words the errors of
a rig file (`check`, `sim`, `describe`, `fmt`, `flash`, `emulate --rig`, `pull --rig` and the
language server; docs/rigs.md), and the one way a lone program becomes a rig of one.

    RIG --read (RigUnreadable: exit 2)--> RigFile (the rig, its own findings, its places)
        --check_rig under the file's settings, when first asked for--> findings
        --accepted()--> Accepted(rig, each program compiled with its controller's model)
                   or RigRefused (exit 1; ProgramsUnread: exit 2) with check's findings
    FILE.mcm --compile for --target/`target`--> a rig of one controller (Rig.of_program)

Each command shows a refusal's findings as `check` shows them (render.report.write_findings)
and decides only what its exit code is.
"""
from __future__ import annotations

from functools import cached_property
from typing import Callable, NamedTuple

from mercmac.compiler import Compilation, checking
from mercmac.compiler.checking import Findings
from mercmac.diagnostics import Severity
from mercmac.errors import InputError, MercmacError
from mercmac.rig import is_rig_path
from mercmac.rig.load import RigFile, parse_rig, read_rig
from mercmac.rig.model import Rig
from mercmac.source import Source, read_source, refuse_larger

Reader = Callable[[str], Source]  # a program's source by its path (the editor's text, or disk)


class Accepted(NamedTuple):
    """A rig `check` finds no errors in, and each controller's program by its name (a
    Compilation made with the controller's model: the one `check` made)."""

    rig: Rig
    programs: dict[str, Compilation]
    findings: list[Findings]  # what `check` reports: its warnings and infos


class RigUnreadable(InputError):
    """The rig file cannot be read at all (exit 2), worded as `check` words a file it
    cannot read; `why` is the reason alone."""

    def __init__(self, path: str, why: str):
        from mercmac.names import printable

        super().__init__(f"cannot read {printable(path)}: {why}")
        self.why = why


class RigRefused(MercmacError):
    """The rig has errors, `findings` say which (the rig file's first, then each program's,
    as `check` reports them); nothing may run. Exit 1, as `sim FILE` with errors."""

    def __init__(self, path: str, findings: list[Findings], message: str = ""):
        from mercmac.names import printable

        super().__init__(message or f"{printable(path)} has errors",
                         hint=f"`mercmac check {printable(path)}` lists them")
        self.path, self.findings = path, findings


class ProgramsUnread(RigRefused, InputError):
    """A program of the rig cannot be read (MR002): an I/O problem, exit 2 in every command
    that takes the rig, as an unreadable file is."""

    def __init__(self, path: str, findings: list[Findings]):
        from mercmac.names import printable

        super().__init__(path, findings, f"a program of {printable(path)} cannot be read")


class Opened:
    """A rig file as read, and what `check` reports on it once asked (`findings`)."""

    def __init__(self, rig_file: RigFile, chosen: checking.Options = checking.Options(),
                 read: Reader = read_source):
        self.rig_file, self._chosen, self._read = rig_file, chosen, read

    @property
    def path(self) -> str:
        return self.rig_file.source.name

    @property
    def rig(self) -> Rig | None:
        """The rig, None when the rig file itself has errors (its findings say which)."""
        return self.rig_file.rig

    @cached_property
    def findings(self) -> list[Findings]:
        """What `check RIG` reports: the rig file's findings first, then each readable
        program's, under the settings found from the rig file and the chosen options."""
        return self.checked(checking.choice_for(self.path, self._chosen))

    def checked(self, choice: checking.Choice) -> list[Findings]:
        """What `check` reports under `choice` (the language server's: an editor's settings)."""
        from mercmac.rig.checks import check_rig

        return check_rig(self.rig_file, choice, self._read)

    @property
    def unread(self) -> int:
        """How many programs could not be read (MR002): each makes the exit code 2."""
        return sum(d.rule.name == "rig-program" for f in self.findings for d in f.diagnostics)

    def accepted(self) -> Accepted:
        """The rig and its compiled programs; RigRefused (ProgramsUnread when a program
        cannot be read) when `check` finds errors."""
        findings, rig = self.findings, self.rig
        programs = findings[1:]  # in the rig's order, one per program that could be read
        runs = (rig is not None and len(programs) == len(rig.controllers)
                and all(_runs(f.compilation) for f in programs))
        if self.unread:
            raise ProgramsUnread(self.path, findings)
        if _errors(findings) or not runs:
            raise RigRefused(self.path, findings if _errors(findings) else _unsuppressed(findings))
        return Accepted(rig, {c.name: f.compilation for c, f in zip(rig.controllers, programs)},
                        findings)


def open_rig(path: str, chosen: checking.Options = checking.Options(), *,
             text: str | None = None, read: Reader = read_source) -> Opened:
    """The rig file at `path` (or `text`, an editor's unsaved text of it), read and located;
    RigUnreadable (exit 2) when it cannot be read. `read(path)` reads a program (the language
    server passes the editor's text)."""
    from mercmac.outfile import reason

    try:
        if text is None:
            rig_file = read_rig(path)
        else:
            refuse_larger(path, text)  # as `check` caps a file it reads
            rig_file = parse_rig(Source(path, text))
    except OSError as e:
        raise RigUnreadable(path, reason(e)) from None
    return Opened(rig_file, chosen, read)


def accept(path: str, chosen: checking.Options = checking.Options()) -> Accepted:
    """The rig at `path` as the commands that run it take it: open_rig, then accepted()."""
    return open_rig(path, chosen).accepted()


def open_program(path: str, *, target: str | None = None) -> Accepted:
    """A lone program as a rig of one controller (docs/rigs.md, "A program is a rig of
    one"): compiled for `target` (else its own `target` line), with the box and the
    joystick on it. RigRefused with its findings when it has errors; InputError (exit 2)
    when it cannot be read."""
    from mercmac.compiler import compile_file

    compiled = compile_file(path, target=target)
    findings = [Findings(compiled, list(compiled.report.items))]
    if not _runs(compiled):
        raise RigRefused(path, findings)
    rig = Rig.of_program(path, target or compiled.program.target)
    return Accepted(rig, {rig.controllers[0].name: compiled}, findings)


def open_any(path: str, *, target: str | None = None) -> Accepted:
    """A rig file accepted, or a lone program as a rig of one (open_program)."""
    if is_rig_path(path):
        return accept(path)
    return open_program(path, target=target)


def _errors(findings: list[Findings]) -> bool:
    return any(d.severity is Severity.ERROR for f in findings for d in f.diagnostics)


def _runs(compilation: Compilation) -> bool:
    return compilation.program is not None and not compilation.report.has_errors


def _unsuppressed(findings: list[Findings]) -> list[Findings]:
    """Every finding, also those the settings or comments leave out: an error turned off
    there still stops a run (`sim FILE` reads no settings), and must be shown to say why."""
    return [Findings(f.compilation, list(f.compilation.report.items)) for f in findings]
