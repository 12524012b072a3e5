"""The page of `sim --web` in a headless browser: frames drawn, events received, CPU used.

Each figure is counted over a window of fixed length (--seconds, default 10 s of wall time).

    python benchmarks/web_session.py [--seconds S] [--speed S] [--chromium PATH]

Each case starts the real command, `mercmac sim FILE --web --no-open`, in a fresh interpreter,
reads the address it prints on stderr, and opens it in headless chromium (playwright, Debian's
/usr/bin/chromium by default); Ctrl-C (SIGINT) stops the server at the end. Counted in the page
by a script added before the page's own: the page's requestAnimationFrame callbacks (the page
asks for one when a message came and draws the latest state in it: frames drawn), the text
changes of a position readout (a MutationObserver: position updates) and the event stream's
messages, with the simulated time (t_ms) each carries. CPU is user + system time from
/proc/PID/stat over the window, in % of one core: the server's process (all its threads), and
the browser's (every chromium process under this one; drawn in software, --disable-gpu). The
page draws at most once per message, so its frames a second are bounded by the stream's rate
(FRAME_S in mercmac/web/server.py; while only the clock goes on, STILL_S sends it about
10 times a second, so (b) and (c) draw fewer frames by design). Nothing is asserted: the figures, and
each goal as a ratio (figure / goal), are printed, measured in this one run.

(a) moving: examples/macros/four-modes.mcm (the manual's Example 4) with `--hold 1`: mode 1,
    and button 1 held from power-on jogs the stage towards 9,999,999 at 70,000 counts/s
    (143 s); the page also holds button 1 with the pointer through the window;
(b) the same session after the pointer lets button 1 go: the jog stops (AB 1), the program
    goes on polling the buttons every 20 ms, nothing moves;
(c) the same program with no button held: it defines home and ends (0.116 s), nothing moves,
    the page open and the clock running;
(d) the same, paused with the page's pause button;
(e) a rig of 16 C-863 controllers at x1, one wired group: c0 sweeps +-20,000 counts forever
    and raises out1 after each forward sweep; c1-c15 each follow the one before (out1 -> in1,
    a chain of 15 wires): wait for its line, pass it on, sweep, wait for it to drop, drop
    their own, sweep back; each at its own velocity (20,000-35,000 counts/s), so that the
    stages keep moving and their passes do not line up.

Goals (the issue): the page draws at least 30 frames a second while the stage moves ((a), and
(e)); the simulation keeps real time with a rig of 16 controllers (e: simulated s / wall s
at least 1.0); the server uses little CPU while nothing moves ((b), (c), (d): at most 2 % of
one core. A page left open on a stopped stage should cost what an idle editor or terminal
costs, 0.2 s of CPU in 10 s, which is also below what `top` shows as noise on a laptop).
"""
from __future__ import annotations

import argparse
import os
import queue
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path

HERE = Path(__file__).resolve().parent
EXAMPLE4 = HERE.parent / "examples" / "macros" / "four-modes.mcm"
CHROMIUM = "/usr/bin/chromium"
# chromium on a machine without a network, as tests/web/test_web_page.py runs it; and no
# throttling of timers or rendering for a page that is not in front (there is no screen)
FLAGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--disable-background-timer-throttling", "--disable-renderer-backgrounding",
         "--disable-backgrounding-occluded-windows"]
ADDRESS_S = 60.0  # s to wait for the server's address line
SETTLE_S = 2.0  # s between a page's first state (or a change) and the window
WAIT_MS = 30_000  # playwright's timeout for one step of the page
FRAME_GOAL = 30.0  # frames drawn a second while the stage moves
REAL_TIME_GOAL = 1.0  # simulated s per wall s of the 16-controller rig at x1
IDLE_GOAL = 2.0  # % of one core for the server while nothing moves
TICK = os.sysconf("SC_CLK_TCK")

# Counters the page updates itself, read at the start and the end of a window.
COUNTERS = """
(() => {
  const m = window.__bench = {frames: 0, messages: 0, positions: 0, t: null, at: null,
                              pos: null};
  const raf = window.requestAnimationFrame.bind(window);
  window.requestAnimationFrame = (cb) => raf((ts) => { m.frames++; return cb(ts); });
  const Source = window.EventSource;
  window.EventSource = class extends Source {
    constructor(url, options) {
      super(url, options);
      this.addEventListener("message", (e) => {
        m.messages++;
        const t = /"t_ms":(-?[0-9.eE+]+)/.exec(e.data);
        if (t) { m.t = Number(t[1]); m.at = performance.now(); }
      });
    }
  };
})();
"""
WATCH = """(el) => {
  const m = window.__bench;
  m.pos = el;
  new MutationObserver((records) => {
    for (const r of records) if (r.type === "characterData" || r.addedNodes.length) m.positions++;
  }).observe(el, {childList: true, characterData: true, subtree: true});
}"""
SNAPSHOT = """() => {
  const m = window.__bench;
  return {frames: m.frames, messages: m.messages, positions: m.positions, t: m.t, at: m.at,
          pos: m.pos ? m.pos.textContent : null, now: performance.now()};
}"""

