"""Run the test suite on every supported Python that pyenv holds, one venv each.

    python3 tools/pythons.py                          # 3.10, 3.11, 3.12 and 3.13
    python3 tools/pythons.py --versions 3.12,3.13 -- -m "not slow"

Each version's interpreter is the newest `X.Y.N` under `$(pyenv root)/versions/`; a version
that is not there is skipped, saying so. Its venv is `.venvs/pyX.Y` (git-ignored), where
`.[test]` is installed again whenever pyproject.toml changes. The arguments after `--` go to
`python -m pytest`. One line per version closes the run. Exit code: 1 if any version's install
or tests failed, else 0 (2: a usage error; 130: Ctrl-C). Standard library only: it runs before
any venv exists. The tests import mercmac from this tree, as the README's test command does.
"""
from __future__ import annotations

import argparse
import hashlib
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

# The versions pyproject's requires-python and classifiers promise (tests/project checks that).
SUPPORTED = ("3.10", "3.11", "3.12", "3.13")

ROOT = Path(__file__).resolve().parents[1]
VENVS = ROOT / ".venvs"
STAMP = "mercmac-install.txt"  # in each venv: what its install was made from


def pyenv_root() -> Path:
    """Where pyenv keeps its Pythons: `pyenv root`, else $PYENV_ROOT, else ~/.pyenv."""
    pyenv = shutil.which("pyenv")
    if pyenv:
        done = subprocess.run([pyenv, "root"], capture_output=True, text=True)
        if done.returncode == 0 and done.stdout.strip():
            return Path(done.stdout.strip())
    return Path(os.environ.get("PYENV_ROOT") or Path.home() / ".pyenv")


def patch_level(name: str, version: str) -> int | None:
    """N for a pyenv folder named `version.N` (no `3.13.0t`, `3.12-dev` or `3.12.0rc1`), else None."""
    match = re.fullmatch(re.escape(version) + r"\.(\d+)", name)
    return int(match.group(1)) if match else None


def interpreter(version: str, root: Path) -> Path | None:
    """The newest pyenv Python X.Y.N's interpreter, or None where pyenv has none."""
    folders = root / "versions"
    found = [(patch_level(p.name, version), p) for p in folders.iterdir()] if folders.is_dir() else []
    found = sorted((n, p) for n, p in found if n is not None and (p / "bin" / "python").exists())
    return found[-1][1] / "bin" / "python" if found else None


def install_stamp(python: Path) -> str:
    """What a venv's install depends on: the interpreter and pyproject.toml's bytes."""
    digest = hashlib.sha256((ROOT / "pyproject.toml").read_bytes()).hexdigest()
    return f"{python.resolve()}\n{digest}\n"


def ready_venv(version: str, python: Path) -> Path:
    """.venvs/pyX.Y with `.[test]` installed as pyproject.toml now says; its python."""
    venv = VENVS / f"py{version}"
    stamp = venv / STAMP
    wanted = install_stamp(python)
    if stamp.exists() and stamp.read_text(encoding="utf-8") == wanted:
        return venv / "bin" / "python"
    stamp.unlink(missing_ok=True)  # a failed install below must not look done next time
    # --clear: a venv made from another patch release (pyenv upgraded) is made anew
    subprocess.run([python, "-m", "venv", "--clear", venv], check=True)
    subprocess.run([venv / "bin" / "python", "-m", "pip", "install", "--quiet", ".[test]"],
                   cwd=ROOT, check=True)
    stamp.write_text(wanted, encoding="utf-8")
    return venv / "bin" / "python"


def run_pytest(python: Path, args: list[str]) -> tuple[int, str]:
    """`python -m pytest ARGS` at the root, its output passed through: (exit code, last line)."""
    proc = subprocess.Popen([python, "-m", "pytest", *args], cwd=ROOT, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT)
    tail = b""
    # chunks, not lines: pytest's progress dots come without a newline
    while chunk := proc.stdout.read1(4096):
        sys.stdout.buffer.write(chunk)
        sys.stdout.flush()
        tail = (tail + chunk)[-4096:]
    lines = [l for l in tail.decode(errors="replace").splitlines() if l.strip()]
    return proc.wait(), lines[-1].strip("= ") if lines else "no output"


def run_version(version: str, root: Path, args: list[str]) -> tuple[str, bool]:
    """Install and test on one version: (its closing line, whether it failed)."""
    python = interpreter(version, root)
    if python is None:
        return f"{version:8} skipped: no {version}.N under {root / 'versions'}", False
    name = python.parents[1].name
    print(f"--- Python {name}: {python}", flush=True)
    start = time.monotonic()
    try:
        venv_python = ready_venv(version, python)
    except subprocess.CalledProcessError as error:
        return f"{name:8} FAILED to install .[test] (exit {error.returncode})", True
    code, last = run_pytest(venv_python, args)
    wall = time.monotonic() - start
    verdict = "passed" if code == 0 else f"FAILED (pytest exit {code})"
    return f"{name:8} {verdict}  {wall:.0f} s wall  [{last}]", code != 0


def chosen_versions(text: str | None, others: bool) -> list[str]:
    """--versions as a list, less this interpreter's with --others; ValueError if unsupported."""
    versions = list(SUPPORTED) if text is None else [v.strip() for v in text.split(",") if v.strip()]
    unknown = [v for v in versions if v not in SUPPORTED]
    if unknown:
        raise ValueError(f"{', '.join(unknown)} not among the supported {', '.join(SUPPORTED)}")
    this = "{}.{}".format(*sys.version_info[:2])
    return [v for v in versions if not (others and v == this)]


def main(argv: list[str]) -> int:
    split = argv.index("--") if "--" in argv else len(argv)
    parser = argparse.ArgumentParser(description="Run the test suite on each supported Python "
                                     "that pyenv holds; arguments after -- go to pytest.")
    parser.add_argument("--versions", help="comma-separated, e.g. 3.12,3.13 (default: all of "
                        + ", ".join(SUPPORTED) + ")")
    parser.add_argument("--others", action="store_true",
                        help="leave out the version running this script (CI tested it already)")
    options = parser.parse_args(argv[:split])
    try:
        versions = chosen_versions(options.versions, options.others)
    except ValueError as error:
        parser.error(str(error))  # exits 2
    root = pyenv_root()
    try:
        results = [run_version(v, root, argv[split + 1:]) for v in versions]
    except KeyboardInterrupt:  # pytest, in the same process group, had the Ctrl-C too
        print("\npythons.py: interrupted", file=sys.stderr)
        return 130
    print("--- per Python version:")
    for line, _ in results:
        print(line)
    return 1 if any(failed for _, failed in results) else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
