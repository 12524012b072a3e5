"""What the page of `sim --web` is told as the simulation runs (mercmac/web/live.py), and
the file followed on disk (mercmac/web/watch.py):

- a hazard is marked in the timeline and stays on its controller's card until power-on;
- the stage's reference switch and hard limit switches where the axis counts, and the one
  pressed;
- a rig with two axes draws its XY path, in the order of the rig's path axes;
- a saved change reloads the program (the buttons held stay held); a change with errors
  lists them as `check` words them and the last good program keeps running; a rig follows
  its programs too; and `sim --web` as a process does all this.
"""
from __future__ import annotations

import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
import urllib.request

from helpers.paths import FOUR_MODES, ROOT
from helpers.web import simulation
from mercmac.vm.models import Options
from mercmac.web.live import Live

RASTER = ROOT / "examples" / "rigs" / "raster"
WAIT_S = 30.0
CLAMPED = """\
autostart {
    JL -20000, JH 20000
    MA 50000
}
"""


def _run(live: Live, ms: float) -> None:
    """Run the live simulation on by `ms` of simulated time, as the page's clock would."""
    goal = live.sim.now_ms() + ms
    live.set_speed(None)
    while live.sim.now_ms() < goal:
        live.advance()


def test_a_hazard_is_marked_and_stays_on_its_card_until_power_on(tmp_path):
    path = tmp_path / "clamped.mcm"
    path.write_text(CLAMPED, encoding="utf-8")
    live = Live(simulation(path), path.name)
    _run(live, 200)
    state, _ = live.state()
    hazards = [text for text, kind in state["log"] if kind == "hazard"]
    assert len(hazards) == 1 and "soft-limit-clamp" in hazards[0], state["log"]
    (card,) = state["controllers"]
    assert card["hazard"].startswith("soft-limit-clamp: ")
    live.power_cycle()
    assert live.state()[0]["controllers"][0]["hazard"] is None


def test_the_stage_shows_its_switches_and_the_one_pressed(tmp_path):
    path = tmp_path / "far.mcm"
    path.write_text("autostart {\n    MA 9000\n}\n", encoding="utf-8")
    live = Live(simulation(path, Options(reference_at=300, hard_limits=(-1000, 1000))),
                path.name)
    card = live.state()[0]["controllers"][0]
    assert (card["reference"], card["referenced"]) == (300, False)
    assert (card["limit_switches"], card["at_limit"]) == ([-1000, 1000], None)
    _run(live, 5000)
    card = live.state()[0]["controllers"][0]
    assert card["at_limit"] == "positive" and card["position"] >= 1000


def test_a_rig_draws_its_xy_path_as_it_goes():
    live = Live(simulation(RASTER / "raster.rig.toml"), "raster.rig.toml")
    box = live.sim.rig.box
    live.press(box, 1, True)
    _run(live, 300)
    live.press(box, 1, False)
    _run(live, 8000)
    state, (_, seen) = live.state()
    assert list(state["path_axes"]) == ["x", "y"]
    xs = {x for x, _ in state["path"]}
    ys = {y for _, y in state["path"]}
    assert len(xs) > 10 and len(ys) > 1, state["path"][:20]  # rows across, stepped up
    assert seen == len(state["path"])
    _run(live, 200)
    later, _ = live.state((0, seen))  # a page that has seen them gets only the new ones
    assert len(later["path"]) < len(state["path"])


def _started(tmp_path, name: str) -> tuple[subprocess.Popen, str]:
    process = subprocess.Popen([sys.executable, "-m", "mercmac", "sim", str(tmp_path / name),
                                "--web", "--no-open", "--speed", "10"], stderr=subprocess.PIPE,
                               stdout=subprocess.DEVNULL, stdin=subprocess.DEVNULL, text=True,
                               env={**os.environ, "DISPLAY": ""})
    line = process.stderr.readline()
    url = re.search(r"http://127\.0\.0\.1:(\d+)/\?token=([\w-]+)", line)
    assert url, line
    return process, f"http://127.0.0.1:{url.group(1)}/api/events?token={url.group(2)}"


