"""Ctrl-C, SIGTERM and SIGHUP end every command alike, from the first instant of the program
to its last (docs/cli.md, "Exit codes"): one line on standard error, exit 128+N, and
never a traceback, click's 'Aborted!', or a half-written file.

Each test starts mercmac as a process through the entry point pyproject.toml declares, and
has it signal itself at a known point: when a given module starts to be imported (the
command line's imports take a while, and a signal then used to trace back), or at a given
simulation event. The point is reached whatever the machine's speed; nothing in mercmac
itself knows about it."""
from __future__ import annotations

import os
import re
import select
import signal
import subprocess
import sys
import time

import pytest

from helpers.cli import on_a_terminal
from helpers.files import leftovers
from helpers.paths import EXAMPLE4, ROOT

pytestmark = pytest.mark.skipif(not hasattr(signal, "SIGHUP"), reason="needs POSIX signals")

SIGNALS = [signal.SIGINT, signal.SIGTERM, signal.SIGHUP]
NAMES = lambda s: signal.Signals(s).name  # noqa: E731 (pytest ids)

# The program as pip's console script or `python -m mercmac` starts it, with a meta path
# finder that sends the process SIGNUM when MODULE is first imported (then runs TELL): a
# signal at that point.
STARTED = """
import os, runpy, signal, sys
class Trip:
    def find_spec(self, name, path=None, target=None):
        if name == {module!r}:
            sys.meta_path.remove(self)
            os.kill(os.getpid(), {signum}){tell}
        return None
sys.meta_path.insert(0, Trip())
sys.argv = ["mercmac", *{args!r}]
{start}
"""

# The same, signalled at the Nth event the simulation hands its VCD dump.
AT_EVENT = """
import os, sys
from mercmac.sim import vcd
seen, on_event = [], vcd.VcdObserver.on_event
def counted(self, event):
    seen.append(event)
    if len(seen) == {nth}:
        os.kill(os.getpid(), {signum})
    on_event(self, event)
vcd.VcdObserver.on_event = counted
sys.argv = ["mercmac", *{args!r}]
{start}
"""


def script_start() -> str:
    """What the console script pyproject.toml declares runs: `from M import F; F()`."""
    declared = re.search(r'^\[project\.scripts\]\nmercmac = "([\w.]+):(\w+)"$',
                         (ROOT / "pyproject.toml").read_text(encoding="utf-8"), re.M)
    module, function = declared.groups()
    return f"from {module} import {function}; sys.exit({function}())"


STARTS = {"script": script_start(),
          "-m": "runpy.run_module('mercmac', run_name='__main__', alter_sys=True)"}


def run(code: str, cwd) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}  # the mercmac under test, not an installed one
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=cwd, env=env, timeout=60)


def said(signum: int) -> list[str]:
    """All that standard error holds after the signal."""
    return ["mercmac: interrupted" + ("" if signum == signal.SIGINT else f" ({NAMES(signum)})")]


# The first import the entry point makes, one click makes, the lazily loaded `sim` command
# (click resolves it: a KeyboardInterrupt there was 'Aborted!', exit 1) and one inside the
# command's work (the compiler, imported when the file is compiled).
MODULES = ["mercmac.cli", "click.core", "mercmac.cli.sim", "mercmac.compiler"]


@pytest.mark.parametrize("module", MODULES)
@pytest.mark.parametrize("signum", SIGNALS, ids=NAMES)
def test_a_signal_while_the_program_starts_ends_it_in_one_line(module, signum, tmp_path):
    code = STARTED.format(module=module, signum=int(signum), start=STARTS["script"], tell="",
                          args=["sim", str(EXAMPLE4), "--until", "1500d"])
    done = run(code, tmp_path)
    assert (done.returncode, done.stderr.splitlines()) == (128 + signum, said(signum)), \
        done.stderr
    assert done.stdout == ""


@pytest.mark.parametrize("signum", SIGNALS, ids=NAMES)
def test_python_dash_m_mercmac_is_the_same_program(signum, tmp_path):
    code = STARTED.format(module="mercmac.cli", signum=int(signum), start=STARTS["-m"], tell="",
                          args=["check", str(EXAMPLE4)])
    done = run(code, tmp_path)
    assert (done.returncode, done.stderr.splitlines()) == (128 + signum, said(signum)), \
        done.stderr


def test_the_entry_point_runs_the_command_line(tmp_path):
    for start in STARTS.values():
        code = STARTED.format(module="none", signum=0, start=start, tell="",
                              args=["check", str(EXAMPLE4)])
        done = run(code, tmp_path)
        assert done.returncode == 0 and "0 errors, 3 warnings" in done.stdout, done.stderr


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGHUP], ids=NAMES)
def test_a_signal_during_sim_shows_the_run_so_far_and_keeps_the_old_vcd(signum, tmp_path):
    """As Ctrl-C does: the timeline so far and the summary, the VCD it was writing dropped
    (the old file stays whole, no temporary file is left), exit 128+N."""
    vcd = tmp_path / "run.vcd"
    vcd.write_text("old\n")
    code = AT_EVENT.format(nth=3, signum=int(signum), start=STARTS["script"],
                           args=["sim", str(EXAMPLE4), "--until", "10s", "--vcd", str(vcd)])
    done = run(code, tmp_path)
    assert (done.returncode, done.stderr.splitlines()[-1:]) == (128 + signum, said(signum)), \
        done.stderr
    assert "Traceback" not in done.stderr
    assert "power-on: MC00 starts" in done.stdout and "Summary" in done.stdout
    assert vcd.read_text() == "old\n" and leftovers(tmp_path) == []


def test_sim_interactive_on_a_terminal_that_hangs_up_ends_with_129(tmp_path):
    """The terminal it put in cbreak mode is gone: putting it back cannot fail the run."""
    import pty

    log = tmp_path / "err.log"
    master, slave = pty.openpty()
    with open(log, "w") as err:
        proc = subprocess.Popen([sys.executable, "-m", "mercmac", "sim", str(EXAMPLE4),
                                 "--interactive"],
                                stdin=slave, stdout=slave, stderr=err, cwd=tmp_path,
                                env={**os.environ, "PYTHONPATH": str(ROOT), "NO_COLOR": "1"},
                                preexec_fn=on_a_terminal(slave))
    os.close(slave)
    seen, end = b"", time.monotonic() + 30
    while b"keys 1-4" not in seen and time.monotonic() < end:  # the box is up: it runs
        if select.select([master], [], [], 0.1)[0]:
            seen += os.read(master, 65536)
    assert b"keys 1-4" in seen, seen
    os.close(master)  # the terminal hangs up
    assert proc.wait(timeout=20) == 128 + signal.SIGHUP, log.read_text()
    assert log.read_text().splitlines() == said(signal.SIGHUP)


@pytest.mark.parametrize("module", ["mercmac.cli", "mercmac.compiler"])
def test_a_signal_the_program_was_started_ignoring_stays_ignored(module, tmp_path):
    """`nohup mercmac ...` ignores SIGHUP (and `mercmac ... &` in a script, SIGINT): the
    command goes on to its end, from the entry point on and inside its work."""
    ignoring = "signal.signal(signal.SIGHUP, signal.SIG_IGN); " + STARTS["script"]
    code = STARTED.format(module=module, signum=int(signal.SIGHUP), start=ignoring,
                          tell="; print('signalled')", args=["check", str(EXAMPLE4)])
    done = run(code, tmp_path)
    assert done.returncode == 0 and "0 errors, 3 warnings" in done.stdout, done.stderr
    assert done.stdout.startswith("signalled\n")
