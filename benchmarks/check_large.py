"""`mercmac check` on large files: wall time, peak memory, output size (issue 7, item 6).

    python benchmarks/check_large.py [--size MB] [--timeout S]

Three generated files of about 1 MB each, checked in a fresh interpreter:
(a) repeated broken lines: a syntax error on every line;
(b) valid lines with many warnings (and a duplicate-slot error per line);
(c) one 1 MB line with an unknown command every few bytes.
Checking must be linear in the file size. Goal: under 2 s each for 1 MB.
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import threading
import time

CASES = {
    "broken lines": lambda n: "[MC01] MR5000 WS100\n" * (n // 20),
    "warnings": lambda n: "[MC05] JN5000,WS,XN1,XF1\n" * (n // 26),
    "one long line": lambda n: "[MC01] " + "XX1," * (n // 4) + "\n",
}
CHECK = "from mercmac.cli import main; main()"


def measure(path: str, timeout: float) -> tuple[float, float, int, str]:
    """Wall seconds, peak RSS in MB, bytes written, and the last line of output."""
    start = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-c", CHECK, "check", path],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    out = bytearray()
    reader = threading.Thread(target=lambda: out.extend(proc.stdout.read()), daemon=True)
    reader.start()
    timer = threading.Timer(timeout, proc.kill)
    timer.start()
    _, _, usage = os.wait4(proc.pid, 0)  # the rusage of this child alone
    timer.cancel()
    proc.returncode = 0  # reaped by wait4
    reader.join()
    wall = time.perf_counter() - start
    last = out.decode(errors="replace").rstrip().rsplit("\n", 1)[-1]
    if wall >= timeout:
        last = f"killed after {timeout:.0f} s"
    return wall, usage.ru_maxrss / 1024, len(out), last


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=float, default=1.0, help="file size in MB (default 1)")
    parser.add_argument("--timeout", type=float, default=120.0, help="seconds before a run is killed")
    args = parser.parse_args()
    size = int(args.size * 1_000_000)
    with tempfile.TemporaryDirectory() as tmp:
        for name, make in CASES.items():
            path = os.path.join(tmp, name.replace(" ", "-") + ".mcm")
            with open(path, "w", encoding="ascii", newline="\n") as f:
                f.write(make(size))
            wall, rss, written, last = measure(path, args.timeout)
            print(f"{name:>14}: {os.path.getsize(path) / 1e6:.1f} MB in {wall:6.2f} s, "
                  f"peak {rss:5.0f} MB, {written / 1e3:8.1f} kB out | {last}")
    print("goal: under 2 s each for 1 MB")


if __name__ == "__main__":
    main()
