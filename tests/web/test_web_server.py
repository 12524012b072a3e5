"""`sim --web`'s server and live session, through real HTTP on 127.0.0.1.

- Only requests with the session's token and this server's Host are answered; every answer
  carries the strict Content-Security-Policy.
- The event stream gives the state the page draws (LEDs, buttons, position, macro).
- A session saved as a scenario replays to the same state on the command line: the manual's
  Example 4, button 3 held at power-on (mode 3), then button 1 pressed.
- The command as a process prints the address and stops on Ctrl-C with exit 130.
"""
from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
import urllib.error
import urllib.request

from helpers.paths import EXAMPLE4, FOUR_MODES, ROOT
from mercmac.web.server import CSP, WebServer

WAIT_S = 30.0
RASTER_RIG = ROOT / "examples" / "rigs" / "raster" / "raster.rig.toml"




def _get(server: WebServer, path: str, *, token: bool = True, host: str | None = None):
    url = f"http://127.0.0.1:{server.port}{path}"
    if token:
        url += ("&" if "?" in path else "?") + f"token={server.token}"
    request = urllib.request.Request(url, headers={"Host": host} if host else {})
    try:
        with urllib.request.urlopen(request, timeout=WAIT_S) as answer:
            return answer.status, dict(answer.headers), answer.read()
    except urllib.error.HTTPError as e:
        return e.code, dict(e.headers), e.read()


def _post(server: WebServer, action: str, body: dict, token: str | None = None) -> int:
    request = urllib.request.Request(
        f"http://127.0.0.1:{server.port}/api/{action}", data=json.dumps(body).encode(),
        method="POST", headers={"Content-Type": "application/json",
                                "X-Mercmac-Token": server.token if token is None else token})
    try:
        with urllib.request.urlopen(request, timeout=WAIT_S) as answer:
            return answer.status
    except urllib.error.HTTPError as e:
        return e.code


def test_only_the_token_and_this_host_are_answered(serve):
    server = serve(FOUR_MODES)
    status, headers, body = _get(server, "/")
    assert status == 200 and headers["Content-Security-Policy"] == CSP
    assert server.token.encode() in body  # the page's asset addresses carry it
    assert _get(server, "/", token=False)[0] == 403
    assert _get(server, "/static/app.js", token=False)[0] == 403
    assert _get(server, "/?token=wrong", token=False)[0] == 403
    # a DNS-rebinding page reaches 127.0.0.1 under its own name: refused
    assert _get(server, "/", host=f"evil.example:{server.port}")[0] == 403
    assert _post(server, "power", {}, token="wrong") == 403
    assert _post(server, "press", {"controller": "four-modes", "button": 9, "down": True}) == 400
    assert _post(server, "launch", {}) == 400


def _first_state(server: WebServer) -> dict:
    url = f"http://127.0.0.1:{server.port}/api/events?token={server.token}"
    with urllib.request.urlopen(url, timeout=WAIT_S) as stream:
        assert stream.headers["Content-Type"].startswith("text/event-stream")
        for line in stream:
            if line.startswith(b"data: "):
                return json.loads(line[6:])
    raise AssertionError("the stream ended without a state")


def test_the_stream_gives_what_the_page_draws(serve):
    server = serve(FOUR_MODES)
    state = _first_state(server)
    (controller,) = state["controllers"]
    assert controller["model"] == "C-863" and controller["unit"] == "counts"
    assert len(controller["leds"]) == len(controller["buttons"]) == 4
    assert isinstance(controller["position"], int) and controller["macro"]
    assert controller["joystick"] is not None  # a lone program has the joystick on it


def test_a_rig_shows_every_controller_and_its_wires(serve):
    state = _first_state(serve(RASTER_RIG))
    assert [c["name"] for c in state["controllers"]] == ["x", "y"]
    assert {(w["from"], w["to"]) for w in state["wires"]} == {("x.out1", "y.in1"),
                                                              ("y.out2", "x.in2")}
    x = state["controllers"][0]
    assert x["pressable"] == [True, False, True, False]  # in2 is wired from y, 4 is not the box's


def _until(probe, what: str) -> None:
    deadline = time.monotonic() + WAIT_S
    while not probe():
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.02)


def test_a_session_saved_as_a_scenario_replays_on_the_command_line(serve, tmp_path):
    """Example 4: button 3 held at power-on chooses mode 3; button 1 then steps the stage."""
    server = serve(EXAMPLE4, speed=20.0)
    live = server.live
    name = next(iter(live.sim.machines))
    assert _post(server, "press", {"controller": name, "button": 3, "down": True}) == 204
    _until(lambda: live.sim.now_ms() > 50 or live.advance(), "the press")
    assert _post(server, "power", {}) == 204
    start = live.power_ms
    _until(lambda: live.advance() or live.sim.now_ms() > start + 400, "mode 3 to start")
    assert _post(server, "press", {"controller": name, "button": 3, "down": False}) == 204
    _until(lambda: live.advance() or live.sim.now_ms() > start + 900, "a while")
    assert _post(server, "press", {"controller": name, "button": 1, "down": True}) == 204
    _until(lambda: live.advance() or live.sim.now_ms() > start + 1500, "the step")
    assert _post(server, "press", {"controller": name, "button": 1, "down": False}) == 204
    _until(lambda: live.advance() or live.sim.now_ms() > start + 2500, "the end")
    status, _, body = _get(server, "/api/scenario")
    assert status == 200
    scenario = tmp_path / "session.toml"
    scenario.write_bytes(body)
    text = body.decode()
    assert re.search(r'at = "0ms"\npress = \[3\]', text), text  # held at power-on
    assert "position = " in text and "outputs = " in text and "macro = " in text
    done = subprocess.run([sys.executable, "-m", "mercmac", "sim", str(EXAMPLE4),
                           "--scenario", str(scenario)], capture_output=True, text=True,
                          timeout=120, stdin=subprocess.DEVNULL)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]


