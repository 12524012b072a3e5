"""Where rigs live is written down (docs/architecture.md, "Where rigs live"): the docstring of
mercmac/rig/__init__.py maps every module about rigs, and the map names only modules that exist.

A module is about rigs when it is in mercmac/rig/, when "rig" or "rigs" is a word of its file
name (`rig_skip.py`, `rig.py`; not `trigger.py`), or when it is one of the rig rooms whose
name does not say so (ROOMS_NAMED_OTHERWISE)."""
from __future__ import annotations

import ast
import re

from helpers.paths import PACKAGE, ROOT

# rig rooms whose file names carry no "rig": the instant rule (the VM knows wires, not rigs),
# the virtual chain (served by `emulate --addresses` with no rig too)
ROOMS_NAMED_OTHERWISE = ("mercmac/vm/wiring.py", "mercmac/emulator/chain.py")


def _named_in_the_map() -> set[str]:
    text = ast.get_docstring(ast.parse((PACKAGE / "rig" / "__init__.py").read_text("utf-8")))
    return set(re.findall(r"mercmac/[\w/]+\.py", text or ""))


def _rig_modules() -> set[str]:
    found = set(ROOMS_NAMED_OTHERWISE)
    for path in PACKAGE.rglob("*.py"):
        words = path.stem.split("_")
        if path.parent == PACKAGE / "rig" or "rig" in words or "rigs" in words:
            found.add(path.relative_to(ROOT).as_posix())
    return found


def test_every_rig_module_is_on_the_map():
    missing = sorted(_rig_modules() - _named_in_the_map())
    assert not missing, f"mercmac/rig/__init__.py's map of rig rooms leaves out {missing}"


def test_every_module_on_the_map_exists():
    named = _named_in_the_map()
    gone = sorted(m for m in named if not (ROOT / m).is_file())
    assert len(named) >= len(ROOMS_NAMED_OTHERWISE) and not gone, \
        f"mercmac/rig/__init__.py's map names modules that do not exist: {gone}"
