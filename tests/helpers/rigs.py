"""Small rigs written to a folder for the rig tests (docs/rigs.md, "The rig file"): the
example raster rig, two wired C-663s passing a token, a wait cycle, and rigs of any two
programs or of one."""
from __future__ import annotations

from pathlib import Path

from helpers.paths import ROOT

RASTER = ROOT / "examples" / "rigs" / "raster" / "raster.rig.toml"

# Two controllers that pass a token round: x raises out1 after its sweep, y steps on in1.
X = ("target C-663\nmacro go { MR 100, WS 0, CN 1, WN 2, CF 1, WF 2, goto go }\n"
     "autostart { goto go }\n")
Y = ("target C-663\nmacro go { WN 1, MR 10, WS 0, CN 2, WF 1, CF 2, goto go }\n"
     "autostart { goto go }\n")
# Each waits for the other's line before raising its own: a wait cycle (MR011).
DEAD_X = "target C-663\nmacro go { WN 2, MR 100, WS 0, CN 1, goto go }\nautostart { goto go }\n"
DEAD_Y = "target C-663\nmacro go { WN 1, MR 100, WS 0, CN 2, goto go }\nautostart { goto go }\n"
WIRES = 'wires = ["x.out1 -> y.in1", "y.out2 -> x.in2"]\n'


def controllers(x: str = "0", y: str = "1", model: str = "C-663") -> str:
    """The `[controllers.x]` and `[controllers.y]` tables: x.mcm and y.mcm at these addresses."""
    return (f'[controllers.x]\naddress = {x}\nmodel = "{model}"\nprogram = "x.mcm"\n'
            f'[controllers.y]\naddress = {y}\nmodel = "{model}"\nprogram = "y.mcm"\n')


def write_rig(folder: Path, toml: str | None = None, x: str = X, y: str = Y) -> Path:
    """A rig file `r.rig.toml` (default: the two wired controllers) and its programs."""
    (folder / "x.mcm").write_text(x, encoding="utf-8")
    (folder / "y.mcm").write_text(y, encoding="utf-8")
    path = folder / "r.rig.toml"
    path.write_text(WIRES + controllers() if toml is None else toml, encoding="utf-8")
    return path


def rig_of(folder: Path, x: str, y: str, wires: str, extra: str = "") -> Path:
    """A rig file of two C-663s, x at 0 and y at 1, with these programs (`target` added),
    wires (TOML strings, comma-separated) and more top-level keys or tables (`extra`)."""
    (folder / "x.mcm").write_text("target C-663\n" + x, encoding="utf-8")
    (folder / "y.mcm").write_text("target C-663\n" + y, encoding="utf-8")
    path = folder / "t.rig.toml"
    path.write_text(f"wires = [{wires}]\n{extra}" + controllers(), encoding="utf-8")
    return path


def rig_of_one(folder: Path, program: str) -> Path:
    """A rig file of one C-663, s at address 0, running `program` (`target` added)."""
    (folder / "s.mcm").write_text("target C-663\n" + program, encoding="utf-8")
    path = folder / "one.rig.toml"
    path.write_text('[controllers.s]\naddress = 0\nmodel = "C-663"\nprogram = "s.mcm"\n',
                    encoding="utf-8")
    return path


def rig_of_many(folder: Path, programs: list[str], wires: list[str]) -> Path:
    """A rig file of controllers c0, c1, ... at addresses 0, 1, ..., C-863s and C-663s in
    turn, with these programs (`target` added) and wires ("c0.out1 -> c1.in2", ...)."""
    tables = []
    for i, program in enumerate(programs):
        model = ("C-863", "C-663")[i % 2]
        (folder / f"c{i}.mcm").write_text(f"target {model}\n{program}", encoding="utf-8")
        tables.append(f'[controllers.c{i}]\naddress = {i}\nmodel = "{model}"\n'
                      f'program = "c{i}.mcm"\n')
    path = folder / "many.rig.toml"
    listed = ", ".join(f'"{w}"' for w in wires)
    path.write_text(f"wires = [{listed}]\n" + "".join(tables), encoding="utf-8")
    return path
