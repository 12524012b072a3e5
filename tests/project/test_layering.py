"""The house has floors (docs/architecture.md, "The floors"): data flows one way.

Every import of every module under mercmac/ is read with `ast` - at the top, in
functions, under `if` - and checked against the layers below. A second test runs
`mercmac check` in a fresh interpreter and looks at what it imported: check stays light.
"""
from __future__ import annotations

import ast
import json
import os
import subprocess
import sys

import pytest

from helpers.paths import FOUR_MODES, PACKAGE, ROOT

# Modules every layer may use: they import none of the subpackages (mercmac.ops names the Op
# that mdtext reads and the compiler lowers to: neither imports the other for it).
FOUNDATION = {"mercmac", "mercmac.__version__", "mercmac.commands", "mercmac.diagnostics",
              "mercmac.errors", "mercmac.mdtext", "mercmac.names", "mercmac.ops",
              "mercmac.outfile", "mercmac.source", "mercmac.timespec"}

# layer -> the layers it must never import
FORBIDDEN = {
    "mercmac.vm": {"cli", "render", "sim", "upload", "emulator"},  # the core: no I/O, no text
    "mercmac.compiler": {"vm", "upload", "emulator", "sim", "cli", "render"},
    "mercmac.upload": {"cli", "sim", "render", "emulator", "vm"},  # plan and wire, no drawing
    "mercmac.sim": {"cli", "upload", "emulator", "render"},  # render reads sim, never the reverse
    "mercmac.emulator": {"cli", "sim", "render"},
    "mercmac.render": {"cli"},
    "mercmac.fmt": {"vm", "upload", "emulator", "sim", "cli", "render"},  # reads the compiler's tokens
}


def _module_name(path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path) -> list[tuple[int, str]]:
    """(line, module) for every import in the file, relative ones made absolute."""
    name = _module_name(path)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found += [(node.lineno, a.name) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                up = package.split(".")[:len(package.split(".")) - node.level + 1]
                base = ".".join(up + ([node.module] if node.module else []))
            found.append((node.lineno, base))
            found += [(node.lineno, f"{base}.{a.name}") for a in node.names]
    return [(line, m) for line, m in found if m == "mercmac" or m.startswith("mercmac.")]


def _layer(module: str) -> str | None:
    """'vm' for mercmac.vm.machine; None for the foundation modules."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 and (PACKAGE / parts[1]).is_dir() else None


MODULES = sorted(p for p in PACKAGE.rglob("*.py") if p.name != "parser_tables.py")


def test_the_walk_sees_imports_inside_functions():
    imports = dict((m, line) for line, m in _imports(PACKAGE / "cli" / "run.py"))
    assert "mercmac.render.sim" in imports  # imported inside a function


@pytest.mark.parametrize("path", MODULES, ids=lambda p: _module_name(p))
def test_imports_follow_the_layers(path):
    name = _module_name(path)
    mine = _layer(name)
    forbidden = next((f for layer, f in FORBIDDEN.items()
                      if name == layer or name.startswith(layer + ".")), set())
    for line, target in _imports(path):
        theirs = _layer(target)
        where = f"{path.relative_to(ROOT)}:{line} imports {target}"
        if name in FOUNDATION or (mine is None and name != "mercmac.__main__"):
            assert theirs is None, f"{where}: a foundation module imports a layer"
        assert theirs not in forbidden, f"{where}: mercmac.{mine} must not import mercmac.{theirs}"
        if theirs == "cli":
            assert mine == "cli" or name == "mercmac.__main__", f"{where}: only the CLI uses the CLI"


# -- check stays light --------------------------------------------------------

_PROBE = """
import json, sys
from click.testing import CliRunner
from mercmac.cli import main
result = CliRunner().invoke(main, ["check", *sys.argv[1:]])
print(json.dumps({"exit": result.exit_code, "modules": sorted(sys.modules)}))
"""
# Heavy or unrelated to checking: rich (only for colour), the language server, plotting,
# and the simulator, the VM, the uploader and the emulator with pyserial.
HEAVY = ("rich", "pygls", "lsprotocol", "matplotlib", "plotly", "serial", "mercmac.lsp",
         "mercmac.vm", "mercmac.sim", "mercmac.upload", "mercmac.emulator")


@pytest.mark.parametrize("args", [[], ["--format", "json"]], ids=["text", "json"])
def test_check_imports_nothing_heavy(args):
    env = {k: v for k, v in os.environ.items() if k not in ("FORCE_COLOR",)} | {"NO_COLOR": "1"}
    out = subprocess.run([sys.executable, "-c", _PROBE, *args, str(FOUR_MODES)],
                         capture_output=True, text=True, cwd=ROOT, env=env, timeout=120)
    assert out.returncode == 0, out.stderr
    probe = json.loads(out.stdout.splitlines()[-1])
    assert probe["exit"] == 0
    heavy = [m for m in probe["modules"]
             if any(m == h or m.startswith(h + ".") for h in HEAVY) or "plot" in m.split(".")[-1]]
    assert heavy == []
