"""Simulator speed: simulated time over wall time, start-up included (issue 3, Speed).

    python benchmarks/sim_speed.py

(a) one hour of the manual's Example 4 in mode 3 (button 3 held at power-on),
    then a 500 ms button press every 30 s, cycling through buttons 1-4;
(b) `[MC00] CN1,WA20,RP,RP` run to its real end (2^32 passes, about 1094 days).
Each case runs in a fresh interpreter, so the wall time includes start-up
(imports, compiling the file). Goal: at most 2 s of wall time each.
"""
from __future__ import annotations

import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
EXAMPLE4 = os.path.join(HERE, "..", "examples", "macros", "manual-example4-four-modes.mcm")
HOUR_MS = 3_600_000


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


def measure(args: list[str]) -> tuple[float, dict]:
    """Run `mercmac sim ... --format json` in a fresh interpreter; wall seconds and result."""
    import json

    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "mercmac", "sim", *args, "--format", "json"],
                          input=LOOP if args[0] == "-" else None, capture_output=True,
                          text=True, check=True)
    return time.perf_counter() - start, json.loads(done.stdout)


def main() -> None:
    for name, (args, simulated_ms) in CASES.items():
        wall, result = measure(args)
        simulated = simulated_ms if simulated_ms is not None else result["ended_ms"]
        ratio = simulated / 1000 / wall
        print(f"{name}: simulated {simulated / 1000:,.0f} s in {wall:.2f} s wall "
              f"-> ratio {ratio:,.0f} : 1 (halted: {result['halted']})")


if __name__ == "__main__":
    main()
