"""The page of `sim --web` in a real browser: Debian's chromium driven by playwright.

- The manual's Example 4: button 3 held at power-on (mode 3), then button 1 held with the
  mouse; the page shows the LEDs, position and macro the simulation has, and the session
  saved from the page's "save as scenario" passes on the command line.
- The raster rig: the box on x starts the scan, and y steps.
- The page asks nothing of any host but 127.0.0.1 and logs no console error.

Skipped, saying why, without playwright (the test extra) or chromium (`apt-get install
chromium`, which the fixture runs when it may).
"""
from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import sys
import time

import pytest

from helpers.locking import held, lock_file
from helpers.paths import EXAMPLE4, ROOT

sync_api = pytest.importorskip("playwright.sync_api", reason="the test extra installs playwright")
sync_api.expect.set_options(timeout=30_000)  # a busy machine: the suite's other workers
RASTER_RIG = ROOT / "examples" / "rigs" / "raster" / "raster.rig.toml"
WAIT_MS = 30_000
# chromium on a machine without a network: no calls home (see the e2e script of the editor)
FLAGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync"]


def _chromium() -> str:
    """Debian's chromium; installed with apt-get when it is missing and root may."""
    found = shutil.which("chromium")
    if found is None and shutil.which("apt-get") and hasattr(os, "getuid") and os.getuid() == 0:
        with held(lock_file(ROOT / "tests" / "web")):
            if shutil.which("chromium") is None:
                _apt_install("chromium")
        found = shutil.which("chromium")
    if found is None:
        pytest.skip("chromium is not installed (apt-get install chromium): the page is not "
                    "tested in a browser")
    return found


def _apt_install(package: str) -> None:
    """apt-get install, and once more after apt-get update (a fresh machine has no package
    lists), as the editor's e2e script does (editors/vscode/e2e/lib/tools.mjs)."""
    env = {**os.environ, "DEBIAN_FRONTEND": "noninteractive"}
    install = ["apt-get", "install", "-y", "-q", package]
    if subprocess.run(install, capture_output=True, timeout=900, env=env,
                      stdin=subprocess.DEVNULL).returncode != 0:
        subprocess.run(["apt-get", "update", "-q"], capture_output=True, timeout=900, env=env,
                       stdin=subprocess.DEVNULL)
        subprocess.run(install, capture_output=True, timeout=900, env=env,
                       stdin=subprocess.DEVNULL)


@pytest.fixture
def browser(tmp_path):
    with sync_api.sync_playwright() as driver:
        launched = driver.chromium.launch(executable_path=_chromium(), headless=True,
                                          args=FLAGS)
        try:
            yield launched
        finally:
            launched.close()


class Watched:
    """A page of the browser, with every request's host and every console error noted."""

    def __init__(self, browser, server):
        self.context = browser.new_context(accept_downloads=True)
        self.page = self.context.new_page()
        self.hosts: set[str] = set()
        self.errors: list[str] = []
        self.page.on("request", lambda r: self.hosts.add(r.url.split("/")[2]))
        self.page.on("console", lambda m: m.type == "error" and self.errors.append(m.text))
        self.page.on("pageerror", lambda e: self.errors.append(str(e)))
        self.page.set_default_timeout(WAIT_MS)
        self.page.goto(server.url)
        # the cards are drawn from the first state: a key pressed before would go nowhere
        self.page.locator("#conn[data-state=open]").wait_for()
        self.page.get_by_role("button", name=re.compile(r"button 1$")).first.wait_for()

    def named(self, name: str):
        return self.page.get_by_label(name, exact=True)

    def button(self, name: str):
        return self.page.get_by_role("button", name=name, exact=True)


def _wait_sim(server, ms: float) -> None:
    """Until the simulation has run `ms` past now (the page's stream drives the clock)."""
    goal = server.live.sim.now_ms() + ms
    deadline = time.monotonic() + WAIT_MS / 1000
    while server.live.sim.now_ms() < goal:
        assert time.monotonic() < deadline, "the simulation does not run"
        time.sleep(0.02)


