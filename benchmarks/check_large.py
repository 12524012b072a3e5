"""`mercmac check` on large files: wall time, peak memory, output size.

    python benchmarks/check_large.py [--size MB] [--timeout S]

Generated files, checked in a fresh interpreter (sizes for the default --size 1):
(a) repeated broken lines: a syntax error on every line (1 MB);
(b) valid lines with many warnings (and a duplicate-slot error per line) (1 MB);
(c) one 1 MB line with an unknown command every few bytes;
(d) one line of 10,000 and (e) of 60,000 repeated `// ` after an error, ending in `mercmac`:
    the suppression comment pattern was quadratic in it (9 s, past 60 s);
(f) one macro of 100,000 commands on one 500 KB line (67-81 s);
(g) `when` blocks nested 32 deep, each followed by code: a block that calls on was
    lowered twice per level (16 levels 0.9 s, doubling per level; 32 hours);
(h) a line of 3,000 `repeat 1 { TP }` and (i) 3,000 lines of a block that calls on,
    then code: one recursion per statement (RecursionError, "internal error").
These three do not grow with --size.
Checking must be linear in the file size. Goal: at most 2 s per MB, and under 2 s each.
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
    "10k x '// '": lambda n: "[MC01] XX1 " + "// " * (n // 100) + "mercmac\n",
    "60k x '// '": lambda n: "[MC01] XX1 " + "// " * (n * 6 // 100) + "mercmac\n",
    "one-macro line": lambda n: "macro a { " + ",".join(["MR 1"] * (n // 10)) + " }\n",
    "32-deep whens": lambda n: _nested_whens(32),
    "3k repeat 1": lambda n: "macro a { " + ", ".join(["repeat 1 { TP }"] * 3000) + " }\n",
    "3k when+call": lambda n: "macro b { TT }\nmacro a {\n" + "when 1 { call b }, TP\n" * 3000 + "}\n",
}
CHECK = "from mercmac.cli import main; main()"


def _nested_whens(depth: int) -> str:
    """`when 1 { ... } MR 1` around itself `depth` times in a macro, and its caller."""
    body = "MR 1"
    for _ in range(depth):
        body = f"when 1 {{ {body} }} MR 1"
    return f"macro a {{ {body} }}\nautostart {{ call a }}\n"


def measure(path: str, timeout: float, command: str = "check") -> tuple[float, float, int, str]:
    """Wall seconds, peak RSS in MB, bytes written, and the last line of output of
    `mercmac COMMAND PATH` in a fresh interpreter."""
    start = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-c", CHECK, command, path],
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


def main(cases: dict = CASES, command: str = "check", doc: str = __doc__) -> None:
    """Write each case, run `mercmac COMMAND` on it and print the figures (fmt_large.py too)."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--size", type=float, default=1.0, help="file size in MB (default 1)")
    parser.add_argument("--timeout", type=float, default=120.0, help="seconds before a run is killed")
    args = parser.parse_args()
    size = int(args.size * 1_000_000)
    with tempfile.TemporaryDirectory() as tmp:
        for name, make in cases.items():
            path = os.path.join(tmp, "".join(c if c.isalnum() else "-" for c in name) + ".mcm")
            with open(path, "w", encoding="ascii", newline="\n") as f:
                f.write(make(size))
            mb = os.path.getsize(path) / 1e6  # before `fmt` rewrites it
            before = os.times()
            wall, rss, written, last = measure(path, args.timeout, command)
            cpu = _children_cpu(os.times()) - _children_cpu(before)  # steadier on a busy machine
            per_mb = f"{wall / mb:6.2f} s/MB" if mb >= 0.25 else " " * 11  # startup would dominate
            print(f"{name:>14}: {mb:5.2f} MB in {wall:6.2f} s ({per_mb}, CPU {cpu:5.2f} s), "
                  f"peak {rss:5.0f} MB, {written / 1e3:8.1f} kB out | {last}")
    print("goal: at most 2 s per MB, and under 2 s each")


def _children_cpu(times: os.times_result) -> float:
    """CPU seconds of the reaped child processes so far."""
    return times.children_user + times.children_system


if __name__ == "__main__":
    main()
