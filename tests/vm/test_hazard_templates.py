"""Hazard messages are templates of their rule, as the checks' are: the machine
reports a hazard with values, never wording, and vm/hazards.py holds every sentence."""
from __future__ import annotations

import ast
import string

import pytest

from mercmac.sim.simulate import simulate_program
from mercmac import hazards
from mercmac.vm.hazards import HazardLog
from mercmac.vm.models import Options
from helpers.compiling import program_of
from helpers.paths import PACKAGE

VM = PACKAGE / "vm"
RULES = {r.name: r for r in hazards.RULES}
# the machine's two ways to report one: _hazard(rule, variant, **values) and
# _refuse(rule, error code, variant)
VARIANT_AT = {"_hazard": 1, "_refuse": 2}


def _fields(template: str) -> set[str]:
    return {f for _, f, _, _ in string.Formatter().parse(template) if f}


def _calls():
    """(place, call node, name) of every hazard report in the VM's sources."""
    for path in sorted(VM.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) \
                    and node.func.attr in VARIANT_AT:
                yield f"{path.name}:{node.lineno}", node, node.func.attr


@pytest.mark.parametrize("r", hazards.RULES, ids=lambda r: r.code)
def test_every_hazard_template_fills_in(r):
    assert r.messages, f"{r.name} has no message"
    for variant, template in r.messages.items():
        assert r.text(variant, **{f: 1 for f in _fields(template)})


def test_hazards_are_reported_with_values_not_wording():
    calls = list(_calls())
    assert len(calls) >= 8
    for place, call, name in calls:
        if call.args[0].__class__ is not ast.Constant:
            continue  # _refuse passing its rule on: its callers are checked
        rule = RULES[call.args[0].value]
        assert not any(isinstance(a, (ast.JoinedStr, ast.BinOp)) for a in call.args), \
            f"{place}: wording at the call; give {rule.name} a template"
        at = VARIANT_AT[name]
        variant = call.args[at].value if len(call.args) > at else ""
        assert variant in rule.messages, f"{place}: {rule.name} has no message {variant!r}"
        given = {k.arg for k in call.keywords} - {"where", "each"}  # place, not wording
        assert _fields(rule.messages[variant]) == given, place


def test_every_hazard_variant_is_used():
    text = "\n".join(p.read_text(encoding="utf-8") for p in VM.glob("*.py")
                     if p.name != "hazards.py")
    for r in hazards.RULES:
        for variant in r.messages:
            assert not variant or f'"{variant}"' in text, f"{r.name}: message {variant!r} unused"


def test_the_log_words_a_hazard_the_first_time_only():
    log = HazardLog()
    assert log.add("busy-loop", (0, 1), macro="MC00") == RULES["busy-loop"].text(macro="MC00")
    assert log.add("busy-loop", (0, 1), macro="MC00") is None
    assert log.add("busy-loop", (0, 2), macro="MC00") is not None  # another place
    with pytest.raises(KeyError, match="no-such-rule"):
        log.add("no-such-rule", None)
    with pytest.raises(KeyError, match="hard-limit has no message 'other'"):
        log.add("hard-limit", None, "other")


def test_a_reported_hazard_is_its_template_filled_with_the_run_s_values():
    run = simulate_program(program_of("[MC00] MR50000,WS0\n"), until_ms=5000,
                   options=Options(hard_limits=(-1000, 5000)))
    [hazard] = run.record.hazards
    assert hazard.message == RULES["hard-limit"].text(side="positive", position=5000)
    assert hazard.message == "the stage hit the positive limit switch at 5000 and stopped abruptly"
