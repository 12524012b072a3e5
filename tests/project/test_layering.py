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
    "mercmac.vm": {"cli", "render", "sim", "upload", "emulator", "web"},  # no I/O, no text
    "mercmac.compiler": {"vm", "upload", "emulator", "sim", "cli", "render", "web"},
    "mercmac.upload": {"cli", "sim", "render", "emulator", "vm", "web"},  # plan and wire
    "mercmac.sim": {"cli", "upload", "emulator", "render", "web"},  # render reads sim
    "mercmac.emulator": {"cli", "sim", "render", "web"},
    "mercmac.render": {"cli", "web"},
    "mercmac.fmt": {"vm", "upload", "emulator", "sim", "cli", "render"},  # reads the compiler's tokens
    # what a rig is, read and checked: data and the compiler's checks, never what runs it
    "mercmac.rig": {"vm", "sim", "upload", "emulator", "cli", "render", "lsp", "decompile",
                    "fmt"},
    # words for stored macros: it reads the compiler (and the language server's re-checker,
    # to check a decompiled source fast), never a port, a simulation or the command line
    "mercmac.decompile": {"cli", "upload", "emulator", "sim"},
    # the editor's view of `check`: compiler, fmt, rigs and help texts; nothing that runs
    "mercmac.lsp": {"cli", "upload", "emulator", "sim", "vm", "decompile"},
    # the box in the browser: an application of the simulator beside the CLI, never a port
    "mercmac.web": {"cli", "upload", "emulator", "lsp", "decompile", "fmt"},
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


# -- one surface: no private members from outside ---------------------------------------
# The machine has one surface for whoever skips, keys and reports (the optimiser, a rig's
# joint skip, plot, VCD): outside mercmac/vm/ no module reads or writes another object's
# `_private` member (docs/architecture.md, "One way down"), nor reads a machine's state key
# by position, which would break silently when a field is added to it (vm/statekey.py).

# A namedtuple's own methods carry an underscore only so that they cannot clash with a field:
# they are its public API (the `collections` documentation), not private members.
NAMEDTUPLE_API = {"_replace", "_make", "_asdict", "_fields", "_field_defaults"}
# Foreign libraries that offer no public way to what is needed: (file, attribute) -> why.
FOREIGN = {
    ("mercmac/compiler/parse.py", "_mres"): "lark's scanner keeps its one compiled regex there",
    ("mercmac/lsp/server.py", "_send_response"): "pygls cannot answer a request it refused",
}
OUTSIDE_VM = [p for p in MODULES if "vm" not in p.relative_to(PACKAGE).parts[:1]]


def _private_uses(tree: ast.AST) -> list[tuple[int, str]]:
    """(line, text) for every `x._name` whose `x` is not self or cls (a dunder is public)."""
    found = []
    for node in ast.walk(tree):
        if (isinstance(node, ast.Attribute) and node.attr.startswith("_")
                and not node.attr.startswith("__") and node.attr not in NAMEDTUPLE_API
                and not (isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"))):
            found.append((node.lineno, ast.unparse(node)))
    return found


def _state_key_by_position(tree: ast.AST) -> list[tuple[int, str]]:
    """(line, text) for `X.STATE_KEY[...]`, `X.STATE_KEY.index(...)` and a subscript of a
    name bound to either: a state key read by where a field stands in it."""
    found, bound = [], set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Assign) and _names_state_key(node.value):
            bound |= {t.id for t in node.targets if isinstance(t, ast.Name)}
    for node in ast.walk(tree):
        if isinstance(node, ast.Subscript) and (
                _names_state_key(node.value)
                or (isinstance(node.value, ast.Name) and node.value.id in bound)):
            found.append((node.lineno, ast.unparse(node)))
        elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
              and node.func.attr == "index" and _names_state_key(node.func.value)):
            found.append((node.lineno, ast.unparse(node)))
    return found


def _names_state_key(node: ast.AST) -> bool:
    return ((isinstance(node, ast.Attribute) and node.attr == "STATE_KEY")
            or (isinstance(node, ast.Name) and node.id == "STATE_KEY"))


def test_the_walk_sees_private_uses_and_state_key_positions():
    tree = ast.parse("m._jump(j)\nself._x = 1\nk[Machine.STATE_KEY.index('block')]\n"
                     "K = Machine.STATE_KEY\nK[3]\np._replace(a=1)\nx.__class__\n")
    assert [t for _, t in _private_uses(tree)] == ["m._jump"]
    assert sorted(t for _, t in _state_key_by_position(tree)) == [
        "K[3]", "Machine.STATE_KEY.index('block')"]


@pytest.mark.parametrize("path", OUTSIDE_VM, ids=lambda p: _module_name(p))
def test_no_private_member_is_used_from_outside(path):
    tree = ast.parse(path.read_text(encoding="utf-8"))
    where = str(path.relative_to(ROOT).as_posix())
    found = [f"{where}:{line}: {text}" for line, text in _private_uses(tree)
             if (where, text.rpartition(".")[2]) not in FOREIGN]
    found += [f"{where}:{line}: {text} (by position)"
              for line, text in _state_key_by_position(tree)]
    assert found == [], "use the owner's public surface:\n" + "\n".join(found)


def test_every_foreign_exception_is_still_needed():
    for (file, attr), why in FOREIGN.items():
        uses = _private_uses(ast.parse((ROOT / file).read_text(encoding="utf-8")))
        assert any(text.endswith("." + attr) for _, text in uses), f"{file}: {attr} ({why}) is gone"
