"""A simulation of a program or a rig as `sim --web` makes it, for the tests of tests/web."""
from __future__ import annotations

from pathlib import Path

from mercmac.rig.open import open_program, open_rig
from mercmac.sim.simulate import Simulation


def simulation(path: Path) -> Simulation:
    """The simulation of `path` (a program, or a rig file) that the live box runs."""
    opened = (open_rig(str(path)).accepted() if path.name.endswith(".rig.toml")
              else open_program(str(path)))
    return Simulation(opened.rig, {n: c.program for n, c in opened.programs.items()},
                      fast_forward="quiet")