def test_the_command_prints_its_address_and_stops_on_ctrl_c():
    process = subprocess.Popen([sys.executable, "-m", "mercmac", "sim", str(FOUR_MODES), "--web",
                                "--no-open"], stderr=subprocess.PIPE, stdout=subprocess.DEVNULL,
                               stdin=subprocess.DEVNULL, text=True,
                               env={**os.environ, "DISPLAY": ""})
    try:
        line = process.stderr.readline()
        url = re.search(r"http://127\.0\.0\.1:\d+/\?token=[\w-]+", line)
        assert url, line
        with urllib.request.urlopen(url.group(), timeout=WAIT_S) as page:
            assert page.status == 200
        process.send_signal(signal.SIGINT)
        assert process.wait(timeout=WAIT_S) == 130
    finally:
        process.kill()
        process.wait()
    assert "Traceback" not in process.stderr.read()


def test_an_editor_that_goes_takes_the_process_with_it():
    """--stop-when-stdin-closes: the extension starts `sim --web` on a pipe, which ends
    however the editor goes (a crash runs no clean-up): the process stops then."""
    process = subprocess.Popen([sys.executable, "-m", "mercmac", "sim", str(FOUR_MODES), "--web",
                                "--no-open", "--stop-when-stdin-closes"], stdin=subprocess.PIPE,
                               stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True,
                               env={**os.environ, "DISPLAY": ""})
    try:
        assert "http://127.0.0.1:" in process.stderr.readline()
        time.sleep(0.5)
        assert process.poll() is None  # an open pipe keeps it serving
        process.stdin.close()
        assert process.wait(timeout=WAIT_S) == 0
    finally:
        process.kill()
        process.wait()
    said = process.stderr.read()
    assert "standard input closed: stopped" in said and "Traceback" not in said


def test_a_scenario_is_saved_at_a_whole_millisecond(tmp_path):
    """Motion goes on within a millisecond: a scenario saved while the clock stood between two
    expected a position the replay never has at a whole one."""
    from helpers.web import simulation
    from mercmac.web.live import Live

    live = Live(simulation(EXAMPLE4), EXAMPLE4.name)
    name = next(iter(live.sim.machines))
    live.press(name, 3, True)
    live.sim.run_until(20)
    live.power_cycle()
    live.sim.run_until(live.sim.now_ms() + 250.5)  # inside the first move of mode 3
    scenario = tmp_path / "between.toml"
    scenario.write_text(live.scenario(), encoding="utf-8")
    assert live.sim.now_ms() == round(live.sim.now_ms())
    done = subprocess.run([sys.executable, "-m", "mercmac", "sim", str(EXAMPLE4), "--scenario",
                           str(scenario)], capture_output=True, text=True, timeout=120,
                          stdin=subprocess.DEVNULL)
    assert done.returncode == 0, done.stdout[-1500:]


def test_options_the_page_replaces_are_refused_with_web():
    for option in (["--buttons", "1@0-1s"], ["--interactive"], ["--speed", "1000"],
                   ["--until", "5s"], ["--joystick", "X=1@0-1s"], ["--format", "json"]):
        done = subprocess.run([sys.executable, "-m", "mercmac", "sim", str(FOUR_MODES), "--web",
                               "--no-open", *option], capture_output=True, text=True,
                              timeout=60, stdin=subprocess.DEVNULL)
        assert done.returncode == 2, (option, done.stderr)
        assert "--web" in done.stderr and "Traceback" not in done.stderr, done.stderr


def test_web_options_without_web_are_refused():
    for option in (["--port", "8123"], ["--no-open"], ["--stop-when-stdin-closes"]):
        done = subprocess.run([sys.executable, "-m", "mercmac", "sim", str(FOUR_MODES), *option],
                              capture_output=True, text=True, timeout=60,
                              stdin=subprocess.DEVNULL)
        assert done.returncode == 2 and "is for --web" in done.stderr, (option, done.stderr)


def test_hold_chooses_the_mode_at_power_on_and_is_in_the_scenario(tmp_path):
    """`--hold 3` with --web holds button 3 at power-on, as --interactive does: Example 4's
    mode 3, and the saved scenario presses it at 0 ms."""
    from helpers.web import simulation
    from mercmac.web.live import Live

    sim = simulation(EXAMPLE4)
    name = next(iter(sim.machines))
    live = Live(sim, EXAMPLE4.name, held={name: (3,)})
    live.sim.run_until(600)
    assert live.sim.machines[name].position() < 0  # mode 3 steps the stage back
    text = live.scenario()
    assert re.search(r'at = "0ms"\npress = \[3\]', text), text
    scenario = tmp_path / "held.toml"
    scenario.write_text(text, encoding="utf-8")
    done = subprocess.run([sys.executable, "-m", "mercmac", "sim", str(EXAMPLE4), "--scenario",
                           str(scenario)], capture_output=True, text=True, timeout=120,
                          stdin=subprocess.DEVNULL)
    assert done.returncode == 0, done.stdout[-1500:]
