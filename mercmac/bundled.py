"""The examples mercmac carries: the repository's examples/ folder, which the wheel holds as
mercmac/examples (pyproject.toml maps it there), for `mercmac examples` to copy out."""
from __future__ import annotations

from pathlib import Path

from mercmac.errors import InputError

# What is an example, as pyproject.toml's package-data says: programs, rigs, scenarios.
PATTERNS = ("macros/*.mcm", "rigs/*/*.rig.toml", "rigs/*/*.mcm", "scenarios/*.toml")


def folder() -> Path:
    """Where the examples are: beside this module in an installed wheel, at the top of the
    repository in a clone (run from the source tree, or installed editable)."""
    here = Path(__file__).resolve().parent
    for place in (here / "examples", here.parent / "examples"):
        if place.is_dir():
            return place
    raise InputError(f"this mercmac ({here}) holds no examples: it was installed without "
                     f"them", hint="install it again from a wheel or from the repository")


def texts() -> dict[str, str]:
    """Every example: its path below the examples folder ('rigs/raster/x.mcm') -> its text,
    in path order."""
    root = folder()
    found = sorted({path for pattern in PATTERNS for path in root.glob(pattern)
                    if path.is_file()})
    return {path.relative_to(root).as_posix(): path.read_text(encoding="utf-8")
            for path in found}
