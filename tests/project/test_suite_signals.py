"""The suite holds when it is started with SIGINT ignored, as a background job (`pytest &`)
and some CI runners start it: conftest gives the test process Python's handler,
so every mercmac a test starts can be interrupted by its Ctrl-C tests."""
from __future__ import annotations

import signal
import subprocess
import sys

import pytest

from helpers.paths import ROOT


def _pytest(test: str) -> list[str]:
    # -n 0: the nested run is one test in this process, where conftest gives back the handler.
    # Two more xdist workers on a loaded 2-core machine bought nothing, and an execnet worker
    # that did not hang up in time kept a passed run from exiting (CI, Python 3.13).
    return [sys.executable, "-m", "pytest", "-q", "-n", "0", "-p", "no:cacheprovider", test]


def _ignoring_sigint() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)


@pytest.mark.slow
def test_a_ctrl_c_test_passes_when_the_suite_inherits_sigint_ignored():
    test = "tests/upload/test_upload_cli.py::test_ctrl_c_in_a_real_process"
    run = subprocess.run(_pytest(test), cwd=ROOT, capture_output=True, text=True, timeout=120,
                         preexec_fn=_ignoring_sigint)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-2000:]


def _ignoring_sighup() -> None:
    signal.signal(signal.SIGHUP, signal.SIG_IGN)


@pytest.mark.slow
@pytest.mark.skipif(not hasattr(signal, "SIGHUP"), reason="needs POSIX signals")
def test_a_hang_up_test_passes_when_the_suite_runs_under_nohup():
    """`nohup pytest` (SIGHUP ignored, inherited by every child): a mercmac a test hangs up
    still stops as a user's would (once it flashed on and exited 0)."""
    test = ("tests/upload/test_flash_signals.py::"
            "test_a_signal_while_a_file_is_flashed_says_what_the_controller_holds[SIGHUP]")
    run = subprocess.run(_pytest(test), cwd=ROOT, capture_output=True, text=True, timeout=120,
                         preexec_fn=_ignoring_sighup)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-2000:]
