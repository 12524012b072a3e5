"""`sim RIG --interactive`: the live box on the rig's box controller, through a
real pseudo-terminal, with every controller on the clock: X's LED 1 goes off only when Y
answered over the wire."""
from __future__ import annotations

import sys

import pytest

from helpers.cli import sim
from helpers.rigs import RASTER, rig_of
from helpers.terminal import Terminal

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="needs a POSIX pty")


@pytest.mark.slow
def test_the_box_on_x_starts_the_scan_and_y_answers_over_the_wire():
    term = Terminal("sim", str(RASTER), "--interactive", "--speed", "20", "--hold", "1")
    term.expect("keys 1-4")
    term.expect("LEDs ●○○○")  # X swept a line and raised out1 ...
    term.expect("LEDs ○○○○")  # ... and took it back once Y had stepped and raised out2
    term.type("q")
    term.expect("Summary")
    assert term.close() == 0


def test_a_rig_without_a_box_has_no_interactive_box(tmp_path):
    path = rig_of(tmp_path, "autostart { CN 1 }\n", "autostart { CN 1 }\n", "")
    result = sim(path, "--interactive")
    assert result.exit_code == 2 and "box = " in result.output


@pytest.mark.slow
def test_keys_of_inputs_the_box_cannot_press_do_nothing(tmp_path):
    """The box on x has buttons 1 and 3 connected, and x.in2 is y's wire:
    keys 2 and 4 leave those lines alone (a key 2 used to mix with the wire's level)."""
    path = rig_of(tmp_path, "autostart { WA 10 }\n", "autostart { CN 1 }\n",
                  '"y.out2 -> x.in2"', 'box = "x"\nbox_buttons = [1, 3]\n')
    term = Terminal("sim", str(path), "--interactive", "--hold", "1")
    term.expect("keys 1-4")
    term.type("1243")  # 1 lets go of the held button, 3 presses one that is connected
    term.expect("buttons  1   2  [3]  4 ")
    term.type("q")
    term.expect("Summary")
    assert term.close() == 0
