"""Simulator speed: simulated time over wall time, start-up included.

    python benchmarks/sim_speed.py

(a) one hour of the manual's Example 4 in mode 3 (button 3 held at power-on),
    then a 500 ms button press every 30 s, cycling through buttons 1-4;
(b) `[MC00] CN1,WA20,RP,RP` run to its real end (2^32 passes, about 1094 days).
Each case runs in a fresh interpreter, so the wall time includes start-up
(imports, compiling the file). Goal: at most 2 s of wall time each.

Loops whose passes are identical except for what they emit,
one simulated day each (goal: a second or two), and 100,000 presses at one
instant (goal: well under a second, measured in-process):
(c) a `goto` ping-pong without any wait (a busy loop);
(d) `every 500ms { CN 1, WA 500, CF 1 }`: two LED changes a pass;
(e) `every 20ms { TT }`: one report a pass, 4 million a day.
`--short` runs (c)-(e) for less simulated time (for the slow code before the
fix) and prints the wall time scaled to a simulated day.

Loops whose passes differ by a constant shift of position and target,
1500 simulated days each (goal: under 2 s of wall time each):
(f) `every 10ms { MR 1, WS 0 }`: a scan stepping forever (into the soft limit);
(g) Example 4 in mode 1 with button 1 held from power-on (`--buttons 1@0`);
(g') `every 10ms { MR 1, WS 0, TS }` from -3000, across the reference edge.

Loops that report or move while the stage moves, 1500 simulated days each on
the C-863 and the C-663 (goal: at most 2 s of wall time each); each is first run for ten
simulated minutes, and the 1500-day run is given up after MOVING_GIVE_UP
seconds (printed as "over"), so that a loop that is not skipped does not run for days:
(i) `macro m { TT, MR 1, when 4 { goto fin }, goto m }`: reports between short moves;
(j) `every 30ms { TT, MR 1, TT, MR 2, ... TT, MR 9 }`: a long body that reports.

A rig (goal: at most 2 s of wall time):
(h) the raster example (examples/rigs/raster/), one simulated hour from button 1 on X:
    both controllers on one clock, joint fast-forward on; then in-process, the same hour
    stepped (joint fast-forward off) for the ratio; and the same to 1500 simulated days
    (not stepped).
"""
from __future__ import annotations

import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
EXAMPLE4 = os.path.join(HERE, "..", "examples", "macros", "manual-example4-four-modes.mcm")
HOUR_MS = 3_600_000
DAY_MS = 24 * HOUR_MS
PRESSES = 100_000


def example4_buttons() -> str:
    """Mode 3 chosen at power-on, then one press every 30 s."""
    presses = ["3@0-300ms"]
    for i, t in enumerate(range(30_000, HOUR_MS, 30_000)):
        presses.append(f"{i % 4 + 1}@{t}-{t + 500}")
    return ",".join(presses)


CASES = {
    "example 4, mode 3, 1 h, a press every 30 s": (
        [EXAMPLE4, "--buttons", example4_buttons(), "--until", "1h"], HOUR_MS),
    "CN1,WA20,RP,RP to its end (1500d asked)": (
        ["-", "--until", "1500d"], None),
}
LOOP = "[MC00] CN1,WA20,RP,RP\n"
LONG_MS = 1500 * 24 * 3_600_000
JOG = "autostart {\n  every 10ms { MR 1, WS 0 }\n}\n"
TS_JOG = "autostart {\n  MA -3000, WS 0\n  every 10ms { MR 1, WS 0, TS }\n}\n"
SHIFT_CASES = {
    "every 10ms { MR 1, WS 0 } to 1500d": lambda: measure_source(JOG, LONG_MS),
    "every 10ms { MR 1, WS 0, TS } across the reference, 1500d":
        lambda: measure_source(TS_JOG, LONG_MS),
    "example 4, mode 1, button 1 held, 1500d": lambda: measure(
        [EXAMPLE4, "--buttons", "1@0", "--until", "1500d"]),
}
MOVING_GIVE_UP = 60  # s of wall time for one 1500-day run of a loop that is not skipped
TEN_MINUTES_MS = 600_000
MOVING_CASES = {
    "macro m { TT, MR 1, when 4 { goto fin }, goto m }":
        "macro m {\n  TT, MR 1, when 4 { goto fin }, goto m\n}\nmacro fin {\n  TP\n}\n"
        "autostart { goto m }\n",
    "every 30ms { TT, MR 1, ... TT, MR 9 }":
        "autostart {\n  every 30ms { "
        + ", ".join(f"TT, MR {n}" for n in range(1, 10)) + " }\n}\n",
}
RASTER = os.path.join(HERE, "..", "examples", "rigs", "raster", "raster.rig.toml")
RIG_CASES = {
    "raster rig, 1 h from button 1 on x": (
        [os.path.abspath(RASTER), "--buttons", "x:1@0-100ms", "--until", "1h"], HOUR_MS),
    "raster rig, 1500 d from button 1 on x": (
        [os.path.abspath(RASTER), "--buttons", "x:1@0-100ms", "--until", "1500d"], LONG_MS),
}
# (source, simulated ms, simulated ms with --short)
DAY_CASES = {
    "goto ping-pong, no wait (busy loop)": (
        "macro a { goto b }\nmacro b { goto a }\nautostart { goto a }\n", DAY_MS, 120_000),
    "every 500ms { CN 1, WA 500, CF 1 }": (
        "autostart {\n  every 500ms { CN 1, WA 500, CF 1 }\n}\n", DAY_MS, 2 * HOUR_MS),
    "every 20ms { TT }": ("autostart {\n  every 20ms { TT }\n}\n", DAY_MS, 600_000),
}


