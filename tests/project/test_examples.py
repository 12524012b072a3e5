"""Every example states its expected diagnostics in `// expect:` comments; check them all."""
from __future__ import annotations

import re
from collections import Counter

import pytest

from helpers.paths import EXAMPLE_FILES
from mercmac.compiler import compile_file

_EXPECT = re.compile(r"//\s*expect:\s*(.+)$")


def expectations(path) -> Counter:
    """(line, rule) -> count, from `// expect: rule, rule x3` comments."""
    found: Counter = Counter()
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        m = _EXPECT.search(line)
        if not m:
            continue
        for item in m.group(1).split(","):
            name, _, times = item.strip().partition(" x")
            found[(number, name.strip())] += int(times or 1)
    return found


FILES = EXAMPLE_FILES


def test_there_are_examples():
    names = {p.name for p in FILES}
    assert {"manual-example1-autostart-loop.mcm", "manual-example2-conditions.mcm",
            "manual-example3-operator-moves.mcm", "manual-example4-four-modes.mcm",
            "manual-3.4.3-parameters.mcm", "four-modes.mcm"} <= names
    assert len(names) >= 8


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.name)
def test_example_diagnostics_match_expectations(path):
    result = compile_file(str(path))
    got = Counter((d.span.line, d.rule.name) for d in result.report.items)
    assert got == expectations(path)


@pytest.mark.parametrize("path", [p for p in FILES if "example3" not in p.name], ids=lambda p: p.name)
def test_examples_without_errors_build(path):
    result = compile_file(str(path))
    assert not result.report.has_errors
    assert result.program.md_lines()