def _states(events: str):
    """The states of the event stream, each with the timeline so far."""
    log = []
    with urllib.request.urlopen(events, timeout=WAIT_S) as stream:
        for line in stream:
            if line.startswith(b"data: "):
                state = json.loads(line[6:])
                log += state["log"]
                yield state, log


def _until(states, probe, what: str) -> dict:
    deadline = time.monotonic() + WAIT_S
    for state, log in states:
        if probe(state, log):
            return state
        assert time.monotonic() < deadline, f"timed out waiting for {what}: {log[-5:]}"
    raise AssertionError(f"the stream ended before {what}")


def _check_text(path) -> str:
    return subprocess.run([sys.executable, "-m", "mercmac", "check", str(path)],
                          capture_output=True, text=True, timeout=120,
                          stdin=subprocess.DEVNULL, env={**os.environ, "NO_COLOR": "1"}).stdout


def test_the_process_follows_saves_and_keeps_the_last_good_program(tmp_path):
    shutil.copy(FOUR_MODES, tmp_path / "four-modes.mcm")
    path = tmp_path / "four-modes.mcm"
    good = path.read_text(encoding="utf-8")
    process, events = _started(tmp_path, "four-modes.mcm")
    try:
        states = _states(events)
        first = _until(states, lambda s, log: s["t_ms"] > 300, "the program to run")
        path.write_text(good.replace("SV ", "SVX ", 1), encoding="utf-8")
        broken = _until(states, lambda s, log: s["problems"], "the problems")
        assert broken["t_ms"] >= first["t_ms"]  # the last good program kept running
        _until(states, lambda s, log: s["problems"] and s["t_ms"] > broken["t_ms"] + 200,
               "the last good program to run on")
        shown = _check_text(path)
        for problem in broken["problems"]:  # each as check words it, caret and all
            assert problem in shown, (problem, shown)
        assert ": error[" in broken["problems"][0] and "SVX" in broken["problems"][0]
        path.write_text(good, encoding="utf-8")
        fixed = _until(states, lambda s, log: not s["problems"] and any(
            "reloaded" in text for text, kind in log if kind == "note"), "the reload")
        assert fixed["controllers"][0]["macro"]
    finally:
        process.send_signal(signal.SIGINT)
        assert process.wait(timeout=WAIT_S) == 130
    assert "Traceback" not in process.stderr.read()


def test_a_rig_follows_its_programs(tmp_path):
    shutil.copytree(RASTER, tmp_path / "raster")
    process, events = _started(tmp_path / "raster", "raster.rig.toml")
    program = next((tmp_path / "raster").glob("*.mcm"))
    try:
        states = _states(events)
        _until(states, lambda s, log: s["t_ms"] > 100, "the rig to run")
        program.write_text(program.read_text(encoding="utf-8") + "\nmacro stray {\n  FOO 1\n}\n",
                           encoding="utf-8")
        broken = _until(states, lambda s, log: s["problems"], "the program's problems")
        assert program.name in broken["problems"][0] and "FOO" in broken["problems"][0]
    finally:
        process.send_signal(signal.SIGINT)
        assert process.wait(timeout=WAIT_S) == 130


def test_a_reload_keeps_the_buttons_held_and_the_timeline(tmp_path):
    path = tmp_path / "four-modes.mcm"
    shutil.copy(FOUR_MODES, path)
    live = Live(simulation(path), path.name)
    name = next(iter(live.sim.machines))
    live.press(name, 3, True)
    _run(live, 50)
    before = live.state()[0]["log"]
    live.reload(simulation(path))
    assert live.sim.now_ms() == 0 and live.sim.machines[name].input(3)
    assert [(c.at_ms, c.button, c.down) for c in live.changes] == [(0, 3, True)]
    log = live.state()[0]["log"]
    assert log[:len(before)] == before  # the timeline goes on
    assert any("reloaded" in text for text, kind in log[len(before):] if kind == "note")
