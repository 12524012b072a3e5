"""Shared test helpers: compile text, find the examples."""
from __future__ import annotations

from pathlib import Path

import pytest

from mercmac.compiler import compile_source
from mercmac.source import Source

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples" / "macros"


def compile_text(text: str, target: str | None = None):
    """Compile a snippet as file 'test.mcm'."""
    return compile_source(Source("test.mcm", text), target)


def rules(text: str, target: str | None = None) -> list[str]:
    """The rule names a snippet triggers, in report order."""
    return [d.rule.name for d in compile_text(text, target).report.sorted()]


@pytest.fixture
def examples_dir() -> Path:
    return EXAMPLES
