"""Compile a snippet of text as the checker and the lowering see it."""
from __future__ import annotations

from mercmac.compiler import compile_source
from mercmac.source import Source


def compile_text(text: str, target: str | None = None):
    """Compile a snippet as file 'test.mcm'."""
    return compile_source(Source("test.mcm", text), target)


def rules(text: str, target: str | None = None) -> list[str]:
    """The rule names a snippet triggers, in report order."""
    return [d.rule.name for d in compile_text(text, target).report.sorted()]


def program_of(text: str, target: str | None = None):
    """The lowered program of a snippet that must compile without errors."""
    result = compile_text(text, target)
    assert result.program is not None and not result.report.has_errors, \
        [d.message for d in result.report.items]
    return result.program
