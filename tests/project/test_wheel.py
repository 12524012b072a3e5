"""The package as released: the sdist and the wheel built with `python -m build`
and passed by `twine check`; the wheel, installed in a fresh venv without lark, runs the
README's commands from an empty folder with the examples `mercmac examples` fetched."""
from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from helpers.paths import PACKAGE, ROOT
from helpers.readme import HARDWARE_PORTS, README, commands, prepare, promise

TIMEOUT_S = 600  # a build or an install from PyPI on a busy machine
# What pip or build print when PyPI cannot be reached: the test is skipped, saying so.
OFFLINE = re.compile(r"Could not find a version|No matching distribution|Failed to establish|"
                     r"Temporary failure in name resolution|Network is unreachable|"
                     r"ProxyError|ConnectTimeout")


def pyproject() -> dict:
    from mercmac.tomlfile import loads

    return loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))


def test_every_package_and_example_folder_is_packaged():
    """pyproject lists its packages (the examples are mapped in): a new one must be listed."""
    listed = set(pyproject()["tool"]["setuptools"]["packages"])
    packages = {".".join(p.parent.relative_to(ROOT).parts) for p in PACKAGE.rglob("__init__.py")}
    examples = {".".join(("mercmac", *p.relative_to(ROOT).parts))
                for p in (ROOT / "examples").rglob("*") if p.is_dir()
                and "__pycache__" not in p.parts} | {"mercmac.examples"}
    assert listed == packages | examples


def test_lark_is_no_run_time_dependency():
    setup = pyproject()["project"]
    assert not any(d.startswith("lark") for d in setup["dependencies"])
    assert any(d.startswith("lark") for d in setup["optional-dependencies"]["dev"])


BLOCK_LARK = """
import sys
class NoLark:
    def find_spec(self, name, path=None, target=None):
        if name == "lark" or name.startswith("lark."):
            raise ModuleNotFoundError("No module named 'lark' (blocked by the test)")
sys.meta_path.insert(0, NoLark())
sys.argv = ["mercmac", *sys.argv[1:]]
from mercmac.__main__ import main
main()
"""


@pytest.mark.parametrize("args", [
    ["check", "examples/macros/manual-example4-four-modes.mcm"],
    ["check", "examples/rigs/raster/raster.rig.toml"],
    ["sim", "examples/macros/four-modes.mcm", "--buttons", "3@0-300ms,1@1s-1.2s"],
    ["fmt", "--check", "examples/macros/four-modes.mcm"],
    ["describe", "examples/macros/jog-box.mcm"],
    ["decompile", "examples/macros/manual-example4-four-modes.mcm"],
    ["flash", "PORT", "examples/macros/four-modes.mcm", "--dry-run"],
])
def test_commands_run_where_lark_cannot_be_imported(args, tmp_path):
    """Each command as a process in which `import lark` fails; a syntax error too, which goes
    through the error recovery (parse.py: the stand-alone parser generated from grammar.lark)."""
    from mercmac.emulator.chain import Chain
    from mercmac.emulator.ptyserver import PtyServer
    from mercmac.emulator.virtual import VirtualController

    (tmp_path / "bad.mcm").write_text("autostart {\n    MR 5 ]\n}\n", encoding="utf-8")
    env = {**os.environ, "PYTHONPATH": str(ROOT), "MERCMAC_DATA_DIR": str(tmp_path)}
    with PtyServer(Chain([VirtualController("C-863", 0)])) as server:
        args = [server.path if a == "PORT" else a for a in args]
        for words, code in ((args, 0), (["check", str(tmp_path / "bad.mcm")], 1)):
            done = subprocess.run([sys.executable, "-c", BLOCK_LARK, *words], cwd=ROOT, env=env,
                                  capture_output=True, text=True, timeout=120)
            assert done.returncode == code, done.stdout + done.stderr
            assert "lark" not in done.stderr and "Traceback" not in done.stderr, done.stderr
    assert "MM001 syntax" in done.stdout


def test_the_language_server_starts_where_lark_cannot_be_imported(tmp_path):
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    done = subprocess.run([sys.executable, "-c", BLOCK_LARK, "lsp"], input=lsp_session(),
                          capture_output=True, cwd=tmp_path, env=env, timeout=120)
    assert b'"capabilities"' in done.stdout and done.returncode == 0, done.stderr[-2000:]


def lsp_session() -> bytes:
    """initialize, initialized, shutdown and exit, framed (LSP base protocol)."""
    import json

    def frame(message: dict) -> bytes:
        body = json.dumps({"jsonrpc": "2.0", **message}).encode()
        return b"Content-Length: %d\r\n\r\n" % len(body) + body

    return b"".join([frame({"id": 1, "method": "initialize", "params": {"capabilities": {}}}),
                     frame({"method": "initialized", "params": {}}),
                     frame({"id": 2, "method": "shutdown"}), frame({"method": "exit"})])


