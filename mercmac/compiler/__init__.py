"""The compiler: .mcm text -> diagnostics and the lowered program (SPEC §1, §2).

    source --parse--> tree --build--> AST --check--> Env --lower--> Program --flow checks
"""
from __future__ import annotations

from typing import NamedTuple

from mercmac.compiler.program import Macro, Op, Program
from mercmac.diagnostics import Report
from mercmac.source import Source, read_source

__all__ = ["Compilation", "compile_file", "compile_source", "Macro", "Op", "Program"]


class Compilation(NamedTuple):
    """What compiling one file gives: its source, diagnostics and (if it parsed) program."""

    source: Source
    report: Report
    program: Program | None


def compile_source(source: Source, target: str | None = None) -> Compilation:
    """Compile text; `target` (from --target) overrides the file's `target` line."""
    from mercmac.compiler.ast_builder import build
    from mercmac.compiler.checks import check_module
    from mercmac.compiler.program_checks import check_program
    from mercmac.compiler.lower import lower
    from mercmac.compiler.parse import parse, paused_gc

    report = Report(source.name)
    tree = parse(source.text, report)
    if tree is None:
        return Compilation(source, report, None)
    module = build(tree)
    with paused_gc():  # a diagnostic per command of a 1 MB file makes no cycles either
        env = check_module(module, report, target.upper() if target else None)
    program = lower(module, env, report, source.name)
    check_program(program, report)
    return Compilation(source, report, program)


def compile_file(path: str, target: str | None = None) -> Compilation:
    """Read and compile a file; OSError propagates for the CLI to report (exit 2)."""
    return compile_source(read_source(path), target)
