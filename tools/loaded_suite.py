"""The README's test command in a fresh clone, on a machine kept busy.

Clones this repository's committed HEAD into a temporary folder and runs the README's second
set-up line there (as .ci/run and tests/project/test_readme.py read it) RUNS times in a row,
with `--durations=10` added, while `stress-ng --cpu N` keeps every core busy. Prints each
run's wall time, pass/fail counts and slowest ten tests; exits 1 if any run failed, 2 when
stress-ng is missing (Debian: apt-get install stress-ng). `--quiet` runs without the load:
the quiet-machine wall time.

    python3 tools/loaded_suite.py [--runs 3] [--cpu 8] [--quiet] [--keep]
"""
from __future__ import annotations

import argparse
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SUMMARY = re.compile(r"^=*\s*(?P<counts>(\d+ \w+,? ?)+) in (?P<seconds>[\d.]+)s", re.M)


def readme_test_command() -> str:
    """The README's second set-up line: the one that installs the test extras and runs pytest."""
    lines = (ROOT / "README.md").read_text(encoding="utf-8").splitlines()
    commands = [line.strip() for line in lines[:6] if line.startswith("    ")]
    if len(commands) < 2 or "pytest" not in commands[1]:
        raise SystemExit("tools/loaded_suite.py: README.md's second set-up line runs no pytest")
    return commands[1]


def fresh_clone(into: Path) -> Path:
    """A clone of this repository's HEAD (what is committed, nothing else) in `into`."""
    clone = into / "mercmac"
    subprocess.run(["git", "clone", "--quiet", str(ROOT), str(clone)], check=True)
    return clone


def start_load(cpus: int) -> subprocess.Popen:
    """stress-ng on `cpus` workers, in a session of its own (stopped by stop_group)."""
    return subprocess.Popen(["stress-ng", "--cpu", str(cpus), "--quiet"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)


def stop_group(process: subprocess.Popen) -> None:
    """Stop a process started in a session of its own, and everything it started."""
    try:
        os.killpg(process.pid, signal.SIGTERM)
    except ProcessLookupError:
        return
    try:
        process.wait(timeout=30)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        process.wait()


def run_once(clone: Path, command: str, log: Path) -> tuple[float, int, str]:
    """Wall seconds, exit code and output of one run of `command` in the clone."""
    started = time.monotonic()
    with log.open("w", encoding="utf-8") as out:
        # a session of its own: stopped, the run takes its pytest workers with it
        run = subprocess.Popen(["bash", "-c", command + " --durations=10"], cwd=clone,
                               stdout=out, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                               start_new_session=True)
        try:
            code = run.wait()
        except BaseException:
            stop_group(run)
            raise
    return time.monotonic() - started, code, log.read_text(encoding="utf-8")


def report(number: int, seconds: float, code: int, output: str) -> None:
    """The run's wall time, its counts, and the slowest ten tests as pytest listed them."""
    summary = SUMMARY.findall(output)
    counts = f"{summary[-1][0].strip()}, pytest's {summary[-1][-1]} s" if summary \
        else "no pytest summary (see the log)"
    print(f"run {number}: {'passed' if code == 0 else f'FAILED (exit {code})'}, "
          f"wall {seconds:.0f} s (install included): {counts}")
    slowest = output.split("slowest 10 durations", 1)
    if len(slowest) == 2:
        for line in slowest[1].splitlines()[1:11]:
            if line.strip():
                print("   ", line.strip())
    failed = [line for line in output.splitlines() if line.startswith(("FAILED", "ERROR"))]
    for line in failed:
        print("   ", line)
    sys.stdout.flush()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3, help="runs in a row (default 3)")
    parser.add_argument("--cpu", type=int, default=8, help="stress-ng CPU workers (default 8)")
    parser.add_argument("--quiet", action="store_true", help="no load: the quiet wall time")
    parser.add_argument("--keep", action="store_true", help="keep the clone and the logs")
    args = parser.parse_args()
    if not args.quiet and shutil.which("stress-ng") is None:
        print("tools/loaded_suite.py: stress-ng is not installed (Debian, Ubuntu: "
              "apt-get install stress-ng); or run with --quiet", file=sys.stderr)
        return 2
    command = readme_test_command()
    folder = Path(tempfile.mkdtemp(prefix="mercmac-loaded-"))
    folder.chmod(0o755)  # as a clone of a user's: the tests that run as nobody read it
    clone = fresh_clone(folder)
    what = "no load" if args.quiet else f"stress-ng --cpu {args.cpu} on {os.cpu_count()} cores"
    print(f"{command}\n  in a fresh clone ({clone}), {args.runs} runs, {what}", flush=True)
    load = None if args.quiet else start_load(args.cpu)
    failures = 0
    try:
        for number in range(1, args.runs + 1):
            seconds, code, output = run_once(clone, command, folder / f"run{number}.log")
            report(number, seconds, code, output)
            failures += code != 0
    finally:
        if load:
            stop_group(load)
        if args.keep or failures:
            print(f"logs and clone kept in {folder}")
        else:
            shutil.rmtree(folder, ignore_errors=True)
    print(f"{args.runs - failures} of {args.runs} runs passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
