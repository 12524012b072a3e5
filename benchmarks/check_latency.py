"""Start-up latency of `mercmac check`.

Prints the ratio of the median wall time of `mercmac check` on the manual's
Example 4 to `python -c pass`, both run by the same interpreter, alternating
runs. Measure the installed package (pip compiles bytecode at install time;
an editable install with PYTHONDONTWRITEBYTECODE measures compilation).
Goal: at most 6.
"""
from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "macros" / "manual-example4-four-modes.mcm"


def wall(argv: list[str]) -> float:
    """Seconds for one run, from a neutral folder so that `-c` imports the installed package
    (from the repository, `mercmac/` would shadow it), and with the bytecode pip compiled:
    PYTHONDONTWRITEBYTECODE in the environment would otherwise compile the parser each run."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    start = time.perf_counter()
    subprocess.run(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=False,
                   cwd=tempfile.gettempdir(), env=env)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=31)
    args = parser.parse_args()
    # what the console script runs (pyproject.toml [project.scripts]): the entry point first
    check = [sys.executable, "-c", "from mercmac.__main__ import main; main()", "check",
             str(EXAMPLE)]
    bare = [sys.executable, "-c", "pass"]
    wall(check), wall(bare)  # warm the file cache
    checks, bares = [], []
    for _ in range(args.runs):
        checks.append(wall(check))
        bares.append(wall(bare))
    c, b = statistics.median(checks), statistics.median(bares)
    print(f"mercmac check {EXAMPLE.name}: median {c * 1000:.1f} ms")
    print(f"python -c pass: median {b * 1000:.1f} ms")
    print(f"ratio: {c / b:.2f} (goal <= 6)")


if __name__ == "__main__":
    main()
