"""Run `mercmac` in-process through the real click group, or as a process."""
from __future__ import annotations

import os
import signal
import subprocess
import sys
from contextlib import contextmanager
from pathlib import Path

from click.testing import CliRunner

KNOWN_EXITS = {0, 1, 2}  # mercmac's exit codes: clean, failed checks, usage or I/O
HANG_S = 20  # wall seconds one command may take before it counts as a hang


def cli(*args, catch: bool = False, **kw):
    """Run `mercmac ARGS...` in-process through the real click group; with `catch`, an
    exception is kept in the result (so a traceback shows as one) instead of raised."""
    from mercmac.cli import main

    return CliRunner().invoke(main, [str(a) for a in args], catch_exceptions=catch, **kw)


def sim(*args):
    """`mercmac sim ARGS...` in-process; an exception is kept in the result."""
    return cli("sim", *args, catch=True)


def mercmac_process(*args: str, cwd):
    """`python -m mercmac ARGS` with the mercmac this test imports (not the one in cwd)."""
    import mercmac

    env = {**os.environ, "PYTHONPATH": str(Path(mercmac.__file__).parents[1])}
    return subprocess.run([sys.executable, "-m", "mercmac", *args], capture_output=True,
                          text=True, cwd=cwd, env=env, timeout=60)


@contextmanager
def hang_guard(seconds: int = HANG_S):
    """Raise in the command if it runs longer than `seconds` (POSIX alarm)."""
    def on_alarm(signum, frame):
        raise TimeoutError(f"hang: no end after {seconds} s")

    old = signal.signal(signal.SIGALRM, on_alarm)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def on_a_terminal(slave: int):
    """Popen's preexec_fn: the child leads a session whose controlling terminal is the pty
    SLAVE, so that closing the master hangs it up and the kernel sends the child SIGHUP, as
    when an ssh connection drops (POSIX)."""
    def become() -> None:
        import fcntl
        import termios

        os.setsid()
        fcntl.ioctl(slave, termios.TIOCSCTTY, 0)
    return become


def as_nobody() -> list[str]:
    """The words that run a command as `nobody` (uid 65534) when the tests run as root (root
    reads any file, so an unreadable one needs another user); skips the test, saying why,
    where no user can be dropped to or this interpreter cannot start as that user (a Python
    whose shared library lies in root's home, as pyenv's 3.10 does)."""
    import pytest

    if os.geteuid() != 0:
        return []
    setpriv = "/usr/bin/setpriv"
    if not os.path.exists(setpriv):
        pytest.skip("root, and no setpriv to drop privileges")
    prefix = [setpriv, "--reuid=65534", "--regid=65534", "--clear-groups"]
    probe = subprocess.run([*prefix, sys.executable, "-c", "pass"], capture_output=True,
                           text=True, timeout=60, cwd="/")
    if probe.returncode != 0:
        pytest.skip(f"{sys.executable} does not start as nobody: "
                    f"{probe.stderr.strip()[:200]}")
    return prefix
