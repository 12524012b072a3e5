"""A rig's fast-forward against the single controller's when no pass changes a wire:
one program, `macro spin { CN 1, CF 1, goto spin }` from the autostart macro,

    python benchmarks/rig_spin.py [--until 1500d]

(a) `sim FILE --until 1500d` for the program alone;
(b) `sim RIG --until 1500d` for a rig of one controller running it.
Each runs in a fresh interpreter (start-up included, as sim_speed.py measures) and is given
up after GIVE_UP seconds (printed as "over"). The rig's skip of passes that change no wire
should cost what the single controller's costs: the ratio (b) / (a) is printed, measured in
this one run (goal: under 2).
"""
from __future__ import annotations

import os
import subprocess
import sys
import tempfile

from sim_speed import measure

SPIN = "target C-663\nmacro spin { CN 1, CF 1, goto spin }\nautostart { goto spin }\n"
RIG = '[controllers.s]\naddress = 0\nmodel = "C-663"\nprogram = "spin.mcm"\n'
GIVE_UP = 120  # s of wall time for one run


def wall_of(path: str, until: str) -> float | None:
    """Wall seconds of `sim PATH --until UNTIL`; None past GIVE_UP."""
    try:
        wall, _ = measure([path, "--until", until], timeout=GIVE_UP)
    except subprocess.TimeoutExpired:
        return None
    return wall


def _shown(wall: float | None) -> str:
    return f"over {GIVE_UP} s" if wall is None else f"{wall:.2f} s"


def main() -> None:
    until = sys.argv[sys.argv.index("--until") + 1] if "--until" in sys.argv else "1500d"
    with tempfile.TemporaryDirectory() as folder:
        program, rig = os.path.join(folder, "spin.mcm"), os.path.join(folder, "spin.rig.toml")
        with open(program, "w", encoding="utf-8") as f:
            f.write(SPIN)
        with open(rig, "w", encoding="utf-8") as f:
            f.write(RIG)
        alone, joint = wall_of(program, until), wall_of(rig, until)
    print(f"spin alone (sim FILE --until {until}): {_shown(alone)} wall")
    print(f"spin as a rig of one (sim RIG --until {until}): {_shown(joint)} wall")
    if alone is not None and joint is not None:
        print(f"rig / file: {joint / alone:.2f}")


if __name__ == "__main__":
    main()
