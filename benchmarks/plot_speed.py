"""`sim --plot` speed and file sizes against the simulation alone.

    python benchmarks/plot_speed.py

Each case runs `mercmac sim` in a fresh interpreter three times: without a plot,
with `--plot x.png` and with `--plot x.html`, and prints the wall times, the
plot's share (plot run minus plain run), the CPU time of each run (steadier than
the wall time on a shared machine) and the sizes of the files:
(a) the README picture: Example 4 in mode 2 (its scenario), 6 s;
(b) 6,000 short presses over 360 s of `every 1ms { when 1 { CN 1, WF 1, CF 1 } }`
    (36,000 macro changes, 12,000 LED changes; before: 50-350 s and a 9-17 MB page);
(c) the same with a move per press (`MR 2000`): a profile sampled under a 1-ms poll;
(d) 5,000 presses 20 s apart: 5,000 fast-forwarded stretches drawn compressed;
(e) a program that moves twice and ends at 2.8 s, run for a day: its idle tail
    drawn compressed.
Goal: the plot costs about what the simulation does (linear), at most ~2 s per MB
of input; the page stays one file of a few MB.
"""
from __future__ import annotations

import os
import resource
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..")
EXAMPLE4 = os.path.join(ROOT, "examples", "macros", "manual-example4-four-modes.mcm")
MODE2 = os.path.join(ROOT, "examples", "scenarios", "manual-example4-four-modes.mode2.toml")
POLL = "autostart { every 1ms { when 1 { CN 1, WF 1, CF 1 } } }\n"
MOVE = "autostart { every 1ms { when 1 { MR 2000, CN 1, WF 1, CF 1 } } }\n"
ONCE = "autostart { MR 50000, WS, MR -20000 }\n"


def presses(count: int, period_ms: int, held_ms: int) -> str:
    """`count` presses of button 1, one every period_ms, each held_ms."""
    return ",".join(f"1@{i * period_ms}-{i * period_ms + held_ms}" for i in range(count))


def cases(folder: str) -> dict[str, list[str]]:
    def source(name: str, text: str) -> str:
        path = os.path.join(folder, name)
        with open(path, "w", encoding="utf-8") as f:
            f.write(text)
        return path

    short = presses(6000, 60, 20)
    return {
        "(a) README picture, Example 4 mode 2": [EXAMPLE4, "--scenario", MODE2],
        "(b) 6,000 presses over 360 s": [source("poll.mcm", POLL), "--buttons", short,
                                         "--until", "360s"],
        "(c) 6,000 presses over 360 s, a move each": [source("move.mcm", MOVE), "--buttons",
                                                      short, "--until", "360s"],
        "(d) 5,000 presses 20 s apart": [source("poll.mcm", POLL), "--buttons",
                                         presses(5000, 20_000, 20), "--until", "100000s"],
        "(e) a program that ends at once, run for a day": [source("once.mcm", ONCE),
                                                            "--until", "1d"],
    }


def wall(args: list[str]) -> tuple[float, float]:
    """Wall and CPU seconds of `mercmac sim ARGS` in a fresh interpreter, output thrown away."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    used = _children_cpu()
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "mercmac", "sim", *args], check=True, env=env,
                   stdout=subprocess.DEVNULL, cwd=tempfile.gettempdir())
    return time.perf_counter() - start, _children_cpu() - used


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def main() -> None:
    with tempfile.TemporaryDirectory() as folder:
        for name, args in cases(folder).items():
            plain, plain_cpu = wall(args)
            line = [f"{name}: simulation {plain:.2f} s (cpu {plain_cpu:.2f} s)"]
            for kind in ("png", "html"):
                out = os.path.join(folder, f"plot.{kind}")
                seconds, cpu = wall(args + ["--plot", out])
                line.append(f"--plot .{kind} {seconds:.2f} s (plot {seconds - plain:+.2f} s, "
                            f"cpu {cpu:.2f} s, {os.path.getsize(out) / 1e6:.2f} MB)")
            size = sum(len(a) for a in args) / 1e6
            print("; ".join(line) + f"; input {size:.2f} MB")


if __name__ == "__main__":
    main()
