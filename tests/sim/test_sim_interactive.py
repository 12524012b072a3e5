"""`sim --interactive` driven through a real pseudo-terminal: keys press buttons, LEDs follow."""
from __future__ import annotations

import subprocess
import sys
import time

import pytest

from helpers.paths import EXAMPLE4
from helpers.terminal import Terminal

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="needs a POSIX pty")


@pytest.mark.slow
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
    term.expect("power-on in")
    term.type("\r")  # Enter ends the count-down: power on now
    term.expect("LEDs ○○○○")
    started = time.monotonic()
    term.expect("LEDs ○○○●", timeout=5)
    assert time.monotonic() - started < 3  # 0.25 s of wall time at x20
    term.expect("direct mode")
    term.type("q")
    assert term.close() == 0


def test_interactive_refuses_without_a_terminal(tmp_path):
    program = tmp_path / "p.mcm"
    program.write_text("[MC00] TP\n")
    done = subprocess.run([sys.executable, "-m", "mercmac", "sim", str(program), "--interactive"],
                          stdin=subprocess.DEVNULL, capture_output=True, text=True, timeout=30)
    assert done.returncode == 2 and "needs a terminal" in done.stderr


def test_hold_at_power_on_selects_mode_2_of_example_4_reset_and_summary():
    # MS176E §3.8.6 Example 4: button 2 held at power-on selects mode 2 (MC12 -> MC20);
    # still held, it moves to 50,000 with LED 2 (MC22) until it is released
    term = Terminal("sim", EXAMPLE4, "--interactive", "--hold", "2", "--speed", "5")
    term.expect("r: reset")
    assert "power-on in" not in term.seen  # --hold decides: no count-down
    term.expect("button 2 pressed")
    term.expect("move to 50000")
    status = term.expect("running MC22")
    assert "LEDs ○●○○  buttons  1  [2]" in status
    term.expect("position       50000  target       50000  running MC22")
    term.type("2")  # released: MC22 returns, MC20 polls the buttons
    term.expect("button 2 released")
    term.expect("running MC2")
    term.type("r")  # power-on again, like RT: button 2 no longer held -> not mode 2
    term.expect("reset: power-on again")
    term.expect("running MC0")
    term.type("q")
    summary = term.expect("hazards")
    assert "Summary: ran to" in summary and "position" in summary
    assert term.close() == 0


@pytest.mark.slow
def test_a_key_during_the_count_down_is_held_at_power_on():
    term = Terminal("sim", EXAMPLE4, "--interactive", "--speed", "5")
    term.expect("power-on in")
    term.type("2")
    term.expect("held: [2]")
    term.expect("move to 50000")  # mode 2 chosen at power-on, as with --hold 2
    term.expect("running MC22")
    term.type("2r")  # release, then reset: the program starts again without a mode button
    term.expect("reset: power-on again")
    term.type("q")
    term.expect("Summary")
    assert term.close() == 0


def test_q_in_the_count_down_quits_with_a_summary(tmp_path):
    program = tmp_path / "p.mcm"
    program.write_text("[MC00] CN1\n")
    term = Terminal("sim", str(program), "--interactive")
    term.expect("power-on in")
    term.type("q")
    term.expect("no macro ran")
    assert term.close() == 0


def test_fail_on_hazard_applies_to_the_box(tmp_path):
    program = tmp_path / "p.mcm"
    program.write_text("[MC00] MA1000\n")
    term = Terminal("sim", str(program), "--interactive", "--servo-off", "--fail-on-hazard",
                    "--hold", "1")
    term.expect("hazard move-servo-off")
    term.type("q")
    term.expect("1 hazard")
    assert term.close() == 1
