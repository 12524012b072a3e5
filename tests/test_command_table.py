"""One command table (docs/architecture.md, "One table, one model, one renderer"): nothing
outside mercmac/commands.py lists mnemonics.

Every module under mercmac/ is read with `ast`: a string constant that is a mnemonic of the
table (docstrings aside) is a second list; code names a command `Mnemonic.EM` or reads the
table. Every `Mnemonic.X` named anywhere is a command of the table.
"""
from __future__ import annotations

import ast

import pytest

from helpers.paths import PACKAGE, ROOT, TESTS
from mercmac.commands import COMMANDS, MODELS, Arg, Command, Kind, Mnemonic

# The table itself, and the parser lark generates from grammar.lark.
EXEMPT = {"commands.py", "parser_tables.py"}
# (module, mnemonic) -> why the literal must stay. Empty: keep it so.
ALLOWED: dict[tuple[str, str], str] = {}
MODULES = sorted(p for p in PACKAGE.rglob("*.py") if p.name not in EXEMPT)


def _docstrings(tree: ast.AST) -> set[int]:
    """ids of the docstring constants: the first statement of a module, class or function."""
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            first = node.body[0] if node.body else None
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant):
                found.add(id(first.value))
    return found


def _literals(path) -> list[tuple[int, str]]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    docs = _docstrings(tree)
    return [(n.lineno, n.value) for n in ast.walk(tree)
            if isinstance(n, ast.Constant) and isinstance(n.value, str)
            and n.value in COMMANDS and id(n) not in docs]


def _name(path) -> str:
    return str(path.relative_to(PACKAGE))


@pytest.mark.parametrize("path", MODULES, ids=_name)
def test_no_mnemonic_literals_outside_the_table(path):
    found = [(line, m) for line, m in _literals(path) if (_name(path), m) not in ALLOWED]
    assert not found, (f"{_name(path)} lists mnemonics {found}: name them Mnemonic.X "
                       "(mercmac/commands.py) or read the table")


def test_the_scan_sees_literals():
    tree_text = 'x = "EM"\nif y == "TM": pass\nz = f"MD{n}"\n'
    tree = ast.parse(tree_text)
    assert sorted(n.value for n in ast.walk(tree) if isinstance(n, ast.Constant)
                  and n.value in COMMANDS) == ["EM", "MD", "TM"]


def test_allowed_literals_are_still_there():
    for (module, mnemonic), why in ALLOWED.items():
        assert why and mnemonic in [m for _, m in _literals(PACKAGE / module)], (module, mnemonic)


def test_every_command_has_its_constant_and_no_more():
    constants = {k: v for k, v in vars(Mnemonic).items() if not k.startswith("_") and k != "name"}
    assert sorted(constants.values()) == sorted(COMMANDS)
    assert all(getattr(Mnemonic, Mnemonic.name(m)) == m for m in COMMANDS)
    assert Mnemonic.EM == "EM" and Mnemonic.FA_Q == "FA?" and type(Mnemonic.EM) is str


SOURCES = sorted(PACKAGE.rglob("*.py")) + sorted(TESTS.rglob("*.py"))


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_named_constant_is_in_the_table(path):
    tree = ast.parse(path.read_text(encoding="utf-8"))
    named = {n.attr for n in ast.walk(tree) if isinstance(n, ast.Attribute)
             and isinstance(n.value, ast.Name) and n.value.id == "Mnemonic"}
    unknown = sorted(named - {"name"} - {Mnemonic.name(m) for m in COMMANDS})
    assert not unknown, f"{path.name} names Mnemonic.{unknown[0]}: no command of the table"


@pytest.mark.parametrize("command", COMMANDS.values(), ids=lambda c: c.mnemonic)
def test_table_facts_fit_their_command(command: Command):
    for model, value in command.power_on:  # power-on values: of an argument, on that model
        assert command.arg is not Arg.NONE and model in MODELS and model in command.models
        assert command.in_range(value)
    if command.reads or command.unsigned:  # report facts: report commands
        assert command.kind is Kind.REPORT
    if command.reads:
        assert COMMANDS[command.reads].kind is Kind.SETTING
        assert COMMANDS[command.reads].models == command.models