def test_example_4_from_the_page_replays_on_the_command_line(browser, serve, tmp_path):
    server = serve(EXAMPLE4, speed=4.0)
    seen = Watched(browser, server)
    page = seen.page
    page.keyboard.down("3")  # held through the power cycle: macro 0 chooses mode 3
    sync_api.expect(seen.button("button 3")).to_have_attribute("aria-pressed", "true")
    seen.button("power cycle").click()
    _wait_sim(server, 600)
    page.keyboard.up("3")
    _wait_sim(server, 300)
    one = seen.button("button 1")
    one.hover()
    page.mouse.down()
    sync_api.expect(one).to_have_attribute("aria-pressed", "true")
    _wait_sim(server, 700)
    page.mouse.up()
    sync_api.expect(one).to_have_attribute("aria-pressed", "false")
    _wait_sim(server, 500)
    page.get_by_role("button", name="pause", exact=True).click()
    _wait_sim_stopped(server)
    machine = next(iter(server.live.sim.machines.values()))
    sync_api.expect(seen.named("position")).to_have_text(str(machine.position()))
    for n in range(1, 5):
        on = "true" if machine.outputs_pattern() >> (n - 1) & 1 else "false"
        sync_api.expect(seen.named(f"LED {n}")).to_have_attribute("data-on", on)
    with page.expect_download() as download:
        seen.button("save as scenario").click()
    scenario = tmp_path / "session.toml"
    download.value.save_as(scenario)
    assert "press = [3]" in scenario.read_text(encoding="utf-8")
    done = subprocess.run([sys.executable, "-m", "mercmac", "sim", str(EXAMPLE4), "--scenario",
                           str(scenario)], capture_output=True, text=True, timeout=120,
                          stdin=subprocess.DEVNULL)
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    assert seen.hosts == {f"127.0.0.1:{server.port}"}
    assert seen.errors == []


def _wait_sim_stopped(server) -> None:
    """Until the clock has stopped (paused: two looks a while apart agree)."""
    deadline = time.monotonic() + WAIT_MS / 1000
    while True:
        before = server.live.sim.now_ms()
        time.sleep(0.2)
        if server.live.sim.now_ms() == before and server.live.paused:
            return
        assert time.monotonic() < deadline, "the page did not pause the simulation"


def test_the_raster_rig_runs_from_the_box_on_x(browser, serve):
    server = serve(RASTER_RIG, speed=20.0)
    seen = Watched(browser, server)
    start = seen.button("x button 1")
    sync_api.expect(seen.button("x button 2")).to_have_attribute("aria-disabled", "true")
    start.hover()
    seen.page.mouse.down()
    _wait_sim(server, 200)
    seen.page.mouse.up()
    y = server.live.sim.machines["y"]
    deadline = time.monotonic() + WAIT_MS / 1000
    while y.position() == 0:  # x sweeps a line, then y steps a row
        assert time.monotonic() < deadline, "y never stepped"
        time.sleep(0.05)
    sync_api.expect(seen.named("y position")).not_to_have_text("0")
    assert seen.hosts == {f"127.0.0.1:{server.port}"}
    assert seen.errors == []


CLAMPED = """\
autostart {
    JL -20000, JH 20000
    SV 50000
    MA 50000
}
"""


def test_a_hazard_is_marked_on_the_card_and_in_the_timeline(browser, serve, tmp_path):
    path = tmp_path / "clamped.mcm"
    path.write_text(CLAMPED, encoding="utf-8")
    server = serve(path)
    seen = Watched(browser, server)
    warning = seen.named("hazard")
    sync_api.expect(warning).to_be_visible()
    sync_api.expect(warning).to_contain_text("soft-limit-clamp")
    sync_api.expect(seen.page.locator(".log-line.hazard")).to_have_count(1)
    seen.button("power cycle").click()
    sync_api.expect(warning).to_be_hidden()
    assert seen.errors == []


def test_a_save_with_an_error_is_shown_and_the_last_good_program_runs(browser, tmp_path):
    """`sim --web` as a process: the page lists the error of a saved change as `check` words
    it, goes on running, and drops the list when the file is fixed."""
    path = tmp_path / "four-modes.mcm"
    good = EXAMPLE4.read_text(encoding="utf-8")
    path.write_text(good, encoding="utf-8")
    process = subprocess.Popen([sys.executable, "-m", "mercmac", "sim", str(path), "--web",
                                "--no-open"], stderr=subprocess.PIPE, text=True,
                               stdin=subprocess.DEVNULL, env={**os.environ, "DISPLAY": ""})
    try:
        url = re.search(r"http://127\.0\.0\.1:\d+/\?token=[\w-]+", process.stderr.readline())
        assert url
        page = browser.new_page()
        page.set_default_timeout(WAIT_MS)
        page.goto(url.group())
        page.get_by_role("button", name="button 1", exact=True).wait_for()
        path.write_text(good + "\nmacro typo {\n    MX 5\n}\n", encoding="utf-8")
        problems = page.locator("#problems")
        sync_api.expect(problems).to_be_visible()
        sync_api.expect(problems).to_contain_text("error[MM002 unknown-command]: unknown command 'MX'")
        clock = page.get_by_label("simulated time")
        before = float(clock.text_content())
        sync_api.expect(clock).not_to_have_text(f"{before:.3f}")  # the last good one runs
        path.write_text(good, encoding="utf-8")
        sync_api.expect(problems).to_be_hidden()
        sync_api.expect(page.locator(".log-line.note", has_text="reloaded").first).to_be_visible()
    finally:
        process.send_signal(signal.SIGINT)
        assert process.wait(timeout=30) == 130
