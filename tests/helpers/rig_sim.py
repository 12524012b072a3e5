"""Two-controller rigs written to a folder for the rig simulator's tests (sim/rig.py)."""
from __future__ import annotations

from pathlib import Path

from helpers.paths import ROOT

RASTER = ROOT / "examples" / "rigs" / "raster" / "raster.rig.toml"


def rig_of(folder: Path, x: str, y: str, wires: str, extra: str = "") -> Path:
    """A rig file of two C-663s, x at 0 and y at 1, with these programs (`target` added),
    wires (TOML strings, comma-separated) and more top-level keys or tables (`extra`)."""
    (folder / "x.mcm").write_text("target C-663\n" + x, encoding="utf-8")
    (folder / "y.mcm").write_text("target C-663\n" + y, encoding="utf-8")
    path = folder / "t.rig.toml"
    path.write_text(f"wires = [{wires}]\n{extra}"
                    '[controllers.x]\naddress = 0\nmodel = "C-663"\nprogram = "x.mcm"\n'
                    '[controllers.y]\naddress = 1\nmodel = "C-663"\nprogram = "y.mcm"\n',
                    encoding="utf-8")
    return path


def rig_of_one(folder: Path, program: str) -> Path:
    """A rig file of one C-663, s at address 0, running `program` (`target` added)."""
    (folder / "s.mcm").write_text("target C-663\n" + program, encoding="utf-8")
    path = folder / "one.rig.toml"
    path.write_text('[controllers.s]\naddress = 0\nmodel = "C-663"\nprogram = "s.mcm"\n',
                    encoding="utf-8")
    return path