def measure(args: list[str], timeout: float | None = None) -> tuple[float, dict]:
    """Run `mercmac sim ... --format json` in a fresh interpreter; wall seconds and result."""
    import json

    import tempfile

    # From a neutral folder with bytecode on: the installed package as a user runs it, not
    # the repository's sources compiled afresh (PYTHONDONTWRITEBYTECODE) on every run.
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "mercmac", "sim", *args, "--format", "json"],
                          input=LOOP if args[0] == "-" else None, capture_output=True,
                          text=True, check=True, cwd=tempfile.gettempdir(), env=env,
                          timeout=timeout)
    return time.perf_counter() - start, json.loads(done.stdout)


def measure_source(source: str, until_ms: int, *options: str,
                   timeout: float | None = None) -> tuple[float, dict]:
    """Simulate a high-level source for until_ms in a fresh interpreter; wall s and JSON."""
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "case.mcm")
        with open(path, "w", encoding="utf-8") as f:
            f.write(source)
        return measure([path, "--until", f"{until_ms}ms", *options], timeout)


def moving_case(name: str, source: str, target: str) -> None:
    """Ten minutes, then 1500 days (given up after MOVING_GIVE_UP s) of one moving loop."""
    wall, result = measure_source(source, TEN_MINUTES_MS, "--target", target)
    line = (f"{name} on the {target.upper()}: 10 min in {wall:.2f} s wall "
            f"(position {result['final']['position']:,}); 1500d in ")
    try:
        wall, result = measure_source(source, LONG_MS, "--target", target,
                                      timeout=MOVING_GIVE_UP)
    except subprocess.TimeoutExpired:
        print(line + f"over {MOVING_GIVE_UP} s wall")
        return
    print(line + f"{wall:.2f} s wall -> ratio {LONG_MS / 1000 / wall:,.0f} : 1 "
          f"(position {result['final']['position']:,})")


def presses_at_one_instant(count: int) -> float:
    """Wall seconds to simulate `count` presses of buttons 1-4 at 1 s, released 1 or 2 ms later."""
    from mercmac.compiler import compile_source
    from mercmac.source import Source
    from mercmac.timespec import Press
    from mercmac.sim.simulate import simulate_program

    program = compile_source(Source("presses.mcm", "autostart {\n  every 20ms { TC 1 }\n}\n")).program
    presses = [Press((1, 2, 3, 4), 1000, 1001 + i % 2) for i in range(count)]
    start = time.perf_counter()
    simulate_program(program, presses=presses, until_ms=3000)
    return time.perf_counter() - start


def raster_stepped(until_ms: int) -> float:
    """Wall seconds of the raster rig stepped instant by instant (no joint fast-forward)."""
    from mercmac.rig.open import accept
    from mercmac.sim.simulate import simulate
    from mercmac.timespec import parse_buttons

    accepted = accept(str(RASTER))
    rig = accepted.rig
    programs = {name: c.program for name, c in accepted.programs.items()}
    start = time.perf_counter()
    simulate(rig, programs, presses={"x": parse_buttons("1@0-100ms")}, until_ms=until_ms,
                 fast_forward="off")
    return time.perf_counter() - start


def main() -> None:
    short = "--short" in sys.argv[1:]
    for name, (source, day_ms, short_ms) in DAY_CASES.items():
        simulated = short_ms if short else day_ms
        wall, result = measure_source(source, simulated)
        truncated = result.get("truncated", {})
        emitted = (len(result["reports"]) + len(result["outputs"]) + truncated.get("reports", 0)
                   + truncated.get("outputs", 0))
        print(f"{name}: simulated {simulated / 1000:,.0f} s in {wall:.2f} s wall "
              f"-> {wall * DAY_MS / simulated:,.1f} s per simulated day, ratio "
              f"{simulated / 1000 / wall:,.0f} : 1 ({emitted:,} reports and LED changes)")
    count = PRESSES // 5 if short else PRESSES
    wall = presses_at_one_instant(count)
    print(f"{count:,} presses at one instant: {wall:.2f} s wall")
    for name, case in SHIFT_CASES.items():
        wall, result = case()
        final = result["final"]
        print(f"{name}: simulated {LONG_MS / 1000:,.0f} s in {wall:.2f} s wall "
              f"-> ratio {LONG_MS / 1000 / wall:,.0f} : 1 (position {final['position']:,})")
    for name, source in MOVING_CASES.items():
        for target in ("c-863", "c-663"):
            moving_case(name, source, target)
    for name, (args, simulated_ms) in RIG_CASES.items():
        wall, result = measure(args)
        y = result["controllers"]["y"]["final"]
        # stepping 1500 days would take days: only the hour is stepped for the ratio
        stepped = (f"; stepped in-process: {raster_stepped(simulated_ms):.2f} s"
                   if simulated_ms <= HOUR_MS else "")
        print(f"{name}: simulated {simulated_ms / 1000:,.0f} s in {wall:.2f} s wall "
              f"-> ratio {simulated_ms / 1000 / wall:,.0f} : 1 (y at {y['position']:,}"
              f"{stepped})")
    for name, (args, simulated_ms) in CASES.items():
        wall, result = measure(args)
        simulated = simulated_ms if simulated_ms is not None else result["ended_ms"]
        ratio = simulated / 1000 / wall
        print(f"{name}: simulated {simulated / 1000:,.0f} s in {wall:.2f} s wall "
              f"-> ratio {ratio:,.0f} : 1 (halted: {result['halted']})")


if __name__ == "__main__":
    main()
