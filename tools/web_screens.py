"""Screenshots of the page of `sim --web` for docs/: the manual's Example 4 in mode 3 with
button 1 held (web-box.png), the raster rig scanning (web-rig.png), a jog run into its soft
limit on a bench with limit switches (web-hazard.png), and a saved change with an error
while the last good program runs (web-problems.png).

    .venv/bin/python tools/web_screens.py [OUT_FOLDER]   (default: docs/)

Needs playwright (the test extra) and Debian's chromium.
"""
from __future__ import annotations

import re
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))
FLAGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync"]


def served(path: Path, speed: float, **bench):
    from helpers.web import simulation
    from mercmac.vm.models import Options
    from mercmac.web.live import Live
    from mercmac.web.server import WebServer

    server = WebServer(Live(simulation(path, Options(**bench)), path.name, speed=speed))
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server


def wait(server, ms: float) -> None:
    goal = server.live.sim.now_ms() + ms
    while server.live.sim.now_ms() < goal:
        time.sleep(0.02)


JOG = """\
// a focus jog: button 1 up, button 2 down, to the soft limits
target C-663
autostart {
    JL -20000, JH 20000
    SV 8000
    goto jog
}
macro jog {
    every 20ms {
        when 1 { MR 9999999, WF 1, AB 1 }
        when 2 { MR -9999999, WF 2, AB 1 }
    }
}
"""


def shot_held(page, server, button: str, ms: float, shot: Path) -> None:
    """The page after `button` has been held with the mouse for `ms` of simulated time;
    the server stopped then."""
    page.get_by_role("button", name=button, exact=True).hover()
    page.mouse.down()
    wait(server, ms)
    page.screenshot(path=str(shot))
    page.mouse.up()
    server.shutdown()


def problems(page, program: Path, shot: Path) -> None:
    """`sim --web` as a process on `program`; a save with a typo in it; the page then."""
    process = subprocess.Popen([sys.executable, "-m", "mercmac", "sim", str(program), "--web",
                                "--no-open"], stderr=subprocess.PIPE, text=True,
                               stdin=subprocess.DEVNULL)
    try:
        url = re.search(r"http://\S+", process.stderr.readline()).group()
        page.goto(url)
        page.get_by_role("button", name="button 1", exact=True).wait_for()
        time.sleep(1)
        good = program.read_text(encoding="utf-8")
        program.write_text(good.replace("SV 8000", "SV 8000, MX 5"), encoding="utf-8")
        page.locator("#problems:not([hidden])").wait_for()
        time.sleep(0.5)
        page.screenshot(path=str(shot))
    finally:
        process.send_signal(signal.SIGINT)
        process.wait(timeout=30)


def main() -> None:
    from playwright.sync_api import expect, sync_playwright

    out = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "docs"
    with sync_playwright() as driver:
        browser = driver.chromium.launch(executable_path="/usr/bin/chromium", args=FLAGS)
        page = browser.new_page(viewport={"width": 1280, "height": 860})
        box = served(ROOT / "examples" / "macros" / "manual-example4-four-modes.mcm", 2.0)
        page.goto(box.url)
        three = page.get_by_role("button", name="button 3", exact=True)
        three.wait_for()
        page.keyboard.down("3")
        expect(three).to_have_attribute("aria-pressed", "true")
        page.get_by_role("button", name="power cycle", exact=True).click()
        wait(box, 600)
        page.keyboard.up("3")
        wait(box, 300)
        shot_held(page, box, "button 1", 1500, out / "web-box.png")
        rig = served(ROOT / "examples" / "rigs" / "raster" / "raster.rig.toml", 10.0)
        page.goto(rig.url)
        page.get_by_role("button", name="x button 1", exact=True).hover()
        page.mouse.down()
        wait(rig, 200)
        page.mouse.up()
        wait(rig, 6000)
        page.screenshot(path=str(out / "web-rig.png"), full_page=True)
        rig.shutdown()
        with tempfile.TemporaryDirectory() as folder:
            jog = Path(folder) / "focus.mcm"
            jog.write_text(JOG, encoding="utf-8")
            hazard = served(jog, 1.0, reference_at=-5000, hard_limits=(-30000, 30000))
            page.goto(hazard.url)
            shot_held(page, hazard, "button 1", 2500, out / "web-hazard.png")
            problems(page, jog, out / "web-problems.png")
        browser.close()


if __name__ == "__main__":
    main()
