"""The suite holds when it is started with SIGINT ignored, as a background job (`pytest &`)
and some CI runners start it (issue 16): conftest gives the test process Python's handler,
so every mercmac a test starts can be interrupted by its Ctrl-C tests."""
from __future__ import annotations

import signal
import subprocess
import sys

import pytest

from helpers.paths import ROOT


def _ignoring_sigint() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)


@pytest.mark.slow
def test_a_ctrl_c_test_passes_when_the_suite_inherits_sigint_ignored():
    test = "tests/upload/test_upload_cli.py::test_ctrl_c_in_a_real_process"
    run = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", test],
                         cwd=ROOT, capture_output=True, text=True, timeout=120,
                         preexec_fn=_ignoring_sigint)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-2000:]
