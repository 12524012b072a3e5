"""Properties of the compiler on generated programs and mangled input.

- Random well-formed high-level programs lower to MD strings that obey every
  firmware limit, and run on a model of the firmware (docs/simulator.md) exactly as the
  structured program means, for every combination of held inputs.
- Mangled input never raises: every failure is a diagnostic.
"""
from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from helpers.budgets import budget
from helpers.compiling import compile_text
from helpers.paths import EXAMPLE_FILES
from mercmac.compiler.ast_builder import build
from mercmac.compiler.checks import check_module
from mercmac.compiler.parse import parse
from mercmac.compiler.program import MAX_COMMANDS
from mercmac.diagnostics import Report
from helpers.programs import programs
from helpers.semantics import firmware_trace, high_level_trace, same_effects

def _stages(text):
    report = Report("gen.mcm")
    module = build(parse(text, report))
    return module, check_module(module, report, None)


@pytest.mark.slow
@settings(max_examples=budget(300), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(programs())
def test_lowered_programs_obey_the_firmware_and_keep_the_meaning(text):
    result = compile_text(text)
    errors = [d for d in result.report.items if d.severity == 0]
    if errors:  # only the slot budget may legitimately run out
        assert {d.rule.name for d in errors} == {"slot-range"}, (text, [d.message for d in errors])
        return
    program = result.program
    assert set(program.macros) <= set(range(32))
    for m in program.macros.values():
        assert len(m.ops) <= MAX_COMMANDS, (text, m.md)
    stored = {slot: [(op.mnemonic, op.arg) for op in m.ops] for slot, m in program.macros.items()}
    module, env = _stages(text)
    for mask in range(0, 64, 7):
        inputs = {n for n in range(1, 7) if mask >> (n - 1) & 1}
        # same_effects: equal traces, up to WA0 (an empty macro is `WA0`) and waits split
        # in pieces (`every 2min` is `WA60000,WA60000`)
        assert same_effects(firmware_trace(stored, inputs), high_level_trace(module, env, inputs)), (
            text, inputs)


NOISE = st.sampled_from(list("[]{},;@=-+?0123456789 \t\nMCEWXNFRPSVTabcdefghijklmnopqrstuvwxyz/\u2122"))


@settings(max_examples=budget(300), deadline=None)
@given(st.sampled_from(EXAMPLE_FILES), st.data())
def test_mangled_input_never_raises(path, data):
    text = path.read_text(encoding="utf-8")
    for _ in range(data.draw(st.integers(1, 6))):
        at = data.draw(st.integers(0, len(text)))
        cut = data.draw(st.integers(0, 3))
        text = text[:at] + "".join(data.draw(st.lists(NOISE, max_size=4))) + text[at + cut:]
    result = compile_text(text)
    for d in result.report.items:
        assert d.span.line >= 1 and d.span.column >= 1 and d.message


@settings(max_examples=budget(200), deadline=None)
@given(st.text(max_size=200))
def test_arbitrary_text_never_raises(text):
    result = compile_text(text)
    assert result.program is not None or result.report.has_errors
