"""The suite's own layout: what tests share lives in tests/helpers/, fixtures
and hooks in conftest.py, files are found through helpers.paths (so a test file can move
to another folder and still run), and every Hypothesis budget follows the chosen profile."""
from __future__ import annotations

import ast
import os
import subprocess
import sys

import pytest

from helpers import budgets
from helpers.paths import ROOT, TESTS

TEST_FILES = sorted(TESTS.rglob("test_*.py"))


def _tree(path) -> ast.Module:
    return ast.parse(path.read_text(encoding="utf-8"))


def _imported(tree: ast.Module) -> list[str]:
    return [n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and n.module] + \
        [a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names]


@pytest.mark.parametrize("path", TEST_FILES, ids=lambda p: str(p.relative_to(TESTS)))
def test_shared_code_comes_from_helpers(path):
    # conftest and `tests.x` resolve only from some places (tests/ itself, the root as the
    # current folder); lsp_wire and semantics are helpers' modules, not top-level ones
    wrong = [m for m in _imported(_tree(path))
             if m in ("conftest", "lsp_wire", "semantics") or m.split(".")[0] == "tests"]
    assert not wrong, f"{path.name} imports {wrong}: import helpers.*"


@pytest.mark.parametrize("path", sorted(TESTS.rglob("*.py")),
                         ids=lambda p: str(p.relative_to(TESTS)))
def test_no_file_imports_a_test_module(path):
    # importing a test module runs its module-level code in the importer (its skips too),
    # resolves only while pytest has put that test's folder on sys.path, and ties one test
    # to another's file: what two tests share lives in tests/helpers/
    named = [n.module or "" for n in ast.walk(_tree(path)) if isinstance(n, ast.ImportFrom)] + \
        [a.name for n in ast.walk(_tree(path)) if isinstance(n, (ast.Import, ast.ImportFrom))
         for a in n.names]  # `from sim import test_x` names the module among the names
    wrong = [m for m in named if any(part.startswith("test_") for part in m.split("."))]
    assert not wrong, f"{path.relative_to(TESTS)} imports {wrong}: move it to tests/helpers/"


@pytest.mark.parametrize("path", TEST_FILES, ids=lambda p: str(p.relative_to(TESTS)))
def test_files_are_found_through_the_helpers_paths(path):
    # a bare __file__ (not mercmac.__file__): a path from the test's own folder
    lines = [n.lineno for n in ast.walk(_tree(path)) if isinstance(n, ast.Name) and n.id == "__file__"]
    assert not lines, f"{path.name}:{lines} finds files from its own folder: use helpers.paths"


def test_conftest_holds_only_fixtures_and_hooks():
    def is_fixture(node) -> bool:
        return any("fixture" in ast.unparse(d) for d in node.decorator_list)

    defined = [n for n in _tree(TESTS / "conftest.py").body
               if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef))]
    others = [n.name for n in defined if not n.name.startswith("pytest_") and not is_fixture(n)]
    assert defined and not others, f"conftest.py defines {others}: move them to tests/helpers/"


@pytest.mark.parametrize("path", TEST_FILES, ids=lambda p: str(p.relative_to(TESTS)))
def test_every_example_budget_follows_the_profile(path):
    fixed = [node.lineno for node in ast.walk(_tree(path)) if isinstance(node, ast.Call)
             and ast.unparse(node.func).endswith("settings")
             for k in node.keywords if k.arg == "max_examples" and isinstance(k.value, ast.Constant)]
    assert not fixed, f"{path.name}:{fixed}: max_examples=budget(N), so `thorough` searches longer"


@pytest.mark.parametrize("environment, profile", [
    ({}, "dev"),
    ({"CI": "true"}, "ci"),
    ({"CI": "true", budgets.VARIABLE: "thorough"}, "thorough"),
    ({budgets.VARIABLE: "ci"}, "ci"),
])
def test_the_profile_is_dev_locally_ci_under_ci_or_the_one_asked_for(environment, profile,
                                                                     monkeypatch):
    for name in ("CI", budgets.VARIABLE, "MERCMAC_FUZZ_EXAMPLES"):
        monkeypatch.delenv(name, raising=False)
    for name, value in environment.items():
        monkeypatch.setenv(name, value)
    assert budgets.chosen() == profile
    assert budgets.budget(30) == (300 if profile == "thorough" else 30)


def test_mercmac_fuzz_examples_still_sets_a_fuzz_budget(monkeypatch):
    monkeypatch.setenv("MERCMAC_FUZZ_EXAMPLES", "7")
    assert budgets.fuzz_budget(40) == 7


@pytest.mark.slow
def test_an_unknown_profile_stops_pytest_naming_the_choices():
    env = {**os.environ, budgets.VARIABLE: "fast"}
    run = subprocess.run([sys.executable, "-m", "pytest", "-n", "0", "-p", "no:cacheprovider",
                          "--collect-only", "tests/project/test_readme.py"], cwd=ROOT, env=env,
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 4, run.stdout[-2000:] + run.stderr[-2000:]  # pytest: usage error
    assert f"{budgets.VARIABLE}='fast'" in run.stderr and "dev, ci, thorough" in run.stderr
    assert "Traceback" not in run.stderr