# -- the released package ----------------------------------------------------------------------

def run(words: list[str], **kw) -> subprocess.CompletedProcess:
    return subprocess.run(words, capture_output=True, text=True, timeout=TIMEOUT_S, **kw)


def outside_env() -> dict:
    """This environment without PYTHONPATH: nothing of the source tree (a mercmac there, or
    its .egg-info, which pip would take for an installed mercmac)."""
    return {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}


def online_or_skip(done: subprocess.CompletedProcess, doing: str) -> None:
    """Skip, saying why, when DONE failed because PyPI could not be reached; fail otherwise."""
    if done.returncode != 0 and OFFLINE.search(done.stdout + done.stderr):
        pytest.skip(f"{doing} needs PyPI, which cannot be reached here")
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]


def shared(tmp_path_factory, name: str, make) -> Path:
    """`make(folder)`'s folder, made once for the whole run: in the base temporary folder that
    every pytest-xdist worker of this run shares (a worker's own is below it), under a lock,
    as xdist's documentation shares session fixtures; the tests of it may run on any worker."""
    from helpers.locking import held

    root = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        root = root.parent
    folder, made = root / name, root / f"{name}.made"
    with held(root / f"{name}.lock"):
        if not made.exists():
            shutil.rmtree(folder, ignore_errors=True)  # what a failed attempt left
            folder.mkdir()
            make(folder)  # skips (offline) or fails before `made` is written
            made.touch()
    return folder


@pytest.fixture(scope="module")
def released(tmp_path_factory) -> Path:
    """The sdist and the wheel, built by `python -m build` from a copy of the tree as a
    clone holds it (the wheel from the sdist, as build does: the sdist must hold enough)."""
    pytest.importorskip("build", reason="the extra `test` brings `build`")

    def build(work: Path) -> None:
        tree = work / "tree"
        shutil.copytree(ROOT, tree, ignore=shutil.ignore_patterns(
            ".git", ".venv", ".venvs", "node_modules", "__pycache__", "build", "dist",
            "*.egg-info", ".hypothesis", ".pytest_cache", "*.vcd", "*.vsix"))
        done = run([sys.executable, "-m", "build", "--outdir", str(work / "dist"), str(tree)],
                   env=outside_env(), cwd=work)
        online_or_skip(done, "`python -m build` (setuptools in an isolated environment)")

    return shared(tmp_path_factory, "release", build) / "dist"


@pytest.mark.slow
def test_twine_checks_the_sdist_and_the_wheel(released):
    pytest.importorskip("twine", reason="the extra `test` brings `twine`")
    files = sorted(map(str, released.iterdir()))
    assert len(files) == 2
    done = run([sys.executable, "-m", "twine", "check", "--strict", *files])
    assert done.returncode == 0 and done.stdout.count("PASSED") == 2, done.stdout + done.stderr


@pytest.mark.slow
def test_the_wheel_holds_the_examples_and_the_sdist_the_tests(released):
    import tarfile

    (wheel,) = released.glob("*.whl")
    held = {n.removeprefix("mercmac/examples/") for n in zipfile.ZipFile(wheel).namelist()
            if n.startswith("mercmac/examples/")}
    from mercmac import bundled

    assert held == set(bundled.texts()) and "rigs/raster/raster.rig.toml" in held
    # the page of `sim --web`: every asset ships in the package, none comes from the network
    static = {n for n in zipfile.ZipFile(wheel).namelist() if n.startswith("mercmac/web/static/")}
    assert static == {f"mercmac/web/static/{name}" for name in ("index.html", "app.js",
                                                                "style.css")}
    (sdist,) = released.glob("*.tar.gz")
    names = {n.split("/", 1)[1] for n in tarfile.open(sdist).getnames() if "/" in n}
    assert {"README.md", "LICENSE", "mercmac/grammar.lark", "examples/rigs/raster/x.mcm",
            "tests/conftest.py", "tests/helpers/readme.py"} <= names


@pytest.fixture(scope="module")
def installed(released, tmp_path_factory) -> Path:
    """A fresh venv with the wheel (and the extra `lsp`) installed from it: its bin/."""
    def install(venv: Path) -> None:
        assert run([sys.executable, "-m", "venv", str(venv)], env=outside_env()).returncode == 0
        (wheel,) = released.glob("*.whl")
        done = run([str(venv / "bin" / "python"), "-m", "pip", "install", "-q", f"{wheel}[lsp]"],
                   env=outside_env(), cwd=venv)
        online_or_skip(done, "installing the wheel's dependencies")

    return shared(tmp_path_factory, "venv", install) / "bin"


