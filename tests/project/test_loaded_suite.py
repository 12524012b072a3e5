"""tools/loaded_suite.py: the README's test command under load runs what CI runs,
says when stress-ng is missing, and reads pytest's counts."""
from __future__ import annotations

import importlib.util
import os
import subprocess
import sys

from helpers.paths import ROOT
from helpers.readme import setup_commands

SCRIPT = ROOT / "tools" / "loaded_suite.py"


def _script():
    spec = importlib.util.spec_from_file_location("loaded_suite", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_it_runs_the_readme_test_command():
    assert _script().readme_test_command() == setup_commands()[1]


def test_without_stress_ng_it_says_so_and_exits_2(tmp_path):
    env = {**os.environ, "PATH": str(tmp_path)}  # no stress-ng (nor anything else) on it
    run = subprocess.run([sys.executable, str(SCRIPT), "--runs", "1"], capture_output=True,
                         text=True, timeout=60, env=env, cwd=tmp_path)
    assert run.returncode == 2, run.stdout + run.stderr
    assert "stress-ng is not installed" in run.stderr and "apt-get install stress-ng" in run.stderr


def test_a_run_is_reported_with_its_counts_and_slowest_tests(capsys):
    output = ("==== slowest 10 durations ====\n12.50s call     tests/a.py::test_slow\n\n"
              "FAILED tests/b.py::test_x - AssertionError\n"
              "==== 1 failed, 41 passed, 3 skipped in 95.20s (0:01:35) ====\n")
    _script().report(2, 120.4, 1, output)
    shown = capsys.readouterr().out
    assert "run 2: FAILED (exit 1), wall 120 s" in shown
    assert "1 failed, 41 passed, 3 skipped, pytest's 95.20 s" in shown
    assert "12.50s call     tests/a.py::test_slow" in shown and "FAILED tests/b.py::test_x" in shown
