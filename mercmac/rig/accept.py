"""The one way into a rig for the commands that run it (`sim`, `describe`, `emulate --rig`,
`flash`; docs/rigs.md): the rig file read, checked exactly as `check RIG` checks it, and refused
with `check`'s findings when it has errors, as `sim FILE` refuses a file with errors.

    path --read--> RigFile --check_rig (the file's settings)--> findings
         --no errors--> Accepted(rig, each program compiled with its controller's model)
         --errors-----> RigRefused(findings): each command shows them as `check` does, exit 1

`read` alone is for `fmt`, which formats the programs of a rig and runs nothing.
"""
from __future__ import annotations

from typing import NamedTuple

from mercmac.compiler import Compilation, checking
from mercmac.compiler.checking import Findings
from mercmac.diagnostics import Severity
from mercmac.errors import InputError, MercmacError
from mercmac.rig.load import RigFile, read_rig
from mercmac.rig.model import Rig


class Accepted(NamedTuple):
    """A rig `check` finds no errors in, and each controller's program by its name (a
    Compilation made with the controller's model: the one `check` made)."""

    rig: Rig
    programs: dict[str, Compilation]
    findings: list[Findings]  # what `check` reports: its warnings and infos


class RigRefused(MercmacError):
    """The rig has errors, `findings` say which (the rig file's first, then each program's,
    as `check` reports them); nothing may run. Exit 1, as `sim FILE` with errors."""

    def __init__(self, path: str, findings: list[Findings]):
        from mercmac.names import printable

        super().__init__(f"{printable(path)} has errors",
                         hint=f"`mercmac check {printable(path)}` lists them")
        self.path, self.findings = path, findings


class ProgramsUnread(RigRefused, InputError):
    """A program of the rig cannot be read (MR002): an I/O problem, exit 2 in every command
    that takes the rig, as an unreadable file is (rig.checks.unreadable_programs)."""

    def __init__(self, path: str, findings: list[Findings]):
        from mercmac.names import printable

        super().__init__(path, findings)
        self.message = f"a program of {printable(path)} cannot be read"


def read(path: str) -> RigFile:
    """The rig file at `path` as read (its own diagnostics in it); InputError (exit 2), worded
    as `check` words it, when it cannot be read."""
    from mercmac.outfile import reason
    from mercmac.names import printable

    try:
        return read_rig(path)
    except OSError as e:
        raise InputError(f"cannot read {printable(path)}: {reason(e)}") from None


def accept(path: str, chosen: checking.Options = checking.Options()) -> Accepted:
    """The rig at `path` and its compiled programs, checked as `check RIG` checks it (its
    settings files apply, laid under `chosen`); RigRefused when that finds errors."""
    from mercmac.rig.checks import check_rig, unreadable_programs

    rig_file = read(path)
    findings = check_rig(rig_file, checking.choice_for(path, chosen))
    programs = findings[1:]  # in the rig's order, one per program that could be read
    rig = rig_file.rig
    runs = (rig is not None and len(programs) == len(rig.controllers)
            and all(_runs(f.compilation) for f in programs))
    if unreadable_programs(findings):
        raise ProgramsUnread(path, findings)
    if _errors(findings) or not runs:
        raise RigRefused(path, findings if _errors(findings) else _unsuppressed(findings))
    return Accepted(rig, {c.name: f.compilation for c, f in zip(rig.controllers, programs)},
                    findings)


def _errors(findings: list[Findings]) -> bool:
    return any(d.severity is Severity.ERROR for f in findings for d in f.diagnostics)


def _runs(compilation: Compilation) -> bool:
    return compilation.program is not None and not compilation.report.has_errors


def _unsuppressed(findings: list[Findings]) -> list[Findings]:
    """Every finding, also those the settings or comments leave out: an error turned off
    there still stops a run (`sim FILE` reads no settings), and must be shown to say why."""
    return [Findings(f.compilation, list(f.compilation.report.items)) for f in findings]