# the 16-controller rig (e)
LEADER = ("target C-863\nmacro go {{\n  MR 20000, WS 10, CN 1\n  MR -20000, WS 10, CF 1\n"
          "  goto go\n}}\nautostart {{\n  SV {sv}, SA 200000\n  goto go\n}}\n")
FOLLOWER = ("target C-863\nmacro go {{\n  WN 1, CN 1, MR 20000, WS 10\n"
            "  WF 1, CF 1, MR -20000, WS 10\n  goto go\n}}\n"
            "autostart {{\n  SV {sv}, SA 200000\n  goto go\n}}\n")
RIG_SIZE = 16


def write_rig(folder: Path) -> Path:
    """c0 leads, c1-c15 follow in a chain of wires; the box on c0 (its unwired 2 and 3)."""
    lines = ['box = "c0"', "box_buttons = [2, 3]",
             "wires = [" + ", ".join(f'"c{i}.out1 -> c{i + 1}.in1"'
                                     for i in range(RIG_SIZE - 1)) + "]", ""]
    for i in range(RIG_SIZE):
        source = (LEADER if i == 0 else FOLLOWER).format(sv=20_000 + 1_000 * i)
        (folder / f"c{i}.mcm").write_text(source, encoding="utf-8")
        lines += [f"[controllers.c{i}]", f"address = {i}", 'model = "C-863"',
                  f'program = "c{i}.mcm"', ""]
    path = folder / "sixteen.rig.toml"
    path.write_text("\n".join(lines), encoding="utf-8")
    return path


# ------------------------------------------------------------------ CPU from /proc
def cpu_s(pid: int) -> float:
    """User + system CPU seconds of a process (all its threads); 0 once it is gone."""
    try:
        with open(f"/proc/{pid}/stat", encoding="ascii", errors="replace") as f:
            fields = f.read().rsplit(")", 1)[1].split()
    except OSError:
        return 0.0
    return (int(fields[11]) + int(fields[12])) / TICK  # utime, stime (fields 14, 15)


def _parents() -> dict[int, tuple[int, str]]:
    """pid -> (parent pid, command name) of every process."""
    out = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat", encoding="ascii", errors="replace") as f:
                text = f.read()
        except OSError:
            continue
        name = text[text.index("(") + 1:text.rindex(")")]
        out[int(entry)] = (int(text.rsplit(")", 1)[1].split()[1]), name)
    return out


def browser_cpu() -> dict[int, float]:
    """CPU seconds of each chromium process under this one (playwright's driver, node, runs
    chromium; the server is not under it)."""
    table = _parents()
    found, mine = {}, {os.getpid()}
    changed = True
    while changed:  # the descendants of this process
        changed = False
        for pid, (parent, _) in table.items():
            if parent in mine and pid not in mine:
                mine.add(pid)
                changed = True
    for pid in mine:
        if pid in table and table[pid][1].startswith("chrom"):
            found[pid] = cpu_s(pid)
    return found


# ------------------------------------------------------------------ the server
class Server:
    """`mercmac sim FILE --web --no-open ...` in a fresh interpreter, until stop()."""

    def __init__(self, path: Path, options: list[str]):
        env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
        env.pop("DISPLAY", None)
        env.pop("WAYLAND_DISPLAY", None)
        self.name = path.name
        self.args = [sys.executable, "-m", "mercmac", "sim", str(path), "--web", "--no-open",
                     *options]
        self.child = subprocess.Popen(self.args, stdin=subprocess.DEVNULL,
                                      stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                      text=True, env=env, cwd=tempfile.gettempdir())
        self.said: list[str] = []
        self.lines: queue.Queue[str | None] = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()  # the pipe never fills
        self.url = self._address()

    def _read(self) -> None:
        for line in self.child.stderr:
            self.said.append(line.rstrip("\n"))
            self.lines.put(line)
        self.lines.put(None)

    def _address(self) -> str:
        deadline = time.monotonic() + ADDRESS_S
        while True:
            try:
                line = self.lines.get(timeout=max(0.0, deadline - time.monotonic()))
                why = "ended before it printed its address"
            except queue.Empty:
                line, why = None, f"printed no address within {ADDRESS_S:g} s"
            if line is None:
                self.stop()
                raise SystemExit(f"{' '.join(self.args[2:])}: {why}; it said: "
                                 f"{' / '.join(self.said[-10:]) or 'nothing'}")
            if "the box in the browser: " in line:
                return line.split("the box in the browser: ", 1)[1].strip()

    @property
    def pid(self) -> int:
        return self.child.pid

    def stop(self) -> None:
        """Ctrl-C, as a person stops it (exit 130); killed if it does not stop in 10 s. Any
        other end is said: the figures of a server that died in a window mean nothing."""
        if self.child.poll() is None:
            self.child.send_signal(signal.SIGINT)
            try:
                self.child.wait(10)
            except subprocess.TimeoutExpired:
                self.child.kill()
                self.child.wait()
                print(f"web_session: {self.name}: the server did not stop on Ctrl-C "
                      "within 10 s: killed")
                return
        if self.child.returncode != 130:
            time.sleep(0.2)  # the reader's last lines
            print(f"web_session: {self.name}: the server ended with exit "
                  f"{self.child.returncode}, not 130: {' / '.join(self.said[-5:])}")


