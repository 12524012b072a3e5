"""Fixtures and hooks for every test; what tests import lives in tests/helpers/."""
from __future__ import annotations

import os
import signal
from pathlib import Path

import pytest

from helpers import budgets
from helpers.paths import EXAMPLES

# A suite started as a background job (`pytest &`) or by some CI runners inherits SIGINT as
# ignored, and so would every process it starts: the Ctrl-C tests could not interrupt the
# mercmac they run. This process takes Python's own handler instead; exec resets a handled
# signal to the default in each child (an ignored one would stay ignored).
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)
# The same for SIGHUP under `nohup` (tools/loaded_suite.py runs so): the tests that hang up a
# mercmac could not. A handler that does nothing keeps this process alive on a hangup, as
# nohup means, while each child starts with the default again.
if hasattr(signal, "SIGHUP") and signal.getsignal(signal.SIGHUP) is signal.SIG_IGN:
    signal.signal(signal.SIGHUP, lambda signum, frame: None)

# Half of the suite's time is spent waiting on timeouts (a silent controller, a process that
# must not answer), not computing, so more workers than cores pay: on 2 cores the pty and
# property tests took 152 s in one process, 92 s in 2 workers, 84 s in 4 and 62 s in 6, but 6
# made the paced emulator's 20 ms character timing miss. Two per core (README, Development).
WORKERS_PER_CORE = 2
# A run of one or two named files (`pytest tests/fmt/test_fmt.py -x`) stays in this process:
# starting workers would cost more than they save, and pdb works.
SERIAL_FILES = 2


def pytest_configure(config):
    """The Hypothesis profile, before any test module builds its `@settings`."""
    try:
        budgets.load()
    except ValueError as error:
        raise pytest.UsageError(str(error)) from None


@pytest.hookimpl(optionalhook=True)  # known only while pytest-xdist is loaded
def pytest_xdist_auto_num_workers(config):
    """`-n auto` (pyproject's addopts): PYTEST_XDIST_AUTO_NUM_WORKERS if set; none for a run
    of a file or two; else two workers per core."""
    if os.environ.get("PYTEST_XDIST_AUTO_NUM_WORKERS"):
        return None  # xdist's own hook reads it
    files = {arg.split("::")[0] for arg in config.args}
    if len(files) <= SERIAL_FILES and all(f.endswith(".py") for f in files):
        return 0
    return WORKERS_PER_CORE * (os.cpu_count() or 1)


@pytest.fixture
def write(tmp_path):
    """`write(text_or_bytes, name="p.mcm")`: a new file in tmp_path, as a str path."""
    def make(text: str | bytes, name: str = "p.mcm") -> str:
        path = tmp_path / name
        if isinstance(text, bytes):
            path.write_bytes(text)
        else:
            path.write_text(text, encoding="utf-8")
        return str(path)
    return make


@pytest.fixture
def program_file(tmp_path, request):
    """The test module's PROGRAM written to tmp_path/prog.mcm."""
    path = tmp_path / "prog.mcm"
    path.write_text(request.module.PROGRAM)
    return path


@pytest.fixture
def examples_dir() -> Path:
    return EXAMPLES


@pytest.fixture
def data_dir(tmp_path, monkeypatch) -> Path:
    """mercmac's data folder (backups, flash history) as MERCMAC_DATA_DIR: tmp_path/data."""
    folder = tmp_path / "data"
    monkeypatch.setenv("MERCMAC_DATA_DIR", str(folder))
    return folder


@pytest.fixture(autouse=True)
def _private_data_dir(tmp_path_factory, monkeypatch):
    """Backups and flash history go to a fresh folder, never the user's data directory."""
    monkeypatch.delenv("MERCMAC_DATA_DIR", raising=False)
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path_factory.mktemp("xdg-data")))


@pytest.fixture(autouse=True)
def _no_emulator_left_serving():
    """A virtual controller's thread ends with its test: one left serving reads whatever pty
    later gets its file descriptor, and answered another test's host from a stale chain."""
    import threading

    def serving() -> set:
        return {t for t in threading.enumerate() if t.name == "mercmac-emulator" and t.is_alive()}

    before = serving()
    yield
    left = serving() - before
    for thread in left:
        thread.join(1.0)  # a closed server's last turn may still be ending
    assert not serving() - before, "a virtual controller is still serving after its test"
