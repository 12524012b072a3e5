"""The application and the library meet in one place: below mercmac/cli/ the
library raises its own errors (mercmac.errors) and writes to no terminal stream; the CLI
words the errors and owns standard output and standard error (with render/, which draws
the text it is given a stream for).

Every module is read with `ast`, as tests/project/test_layering.py reads imports.
"""
from __future__ import annotations

import ast

import pytest

from helpers.paths import PACKAGE, ROOT

# The language server's standard output is its wire to the editor (LSP base protocol).
WIRES = {"mercmac/lsp/server.py": {"stdout"}}
MODULES = sorted(p for p in PACKAGE.rglob("*.py") if p.name != "parser_tables.py")  # lark's
# The application: mercmac/cli/, and the program's entry point before it (it says which signal
# stopped the program when the command line could not be imported yet: mercmac/__main__.py).
LIBRARY = [p for p in MODULES if p.relative_to(PACKAGE).parts[0] not in ("cli", "__main__.py")]
# The library less render/, which draws text onto the streams it is handed.
QUIET = [p for p in LIBRARY if p.relative_to(PACKAGE).parts[0] != "render"]


def _name(path) -> str:
    return path.relative_to(ROOT).as_posix()


def _tree(path) -> ast.Module:
    return ast.parse(path.read_text(encoding="utf-8"))


def _outside_main(tree: ast.Module):
    """Every node but those under `if __name__ == "__main__":` (a module run as a script)."""
    for node in tree.body:
        if not (isinstance(node, ast.If) and "__main__" in ast.unparse(node.test)):
            yield from ast.walk(node)


def _names(node) -> set[str]:
    if isinstance(node, ast.Name):
        return {node.id}
    if isinstance(node, ast.Attribute):
        return {node.attr}
    if isinstance(node, ast.alias):
        return {node.asname or node.name.rpartition(".")[2]}
    if isinstance(node, ast.ClassDef):
        return {node.name}
    return set()


@pytest.mark.parametrize("path", LIBRARY, ids=_name)
def test_the_library_raises_no_command_line_error(path):
    said = [node.lineno for node in ast.walk(_tree(path))
            if "UsageError" in _names(node) and hasattr(node, "lineno")]
    assert said == [], (f"{_name(path)}:{said[0]} names UsageError, the command line's own "
                        "error: raise a kind of mercmac.errors (InputError, SettingsError...) "
                        "and let mercmac/cli word it")


@pytest.mark.parametrize("path", QUIET, ids=_name)
def test_the_library_writes_to_no_terminal_stream(path):
    allowed = WIRES.get(_name(path), set())
    streams = [(node.lineno, node.attr) for node in _outside_main(_tree(path))
               if isinstance(node, ast.Attribute) and node.attr in ("stdout", "stderr")
               and isinstance(node.value, ast.Name) and node.value.id == "sys"
               and node.attr not in allowed]
    printed = [(node.lineno, "print") for node in _outside_main(_tree(path))
               if isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
               and node.func.id == "print"]
    found = streams + printed
    assert found == [], (f"{_name(path)}:{found[0][0]} uses {found[0][1]}: what people read "
                         "is written by mercmac/cli and mercmac/render")


def test_the_walk_sees_a_write_inside_a_function(tmp_path):
    sample = tmp_path / "sample.py"
    sample.write_text("import sys\n\ndef f():\n    sys.stdout.write('x')\n\n"
                      "if __name__ == '__main__':\n    print('run as a script')\n")
    seen = [n.attr for n in _outside_main(_tree(sample)) if isinstance(n, ast.Attribute)]
    assert seen == ["write", "stdout"]