# ------------------------------------------------------------------ one window
@dataclass
class Figures:
    frames: float  # page frames drawn a second
    positions: float  # text changes of the watched position readout a second
    messages: float  # event-stream messages a second
    sim_rate: float | None  # simulated s per wall s, from the messages' t_ms
    server: float  # % of one core
    browser: float  # % of one core, all chromium processes
    moved: str  # the position readout at the start and the end


def measure(page, server: Server, seconds: float) -> Figures:
    """Counts over `seconds` of wall time, from now."""
    def look():
        return (page.evaluate(SNAPSHOT), time.monotonic(), cpu_s(server.pid), browser_cpu())

    (p0, w0, s0, b0) = look()
    time.sleep(seconds)
    (p1, w1, s1, b1) = look()
    wall, page_s = w1 - w0, (p1["now"] - p0["now"]) / 1000
    browser = sum(b1[pid] - b0.get(pid, 0.0) for pid in b1)  # one that ended is not counted
    rate = None
    if p0["at"] is not None and p1["at"] is not None and p1["at"] > p0["at"]:
        rate = (p1["t"] - p0["t"]) / (p1["at"] - p0["at"])
    moved = "no" if p0["pos"] == p1["pos"] else f"{p0['pos']} -> {p1['pos']}"
    return Figures(frames=(p1["frames"] - p0["frames"]) / page_s,
                   positions=(p1["positions"] - p0["positions"]) / page_s,
                   messages=(p1["messages"] - p0["messages"]) / page_s, sim_rate=rate,
                   server=100 * (s1 - s0) / wall, browser=100 * browser / wall, moved=moved)


def opened(browser, server: Server, position: str):
    """A fresh page on the server's address, its first state drawn, the readout watched."""
    context = browser.new_context(viewport={"width": 1280, "height": 860})
    context.add_init_script(COUNTERS)
    page = context.new_page()
    page.set_default_timeout(WAIT_MS)
    page.goto(server.url)
    page.locator("#conn[data-state=open]").wait_for()
    readout = page.get_by_label(position, exact=True)
    readout.wait_for()
    readout.evaluate(WATCH)
    return context, page


def wait_clock(page, seconds: float) -> None:
    """Until the page has seen the simulated clock at `seconds` or later."""
    page.wait_for_function(f"() => window.__bench.t !== null && window.__bench.t >= "
                           f"{seconds * 1000}")


# ------------------------------------------------------------------ the cases
def moving_and_released(browser, args) -> list[tuple[str, Figures]]:
    server = Server(EXAMPLE4, ["--hold", "1", "--speed", f"{args.speed:g}"])
    try:
        context, page = opened(browser, server, "position")
        try:
            one = page.get_by_role("button", name="button 1", exact=True)
            one.hover()
            page.mouse.down()
            page.wait_for_function("() => document.querySelector('[aria-label=\"button 1\"]')"
                                   ".getAttribute('aria-pressed') === 'true'")
            time.sleep(SETTLE_S)
            moving = measure(page, server, args.seconds)
            page.mouse.up()
            page.wait_for_function("() => document.querySelector('[aria-label=\"button 1\"]')"
                                   ".getAttribute('aria-pressed') === 'false'")
            time.sleep(SETTLE_S)
            released = measure(page, server, args.seconds)
        finally:
            context.close()
    finally:
        server.stop()
    return [("(a) four-modes, button 1 held: moving", moving),
            ("(b) the same, button 1 let go: still", released)]


