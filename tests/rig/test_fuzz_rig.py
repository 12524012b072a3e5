"""Hostile rig files through every command that reads one, as the
fuzz tests of the commands put hostile programs through them: random keys, types, names,
paths and wires (tests/helpers/hostile_rigs.py) through `check`, `sim`, `describe`, `fmt` and
`emulate --rig`, in-process through the real click group.

The promises, for every rig and command: no traceback and a known exit code; no hang; no
file outside the rig's folder opened (an audit hook sees every `open`, a symlink followed
to its end), shown (the secret's text never in the output) or written (the tree around the
rig folder is byte for byte as before). The language server's agreement with `check` on the
same rigs is tests/lsp/test_lsp_rig_fuzz.py.

`MERCMAC_FUZZ_EXAMPLES=500 pytest tests/rig/test_fuzz_rig.py` searches harder.
"""
from __future__ import annotations

import os
import sys
import tempfile
from contextlib import contextmanager
from pathlib import Path

import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from helpers.budgets import fuzz_budget
from helpers.cli import hang_guard
from helpers.hostile_rigs import SECRET, make_rig, tree
from mercmac.cli import main

BUDGET = settings(max_examples=fuzz_budget(25), deadline=None,
                  derandomize="MERCMAC_FUZZ_EXAMPLES" not in os.environ,
                  suppress_health_check=[HealthCheck.too_slow])
INTERRUPTED = 130  # emulate's end when its server stops (below: at once)
COMMANDS = {  # each command that takes a rig, and the exit codes it may end with
    "check": (["check"], {0, 1, 2}),
    "check json": (["check", "--format", "json"], {0, 1, 2}),
    "sim": (["sim", "--until", "300ms"], {0, 1, 2}),
    "sim json": (["sim", "--format", "json", "--until", "300ms"], {0, 1, 2}),
    "describe": (["describe"], {0, 1, 2}),
    "describe markdown": (["describe", "--format", "markdown"], {0, 1, 2}),
    "fmt": (["fmt"], {0, 1, 2}),
    "emulate": (["emulate", "--rig"], {1, 2, INTERRUPTED}),
}

_opened: list[str] | None = None  # the paths opened while a command runs, when watched


def _audit(event: str, args: tuple) -> None:
    if _opened is not None and event == "open" and isinstance(args[0], (str, bytes)):
        _opened.append(os.fsdecode(args[0]))


sys.addaudithook(_audit)  # hooks stay for the process; this one records only when asked


@contextmanager
def _watching_opens():
    global _opened
    _opened = []
    try:
        yield _opened
    finally:
        _opened = None


@pytest.fixture(autouse=True)
def _emulator_stops_at_once(monkeypatch):
    """`emulate --rig` serves until Ctrl-C: here it is pressed the moment serving starts,
    after the rig was read, checked and its chain built."""
    from mercmac.emulator.ptyserver import PtyServer

    def interrupted(self):
        raise KeyboardInterrupt

    monkeypatch.setattr(PtyServer, "serve_forever", interrupted)


@BUDGET
@given(rnd=st.randoms(use_true_random=False), command=st.sampled_from(sorted(COMMANDS)))
def test_a_hostile_rig_reaches_nothing_outside_its_folder(rnd, command):
    args, exits = COMMANDS[command]
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp)
        rig = make_rig(rnd, root)
        work = root / "cwd"
        work.mkdir()
        before = tree(root, skip=rig.parent)
        result, opened = _run(work, [*args, str(rig)])
        shown = result.output + (result.stderr if result.stderr_bytes is not None else "")
        assert result.exception is None or isinstance(result.exception, SystemExit), \
            (command, rig.read_bytes()[:2000], result.exception)
        assert result.exit_code in exits, (command, result.exit_code, shown[-2000:])
        assert "Traceback" not in shown
        assert "SECRET-" not in shown and SECRET not in shown, (command, shown[-2000:])
        reached = [p for p in opened if _outside(p, rig.parent)]
        assert reached == [], (command, reached)
        assert tree(root, skip=rig.parent) == before, command


def _run(work: Path, args: list[str]):
    """The command run in `work`, and the paths it opened (relative ones from `work`)."""
    old = os.getcwd()
    os.chdir(work)
    try:
        with hang_guard(), _watching_opens() as opened:
            result = CliRunner().invoke(main, args, catch_exceptions=True)
        return result, [os.path.join(work, p) for p in opened]
    finally:
        os.chdir(old)


def _outside(path: str, folder: Path) -> bool:
    """Whether `path`, followed through its links, lies beside the rig's folder (in the test's
    own tree: the interpreter's and the libraries' files are not the rig's business)."""
    real = Path(os.path.realpath(path))
    root = folder.resolve().parent
    return real.is_relative_to(root) and not real.is_relative_to(folder.resolve())
