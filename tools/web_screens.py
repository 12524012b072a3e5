"""Screenshots of the page of `sim --web` for docs/: the manual's Example 4 in mode 3 with
button 1 held, and the raster rig scanning.

    .venv/bin/python tools/web_screens.py [OUT_FOLDER]   (default: docs/)

Needs playwright (the test extra) and Debian's chromium.
"""
from __future__ import annotations

import sys
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))
FLAGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync"]


def served(path: Path, speed: float):
    from helpers.web import simulation
    from mercmac.web.live import Live
    from mercmac.web.server import WebServer

    server = WebServer(Live(simulation(path), path.name, speed=speed))
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server


def wait(server, ms: float) -> None:
    goal = server.live.sim.now_ms() + ms
    while server.live.sim.now_ms() < goal:
        time.sleep(0.02)


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
        page.get_by_role("button", name="button 1", exact=True).hover()
        page.mouse.down()
        wait(box, 1500)
        page.screenshot(path=str(out / "web-box.png"))
        page.mouse.up()
        box.shutdown()
        rig = served(ROOT / "examples" / "rigs" / "raster" / "raster.rig.toml", 10.0)
        page.goto(rig.url)
        page.get_by_role("button", name="x button 1", exact=True).hover()
        page.mouse.down()
        wait(rig, 200)
        page.mouse.up()
        wait(rig, 6000)
        page.screenshot(path=str(out / "web-rig.png"), full_page=True)
        rig.shutdown()
        browser.close()


if __name__ == "__main__":
    main()
