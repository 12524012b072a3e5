"""The compiler: .mcm text -> diagnostics and the lowered program
(docs/language.md, docs/checks.md).

    source --parse--> tree --build--> AST --check--> Env --lower--> Program --flow checks
"""
from __future__ import annotations

import re
from typing import NamedTuple

from mercmac.compiler.program import Macro, Program
from mercmac.ops import Op
from mercmac.diagnostics import Report
from mercmac.source import Source, read_source

_WORD = re.compile(r"[A-Za-z_][A-Za-z0-9_.]*")

__all__ = ["Compilation", "compile_file", "compile_source", "Macro", "Op", "Program"]


class Compilation(NamedTuple):
    """What compiling one file gives: its source, diagnostics and (if it parsed) program."""

    source: Source
    report: Report
    program: Program | None


def compile_source(source: Source, target: str | None = None) -> Compilation:
    """Compile text; `target` (from --target) overrides the file's `target` line."""
    from mercmac.compiler.ast_builder import parse_module
    from mercmac.compiler.checks import check_module
    from mercmac.compiler.program_checks import check_program
    from mercmac.compiler.lower import lower
    from mercmac.compiler.parse import paused_gc
    from mercmac.suppress import expected_hazards

    report = Report(source.name)
    parsed = parse_module(source.text, report)
    if parsed.tree is None:
        return Compilation(source, report, None)
    module = parsed.tree
    model = target.upper() if target else None
    if parsed.failed:
        _check_partial(source, module, parsed.broken, report, model)
        return Compilation(source, report, None)  # nothing with errors is lowered
    with paused_gc():  # a diagnostic per command of a 1 MB file makes no cycles either
        env = check_module(module, report, model)
    program = lower(module, env, report, source.name)
    check_program(program, report)
    program.expected = expected_hazards(source)
    return Compilation(source, report, program)


def _check_partial(source: Source, module, broken: frozenset[int], report: Report,
                   target: str | None) -> None:
    """The checks of a file with broken lines: every line that parsed is checked
    as in a whole file, so that one line being typed hides nothing on the others.

    - What a broken line held up to its error is not checked: its diagnostics are the
      parser's (a line is reported once).
    - A name written on a broken line is not reported as undefined anywhere: that line may
      be its definition (`macor scan {`). Other undefined names are reported, with their
      nearest defined name.
    - The checks of the lowered program (nested-call, undefined-macro, unreachable-macro,
      too-many-commands, ...) describe the whole program's calls and macros, which a missing
      line changes (a broken `call x` would make x "unreachable"): they wait until the file
      parses. Nothing is lowered, so nothing with errors is built, simulated or uploaded.
    """
    from mercmac.compiler.checks import check_module
    from mercmac.compiler.parse import paused_gc

    unsure: set[str] = set()
    for line in broken:
        unsure.update(_WORD.findall(source.line(line).split("//", 1)[0]))
    found = Report(report.file)
    with paused_gc():
        check_module(module, found, target, frozenset(unsure))
    report.items.extend(d for d in found.items if d.span.line not in broken)


def compile_file(path: str, target: str | None = None) -> Compilation:
    """Read and compile a file; an unreadable one is an InputError (exit 2), worded as
    `check` words it: "cannot read FILE: reason"."""
    from mercmac.errors import InputError
    from mercmac.names import printable
    from mercmac.outfile import reason

    try:
        source = read_source(path)
    except OSError as e:
        raise InputError(f"cannot read {printable(path)}: {reason(e)}") from None
    return compile_source(source, target)