def idle(browser, args) -> list[tuple[str, Figures]]:
    server = Server(EXAMPLE4, ["--speed", f"{args.speed:g}"])
    try:
        context, page = opened(browser, server, "position")
        try:
            wait_clock(page, 0.5)  # home defined, the program ended
            time.sleep(SETTLE_S)
            running = measure(page, server, args.seconds)
            page.get_by_role("button", name="pause", exact=True).click()
            page.get_by_role("button", name="run", exact=True).wait_for()
            time.sleep(SETTLE_S)
            paused = measure(page, server, args.seconds)
        finally:
            context.close()
    finally:
        server.stop()
    return [("(c) four-modes, no button: ended", running),
            ("(d) the same, paused on the page", paused)]


def rig(browser, args) -> list[tuple[str, Figures]]:
    with tempfile.TemporaryDirectory() as folder:
        server = Server(write_rig(Path(folder)), ["--speed", "1"])
        try:
            context, page = opened(browser, server, "c0 position")
            try:
                wait_clock(page, 0.5)
                time.sleep(SETTLE_S)
                figures = measure(page, server, args.seconds)
            finally:
                context.close()
        finally:
            server.stop()
    return [(f"(e) rig of {RIG_SIZE}, wired chain, x1", figures)]


# ------------------------------------------------------------------ the table
def table(rows: list[tuple[str, Figures]]) -> None:
    head = ("case", "frames/s", "position/s", "events/s", "sim s/wall s", "server %",
            "browser %", "position moved")
    cells = [head] + [(name, f"{f.frames:.1f}", f"{f.positions:.1f}", f"{f.messages:.1f}",
                       "-" if f.sim_rate is None else f"{f.sim_rate:.3f}", f"{f.server:.1f}",
                       f"{f.browser:.1f}", f.moved) for name, f in rows]
    widths = [max(len(row[i]) for row in cells) for i in range(len(head))]
    for n, row in enumerate(cells):
        print("  ".join(cell.ljust(w) if i in (0, len(head) - 1) else cell.rjust(w)
                        for i, (cell, w) in enumerate(zip(row, widths))).rstrip())
        if n == 0:
            print("  ".join("-" * w for w in widths))


def goals(rows: dict[str, Figures]) -> None:
    print("\nGoals (figure / goal; met at >= 1 for rates, at <= 1 for CPU):")
    for name, f in rows.items():
        if name.startswith(("(a)", "(e)")):
            drawn = f" (the page drew {f.frames / f.messages:.0%} of the {f.messages:.1f} " \
                "events/s)" if f.messages else ""
            print(f"  {name}: frames drawn {f.frames:.1f}/s / {FRAME_GOAL:g} = "
                  f"{f.frames / FRAME_GOAL:.2f}{drawn}")
        if name.startswith("(e)"):
            rate = f.sim_rate
            print(f"  {name}: simulated s per wall s " + ("- (no messages)" if rate is None else
                  f"{rate:.3f} / {REAL_TIME_GOAL:g} = {rate / REAL_TIME_GOAL:.2f}"))
        if name.startswith(("(b)", "(c)", "(d)")):
            print(f"  {name}: server CPU {f.server:.1f} % / {IDLE_GOAL:g} % = "
                  f"{f.server / IDLE_GOAL:.2f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=10.0,
                        help="wall seconds of each window (default 10)")
    parser.add_argument("--speed", type=float, default=1.0,
                        help="--speed of the single-controller cases (a)-(d); the rig runs "
                             "at x1 (default 1)")
    parser.add_argument("--chromium", default=CHROMIUM, help=f"default {CHROMIUM}")
    args = parser.parse_args()
    try:
        from playwright.sync_api import Error, sync_playwright
    except ImportError:
        print("web_session: playwright is not installed (pip install playwright, or the test "
              "extra): nothing measured")
        return
    chromium = args.chromium if os.path.isfile(args.chromium) else shutil.which(args.chromium)
    if chromium is None:
        print(f"web_session: no chromium at {args.chromium} (apt-get install chromium, or "
              "--chromium PATH): nothing measured")
        return
    print(f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f} before; "
          f"windows of {args.seconds:g} s")
    rows: list[tuple[str, Figures]] = []
    with sync_playwright() as driver:
        try:
            browser = driver.chromium.launch(executable_path=chromium, headless=True,
                                             args=FLAGS)
        except Error as e:
            print(f"web_session: chromium ({chromium}) does not start: "
                  f"{str(e).splitlines()[0]}: nothing measured")
            return
        try:
            print(f"chromium {browser.version}, headless")
            for case in (moving_and_released, idle, rig):
                try:
                    rows += case(browser, args)
                except (Error, SystemExit) as e:  # a page that never came, a server that did not
                    print(f"web_session: {case.__name__}: not measured: "
                          f"{str(e).splitlines()[0] if str(e) else type(e).__name__}")
        finally:
            browser.close()
    print()
    table(rows)
    goals(dict(rows))


if __name__ == "__main__":
    main()
