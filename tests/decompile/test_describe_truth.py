"""`describe` tells the whole of what a program does: a pulse with its end, an abort as no
mode, a controller without the box in its own words, the soft limit that stops a jog, and
how long a loop's pass takes (so how long a button must be held). One unit per model
(MS176E §1.2): steps on a C-663 in describe, the timeline and the plot alike."""
from __future__ import annotations

import json
import re

from helpers.cli import cli
from helpers.paths import EXAMPLE4, ROOT
from mercmac.decompile import describe, read_macros
from mercmac.decompile.prose import described

CAMERA = """\
target C-863
autostart { SV 20000, CP 0, goto idle }
macro idle {
    every 20ms {
        when 1 { goto scan }
        when 3 { goto stop }
    }
}
macro scan {
    repeat 10 {
        MR 2000, WS 50
        CN 4, WA 10, CF 4
    }
    goto idle
}
macro stop { AB 1 }
"""


def _describe(tmp_path, text: str, *args: str) -> str:
    path = tmp_path / "p.mcm"
    path.write_text(text)
    result = cli("describe", path, *args)
    assert result.exit_code == 0, result.output
    return result.stdout


def test_a_pulse_is_said_with_its_end(tmp_path):
    text = _describe(tmp_path, CAMERA)
    assert "scan (MC02): LED 4 on for 10 ms, then off again (a pulse)" in text


def test_an_abort_is_a_stop_chosen_by_a_button_not_a_mode(tmp_path):
    text = _describe(tmp_path, CAMERA)
    modes = text.split("Modes chosen by buttons:")[1].split("\n\n")[0]
    assert "scan (MC02)" in modes and "stop (MC03)" not in modes
    assert ("stop (MC03): while button 3 is held (through idle.when@6 (MC05)), stop smoothly; "
            "then the program ends (direct mode)") in text
    data = json.loads(_describe(tmp_path, CAMERA, "--format", "json"))
    assert [m["name"] for m in data["modes"]] == ["scan"]
    assert [m["name"] for m in data["ends"]] == ["stop"]


def test_a_jog_says_the_soft_limit_that_stops_it(tmp_path):
    text = _describe(tmp_path, "target C-663\nautostart { JL -20000, JH 20000, goto jog }\n"
                               "macro jog { every 20ms { when 1 { MR 9999999, WF 1, AB 1 } "
                               "when 2 { MA -50000 } } }\n")
    assert "move +9,999,999 steps (a jog: the upper soft limit, 20,000, stops it)" in text
    assert "move to position -50,000 (the lower soft limit stops it at -20,000)" in text


def test_a_loop_says_how_long_its_pass_takes_as_the_simulator_runs_it():
    """Example 4's mode 2 (MC20): the simulator skips its passes at 111 ms each."""
    loops = {x["slot"]: x["pass_ms"] for x in described(read_macros(EXAMPLE4.read_text()))["loops"]}
    assert loops[20] == 111
    scenario = ROOT / "examples" / "scenarios" / "manual-example4-four-modes.mode2.toml"
    run = cli("sim", EXAMPLE4, "--scenario", scenario)
    assert "passes of MC20 (111 ms each)" in run.stdout
    text = describe(read_macros(EXAMPLE4.read_text()))
    assert ("MC20 (mode_2): every 100 ms; a pass takes 111 ms with nothing held, so a button "
            "must be held at least that long to be seen") in text


def test_a_controller_without_the_box_has_inputs_and_outputs(tmp_path):
    rig = ROOT / "examples" / "rigs" / "raster" / "raster.rig.toml"
    text = cli("describe", rig).stdout
    y = text.split("y, address 1")[1].split("\nWires:")[0]
    assert "LED" not in y and "button" not in y
    assert "all outputs off" in y and "Outputs:" in y
    x = text.split("x, address 0")[1].split("y, address 1")[0]
    assert "LEDs:" in x and "button 1 is held" in x  # the box is on x


def test_one_unit_per_model_in_describe_timeline_and_plot(tmp_path):
    """A C-663 program said in steps everywhere: describe's title, the timeline's steady
    fast-forward, the plot's position axis."""
    text = "target C-663\nautostart { every 20ms { MR 25000 } }\n"
    assert "distances in steps" in _describe(tmp_path, text)
    path = tmp_path / "p.mcm"
    run = cli("sim", path, "--until", "50s")
    assert re.search(r"the target \+25,000 steps further each", run.stdout), run.stdout
    assert "counts" not in run.stdout
    plotted = cli("sim", path, "--until", "50s", "--plot", tmp_path / "p.html")
    assert plotted.exit_code == 0 and '"unit":"steps"' in (tmp_path / "p.html").read_text()
