"""Rules are data: every check and hazard has a code, an explanation and `explain`;
every message is a template of its rule, filled in by the code that reports it."""
from __future__ import annotations

import ast
import string
from pathlib import Path

import pytest

from helpers.cli import cli
from helpers.compiling import program_of
from helpers.paths import PACKAGE, ROOT
from mercmac import diagnostics
from mercmac.sim.simulate import simulate_program
from mercmac import hazards
from mercmac.vm.models import Options

ALL = diagnostics.RULES + hazards.RULES
LIMITS = (-20_000, 20_000)

# (hazard, program, simulator options): each must be reported.
HAZARDS = [
    ("move-servo-off", "[MC00] MR100\n", {"servo_on": False}),
    ("move-joystick-on", "[MC00] JN20000,MR100\n", {}),
    ("soft-limit-clamp", "[MC00] JH1000,MA5000\n", {}),
    ("hard-limit", "[MC00] MR50000,WS0\n", {"hard_limits": LIMITS}),
    ("ws-never-finishes", "[MC00] SV0,MR100,WS0\n", {}),
    ("busy-loop", "[MC00] TB,RP\n", {}),
    ("reference-not-found", "[MC00] FE3,WS0\n", {"reference_at": 5000, "hard_limits": LIMITS}),
]


@pytest.mark.parametrize("name,text,options", HAZARDS, ids=[h[0] for h in HAZARDS])
def test_hazard_is_found(name, text, options):
    run = simulate_program(program_of(text), until_ms=5000, options=Options(**options))
    assert name in [h.rule for h in run.record.hazards]


def test_every_hazard_is_tested_and_explained():
    # rig-deadlock needs several controllers: tests/sim/test_rig_sim.py finds it on a rig
    assert {name for name, _, _ in HAZARDS} | {"rig-deadlock"} == set(hazards.NAMES)
    for r in hazards.RULES:
        assert r.code.startswith("MH") and len(r.explanation) > 100, r.name


def test_codes_and_names_are_unique_across_checks_and_hazards():
    assert len({r.code for r in ALL}) == len({r.name for r in ALL}) == len(ALL)


@pytest.mark.parametrize("r", ALL, ids=lambda r: r.code)
def test_explain_by_code_and_by_name(r):
    by_code, by_name = cli("explain", r.code), cli("explain", r.name.upper())
    assert by_code.exit_code == by_name.exit_code == 0, by_code.output
    assert by_code.output == by_name.output
    assert by_code.output.startswith(f"{r.code} {r.name} ({r.severity})")


def test_explain_lists_checks_and_hazards():
    listed = cli("explain").output
    for r in ALL:
        assert r.code in listed and r.name in listed


# -- messages are templates ---------------------------------------------------

def _fields(template: str) -> set[str]:
    return {f.split(".")[0].split("[")[0] for _, f, _, _ in string.Formatter().parse(template) if f}


@pytest.mark.parametrize("r", diagnostics.RULES, ids=lambda r: r.code)
def test_every_message_template_fills_in(r):
    assert r.messages, f"{r.name} has no message"
    for variant, template in r.messages.items():
        fields = _fields(template)
        assert all(f.isidentifier() for f in fields), (r.name, variant, fields)  # `{{` for a brace
        assert r.text(variant, **{f: 1 for f in fields}), (r.name, variant)


def _sources() -> dict[Path, str]:
    return {p: p.read_text(encoding="utf-8") for p in PACKAGE.rglob("*.py")
            if p.name != "parser_tables.py"}  # lark's generated stand-alone parser


def _rule_of(node) -> diagnostics.Rule | None:
    first = node.args[0] if node.args else None
    if isinstance(first, ast.Constant) and isinstance(first.value, str):
        try:
            return diagnostics.rule(first.value)
        except KeyError:
            return None
    return None


def _reports():
    """(place, rule, variant node or None, given fields or None when not all literal) for
    every `X.add("rule", span, variant, **values)` and `Finding("rule", where, variant,
    (("field", value), ...))` (mercmac.mdtext) in the package whose rule is a literal."""
    for path, text in _sources().items():
        for node in ast.walk(ast.parse(text)):
            if not isinstance(node, ast.Call) or (r := _rule_of(node)) is None:
                continue
            place = f"{path.relative_to(ROOT)}:{node.lineno}"
            if isinstance(node.func, ast.Attribute) and node.func.attr == "add":
                assert len(node.args) <= 3, f"{place}: a message passed as text; give {r.name} a template"
                given = {k.arg for k in node.keywords}
                yield place, r, node.args[2] if len(node.args) == 3 else None, \
                    None if None in given else given
            elif isinstance(node.func, ast.Name) and node.func.id == "Finding":
                values = node.args[3] if len(node.args) > 3 else ast.Tuple([])
                pairs = values.elts if isinstance(values, ast.Tuple) else None
                given = None if pairs is None or not all(
                    isinstance(p, ast.Tuple) and isinstance(p.elts[0], ast.Constant) for p in pairs
                ) else {p.elts[0].value for p in pairs}
                yield place, r, node.args[2] if len(node.args) > 2 else None, given


def test_reports_pass_values_not_wording():
    found = list(_reports())
    assert len(found) > 30
    for place, r, variant, given in found:
        variant = variant or ast.Constant("")
        assert not isinstance(variant, (ast.JoinedStr, ast.BinOp)), f"{place}: wording at the call"
        if isinstance(variant, ast.Constant):
            assert variant.value in r.messages, f"{place}: {r.name} has no message {variant.value!r}"
            if given is not None:
                assert _fields(r.messages[variant.value]) <= given, place


def test_every_message_variant_is_used():
    text = "\n".join(t for p, t in _sources().items() if p.name != "diagnostics.py")
    for r in diagnostics.RULES:
        for variant in r.messages:
            assert not variant or f'"{variant}"' in text, f"{r.name}: message {variant!r} unused"
