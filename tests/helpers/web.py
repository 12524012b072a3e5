"""A simulation of a program or a rig as `sim --web` makes it, for the tests of tests/web."""
from __future__ import annotations

from pathlib import Path

from mercmac.rig.open import open_program, open_rig
from mercmac.sim.simulate import Simulation
from mercmac.vm.models import Options


def simulation(path: Path, options: Options = Options()) -> Simulation:
    """The simulation of `path` (a program, or a rig file) that the live box runs, on a
    bench of `options` (switches, servo)."""
    opened = (open_rig(str(path)).accepted() if path.name.endswith(".rig.toml")
              else open_program(str(path)))
    return Simulation(opened.rig, {n: c.program for n, c in opened.programs.items()},
                      options=options, fast_forward="quiet")
