"""`sim --interactive` driven through a real pseudo-terminal: keys press buttons, LEDs follow."""
from __future__ import annotations

import os
import pty
import select
import subprocess
import sys
import time

import pytest

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="needs a POSIX pty")


class Terminal:
    """A child process on the slave side of a pty; we read and type on the master side."""

    def __init__(self, *args: str):
        self.master, slave = pty.openpty()
        env = dict(os.environ, NO_COLOR="1")
        self.proc = subprocess.Popen([sys.executable, "-m", "mercmac", *args], stdin=slave,
                                     stdout=slave, stderr=slave, env=env, close_fds=True)
        os.close(slave)
        self.seen = ""

    def expect(self, text: str, timeout: float = 10.0) -> str:
        """Read until `text` appears in what the screen received since the last expect."""
        deadline = time.monotonic() + timeout
        while text not in self.seen:
            left = deadline - time.monotonic()
            if left <= 0:
                raise AssertionError(f"never saw {text!r}; got {self.seen[-400:]!r}")
            ready, _, _ = select.select([self.master], [], [], left)
            if ready:
                try:
                    self.seen += os.read(self.master, 4096).decode(errors="replace")
                except OSError:  # the child closed the pty
                    break
        assert text in self.seen, f"never saw {text!r}; got {self.seen[-400:]!r}"
        found, self.seen = self.seen, self.seen[self.seen.index(text) + len(text):]
        return found

    def type(self, keys: str) -> None:
        os.write(self.master, keys.encode())

    def close(self) -> int:
        code = self.proc.wait(timeout=10)
        os.close(self.master)
        return code


def test_keys_press_and_release_buttons_and_leds_follow(tmp_path):
    program = tmp_path / "box.mcm"
    # each button lights its LED while held; the loop polls every 10 ms
    program.write_text("[MC00] EM1,EM2,WA10,RP,RP\n[MC01] XN1,CN1,WF1,CF1\n"
                       "[MC02] XN2,CP6,MR500,WF2,CP0\n")
    term = Terminal("sim", str(program), "--interactive", "--speed", "1")
    term.expect("keys 1-4")
    term.expect("LEDs ○○○○")
    term.type("1")
    term.expect("button 1 pressed")
    term.expect("LEDs ●○○○  buttons [1]")
    term.type("1")
    term.expect("button 1 released")
    term.expect("LEDs ○○○○")
    term.type("2")
    term.expect("LEDs ○●●○")
    term.expect("move to 500")
    term.type("2")
    term.expect("button 2 released")
    term.expect("position         500")
    term.expect("MC00")
    term.type("q")
    assert term.close() == 0


def test_speed_factor_runs_simulated_time_faster(tmp_path):
    program = tmp_path / "slow.mcm"
    program.write_text("[MC00] WA5000,CN4\n")  # 5 s of simulated time
    term = Terminal("sim", str(program), "--interactive", "--speed", "20")
    started = time.monotonic()
    term.expect("LEDs ○○○●", timeout=5)
    assert time.monotonic() - started < 4.5  # 0.25 s of wall time at x20, with start-up
    term.expect("direct mode")
    term.type("q")
    assert term.close() == 0


def test_interactive_refuses_without_a_terminal(tmp_path):
    program = tmp_path / "p.mcm"
    program.write_text("[MC00] TP\n")
    done = subprocess.run([sys.executable, "-m", "mercmac", "sim", str(program), "--interactive"],
                          stdin=subprocess.DEVNULL, capture_output=True, text=True, timeout=30)
    assert done.returncode == 2 and "needs a terminal" in done.stderr
