"""Every supported Python: tools/pythons.py runs the suite on each version that
pyenv holds, and pyproject, the README and CI name the same versions it covers."""
from __future__ import annotations

import importlib.util
import re
import sys
from pathlib import Path

import pytest

from helpers.paths import ROOT
from mercmac import tomlfile

SCRIPT = ROOT / "tools" / "pythons.py"
_spec = importlib.util.spec_from_file_location("pythons", SCRIPT)
pythons = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(pythons)

PROJECT = tomlfile.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
README = (ROOT / "README.md").read_text(encoding="utf-8")
THIS = "{}.{}".format(*sys.version_info[:2])


def test_requires_python_starts_at_the_oldest_version_covered():
    assert PROJECT["requires-python"] == f">={pythons.SUPPORTED[0]}"


def test_the_classifiers_name_exactly_the_versions_covered():
    prefix = "Programming Language :: Python :: "
    named = [c.removeprefix(prefix) for c in PROJECT["classifiers"] if c.startswith(prefix + "3.")]
    assert named == list(pythons.SUPPORTED)


def test_the_readme_names_the_versions_covered():
    assert f"(Python {pythons.SUPPORTED[0]}+)" in README.split("\n\n")[1]
    development = README.split("\n## Development\n", 1)[1].split("\n## ", 1)[0]
    listed = ", ".join(pythons.SUPPORTED[:-1]) + " and " + pythons.SUPPORTED[-1]
    assert "tools/pythons.py" in development and f"Python {listed}" in development


def test_this_python_is_one_of_them():
    assert THIS in pythons.SUPPORTED


def test_ci_runs_the_other_versions_after_the_readme_command():
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8").splitlines()
    matrix = [i for i, line in enumerate(ci) if "tools/pythons.py --others" in line]
    readme = [i for i, line in enumerate(ci) if line.endswith(".venv/bin/python -m pytest")]
    assert matrix and readme and readme[0] < matrix[0]


def _pyenv(tmp_path: Path, *names: str) -> Path:
    """A pyenv root whose versions/ holds these folders, each with a bin/python."""
    for name in names:
        (tmp_path / "versions" / name / "bin").mkdir(parents=True)
        (tmp_path / "versions" / name / "bin" / "python").touch()
    return tmp_path


def test_the_newest_patch_release_is_taken_and_other_builds_are_not(tmp_path):
    root = _pyenv(tmp_path, "3.12.9", "3.12.10", "3.12.11t", "3.12-dev", "3.12.12rc1", "3.1.99")
    assert pythons.interpreter("3.12", root) == root / "versions" / "3.12.10" / "bin" / "python"
    assert pythons.interpreter("3.1", root) == root / "versions" / "3.1.99" / "bin" / "python"
    assert pythons.interpreter("3.13", root) is None
    assert pythons.interpreter("3.13", tmp_path / "nowhere") is None


def test_pyenv_root_follows_pyenv_root_env(tmp_path, monkeypatch):
    # `pyenv root` prints $PYENV_ROOT where pyenv is installed; the script reads it where not
    monkeypatch.setenv("PYENV_ROOT", str(tmp_path))
    assert pythons.pyenv_root() == tmp_path


def test_unknown_versions_are_a_usage_error_and_others_leaves_this_one_out():
    with pytest.raises(ValueError, match="3.9 not among the supported"):
        pythons.chosen_versions("3.12,3.9", others=False)
    with pytest.raises(SystemExit) as usage:
        pythons.main(["--versions", "3.9"])
    assert usage.value.code == 2
    assert pythons.chosen_versions(" 3.13 ,3.12", others=False) == ["3.13", "3.12"]
    assert THIS not in pythons.chosen_versions(None, others=True)
    assert len(pythons.chosen_versions(None, others=True)) == len(pythons.SUPPORTED) - 1


def _run(tmp_path, monkeypatch, capsys, verdict: str) -> tuple[int, str]:
    """main() on 3.10 (missing) and 3.12 (present, its venv this Python) for a one-test file."""
    monkeypatch.setenv("PYENV_ROOT", str(_pyenv(tmp_path / "pyenv", "3.12.1")))
    monkeypatch.setattr(pythons, "ready_venv", lambda version, python: Path(sys.executable))
    test = tmp_path / "tests" / "test_one.py"
    test.parent.mkdir()
    test.write_text(f"def test_one():\n    assert {verdict}\n", encoding="utf-8")
    code = pythons.main(["--versions", "3.10,3.12", "--", str(test), "-p", "no:cacheprovider",
                         "-p", "no:xdist", "--rootdir", str(test.parent), "-c", "/dev/null"])
    return code, capsys.readouterr().out


def test_a_missing_version_is_skipped_saying_so_and_a_passing_one_exits_0(
        tmp_path, monkeypatch, capsys):
    code, out = _run(tmp_path, monkeypatch, capsys, "True")
    summary = out.split("--- per Python version:\n", 1)[1].splitlines()
    assert code == 0
    assert summary[0] == f"3.10     skipped: no 3.10.N under {tmp_path / 'pyenv' / 'versions'}"
    assert re.fullmatch(r"3\.12\.1 +passed  \d+ s wall  \[1 passed in [\d.]+s\]", summary[1])


def test_a_failing_version_exits_1_and_its_pytest_output_is_shown(tmp_path, monkeypatch, capsys):
    code, out = _run(tmp_path, monkeypatch, capsys, "False")
    assert code == 1
    assert "assert False" in out  # pytest's own report, passed through
    assert re.search(r"^3\.12\.1 +FAILED \(pytest exit 1\)  \d+ s wall  \[1 failed in ", out, re.M)


def test_the_venv_is_installed_again_only_when_pyproject_changes(tmp_path, monkeypatch):
    calls = []

    def run(command, cwd=None, check=False):
        calls.append(command[2] if command[1] == "-m" else command)
        if command[2] == "pip" and fail:
            raise pythons.subprocess.CalledProcessError(1, command)
        if command[2] == "venv":
            (Path(command[-1]) / "bin").mkdir(parents=True, exist_ok=True)

    monkeypatch.setattr(pythons, "ROOT", tmp_path)
    monkeypatch.setattr(pythons, "VENVS", tmp_path / ".venvs")
    monkeypatch.setattr(pythons.subprocess, "run", run)
    (tmp_path / "pyproject.toml").write_text("[project]\n", encoding="utf-8")
    python = Path(sys.executable)
    fail = False
    assert pythons.ready_venv("3.12", python) == tmp_path / ".venvs" / "py3.12" / "bin" / "python"
    assert calls == ["venv", "pip"]
    pythons.ready_venv("3.12", python)
    assert calls == ["venv", "pip"]  # nothing changed: nothing done
    (tmp_path / "pyproject.toml").write_text("[project]\nname = 'x'\n", encoding="utf-8")
    fail = True
    with pytest.raises(pythons.subprocess.CalledProcessError):
        pythons.ready_venv("3.12", python)
    fail = False
    pythons.ready_venv("3.12", python)  # a failed install is tried again
    pythons.ready_venv("3.12", python)
    assert calls == ["venv", "pip"] * 3