class Installed:
    """`mercmac` of the installed wheel, run as a user would: from FOLDER, nothing of the
    source tree on the path."""

    def __init__(self, bin: Path, data: Path):
        self.env = outside_env()
        self.env.update(PATH=f"{bin}{os.pathsep}{os.environ['PATH']}", MERCMAC_DATA_DIR=str(data))
        self.bin = bin

    def __call__(self, line: str, folder: Path, port: str = "") -> subprocess.CompletedProcess:
        words = [port if w in HARDWARE_PORTS else w for w in shlex.split(line)]
        out = None
        if ">" in words:
            at = words.index(">")
            words, out = words[:at], words[at + 1]
        assert words[0] == "mercmac"
        done = run([str(self.bin / "mercmac"), *words[1:]], cwd=folder, env=self.env)
        if out:
            (folder / out).write_text(done.stdout, encoding="utf-8")
        return done


def first_setup_sim() -> str:
    """The README's first set-up command, its last part: `mercmac sim examples/...`."""
    first = next(l.strip() for l in README.splitlines() if l.startswith("    python3 -m venv"))
    return first.split("&&")[-1].strip().replace(".venv/bin/mercmac", "mercmac")


@pytest.mark.slow
def test_the_installed_wheel_runs_the_readme(installed, tmp_path):
    home = tmp_path / "empty"
    home.mkdir()
    mercmac = Installed(installed, tmp_path / "data")
    where = run([str(installed / "python"), "-c", "import mercmac, importlib.util; "
                 "print(mercmac.__file__, importlib.util.find_spec('lark'))"],
                cwd=home, env=mercmac.env).stdout
    assert where.startswith(str(installed.parent)) and where.split()[-1] == "None", where

    def ok(line: str, code: int = 0, folder: Path = home, port: str = "") -> str:
        done = mercmac(line, folder, port)
        assert done.returncode == code and "Traceback" not in done.stderr, \
            f"{line}: exit {done.returncode}\n{done.stdout[-2000:]}{done.stderr[-2000:]}"
        return done.stdout + done.stderr

    assert "13 example files" in ok("mercmac examples")
    assert "button 1 pressed" in ok(first_setup_sim())
    ok("mercmac check examples/rigs/raster/raster.rig.toml")
    ok("mercmac sim examples/rigs/raster/raster.rig.toml --buttons x:1@0-100ms --until 1h")
    ok("mercmac sim examples/macros/manual-example4-four-modes.mcm --scenario "
       "examples/scenarios/manual-example4-four-modes.mode2.toml")
    ok("mercmac describe examples/macros/four-modes.mcm")
    ok("mercmac describe examples/rigs/raster/raster.rig.toml")
    assert "macro" in ok("mercmac decompile examples/macros/manual-example4-four-modes.mcm")
    ok("mercmac fmt --check examples/macros/four-modes.mcm")
    ok("mercmac build examples/macros/four-modes.mcm")
    assert "wrote" in ok("mercmac new start.mcm")
    ok("mercmac check start.mcm")
    ok("mercmac fmt --check start.mcm")
    ok("mercmac sim start.mcm --buttons 1@0-300ms --until 2s")
    ok("mercmac new rig/xy.rig.toml --target C-663")
    ok("mercmac sim rig/xy.rig.toml --buttons x:1@0-100ms --until 30s")
    _lsp_answers(installed, home, mercmac.env)
    emulator = subprocess.Popen([str(installed / "mercmac"), "emulate"], cwd=home,
                                env=mercmac.env, stdout=subprocess.PIPE, text=True)
    try:
        port = next(l.strip() for l in emulator.stdout if l.startswith("/"))
        for number, line in enumerate(commands()):
            folder = tmp_path / f"readme-{number}"
            folder.mkdir()
            prepare(folder, line, example4=home / "examples" / "macros" /
                    "manual-example4-four-modes.mcm")
            code, phrases = promise(line.replace("/dev/ttyUSB0", "PORT"))
            said = ok(line, code, folder, port)
            assert all(p in said for p in phrases), f"{line}: {phrases} not in {said}"
        ok(f"mercmac flash {port} start.mcm --dry-run")
        assert "verified" in ok(f"mercmac flash {port} start.mcm")
    finally:
        emulator.terminate()
        emulator.wait(timeout=60)


def _lsp_answers(bin: Path, folder: Path, env: dict) -> None:
    """`mercmac lsp` of the wheel answers initialize and shuts down on exit (extra `lsp`)."""
    done = subprocess.run([str(bin / "mercmac"), "lsp"], input=lsp_session(),
                          capture_output=True, cwd=folder, env=env, timeout=120)
    assert b'"capabilities"' in done.stdout and done.returncode == 0, done.stderr[-2000:]
