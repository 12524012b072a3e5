"""A safe fix never changes what a program means (docs/checks.md, "Fixes").

Programs are generated whole, then one word of them is misspelled by one edit, as a hand
slips. `check --fix` makes only the safe fixes: they never turn a command into another,
and when the fixed file checks clean it builds to exactly the MD lines of the program as
it was written before the slip. A program `check` accepts builds to the same MD lines
after its safe fixes (the `target` line) as before.
"""
from __future__ import annotations

import re

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from helpers.budgets import budget
from helpers.programs import programs
from mercmac.commands import lookup
from mercmac.compiler import compile_source, fixing
from mercmac.compiler.checking import Choice, choice_for
from mercmac.diagnostics import SAFE, Severity
from mercmac.source import Source

TARGET = "C-863"
WORD = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
LETTERS = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"


def _choice() -> Choice:
    return choice_for(None)._replace(target=TARGET)


def _md(text: str) -> list[str] | None:
    """The MD lines the text builds to, or None when it has errors."""
    built = compile_source(Source("p.mcm", text), target=TARGET)
    if built.report.has_errors or built.program is None:
        return None
    return built.program.md_lines()


def _commands(text: str) -> list[str]:
    """The native commands of a text in order, as written (upper-case two-letter words
    the manual has: the generated programs name their macros leafN and modeN)."""
    return [w for w in WORD.findall(text) if len(w) == 2 and w.isupper() and lookup(w)]


@st.composite
def slips(draw):
    """A generated program, and the same with one word misspelled by one edit."""
    text = draw(programs())
    words = list(WORD.finditer(text))
    word = draw(st.sampled_from(words))
    w, at = word.group(), draw(st.integers(0, len(word.group()) - 1))
    edit = draw(st.sampled_from(["insert", "delete", "replace", "swap"]))
    letter = draw(st.sampled_from(LETTERS))
    if edit == "insert":
        slipped = w[:at] + letter + w[at:]
    elif edit == "delete" and len(w) > 1:
        slipped = w[:at] + w[at + 1:]
    elif edit == "swap" and at + 1 < len(w):
        slipped = w[:at] + w[at + 1] + w[at] + w[at + 2:]
    else:
        slipped = w[:at] + letter + w[at + 1:]
    return text, text[:word.start()] + slipped + text[word.end():]


@settings(max_examples=budget(300), deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(slips())
def test_safe_fixes_restore_the_program_or_leave_it_refused(case):
    written, slipped = case
    fixed = fixing.fix(Source("p.mcm", slipped), _choice())
    assert all(m.fix.applicability is SAFE for m in fixed.made)
    assert _commands(fixed.after) == _commands(slipped), (slipped, fixed.after)
    before = _md(slipped)
    after = _md(fixed.after)
    if before is not None:  # the slip made another program that checks: nothing to restore
        assert after == before, (slipped, fixed.after)
    elif after is not None:
        assert after == _md(written), (slipped, fixed.after)


@settings(max_examples=budget(200), deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(programs())
def test_a_program_check_accepts_builds_the_same_after_its_safe_fixes(text):
    before = _md(text)
    fixed = fixing.fix(Source("p.mcm", text), _choice())
    if before is None:
        return
    assert _md(fixed.after) == before
    assert not any(d.severity is Severity.ERROR for d in fixed.findings.diagnostics)
    assert fixed.after.startswith("target C-863\n") and len(fixed.made) == 1
