"""Rigs (docs/rigs.md): several controllers on one RS-232/USB daisy chain (MS176E
§3.2), their programs, the box, the joystick and the wires between their I/O lines. A lone
program is a rig of one (Rig.of_program): every command that takes a rig runs one the same
way, and shows the controllers' names only where there are several.

    NAME.rig.toml --open (read, locate: positions)--> Rig + the file's own diagnostics
                  --checks--> the rig rules (MRnnn, in mercmac.diagnostics) and each program's
                              findings; each program checked with its controller's model
                  --accepted--> the Rig and its compiled programs, for the commands that run
                              it (sim, describe, emulate --rig, flash), or RigRefused with
                              `check`'s findings
    NAME.mcm      --open_program--> a rig of one, its program compiled, or RigRefused

Where rigs live (docs/architecture.md, "Where rigs live"): every module about several
controllers, by floor, each with what it owns; in the other floors a rig's module is
`rig.py`, or `rig_NOUN.py` where a floor has more than one. The pipelines themselves (sim,
render, flash, describe, the emulator's server) are one for one controller or sixteen and
live where a lone program's always did. tests/project/test_rig_rooms.py holds this map to
the files.

Data and reading:
    mercmac/rig/__init__.py        this map; `is_rig_path`, the `*.rig.toml` test of a path
    mercmac/rig/model.py           what a rig is: controllers, box, joystick, wires (data only)
    mercmac/rig/load.py            NAME.rig.toml -> a Rig, or the file's own findings (MR001-3)
    mercmac/rig/locate.py          line and column of keys, headers and wires in a rig file
    mercmac/rig/presses.py         what a person may press on a rig (box buttons, joystick)
Checking:
    mercmac/rig/checks.py          the rig rules (MR004-MR012) and `check RIG`
    mercmac/rig/open.py            the one way every command opens a rig, or a lone program
Simulating:
    mercmac/vm/wiring.py           the instant rule: machines joined by wires on one clock
    mercmac/sim/group.py           the controllers wires join: each group runs on its own
    mercmac/sim/rig_skip.py        fast-forward over the passes a wired group repeats jointly
    mercmac/sim/rig_deadlock.py    a rig whose controllers wait for good (MH008)
Drawing:
    mercmac/sim/rig_plot.py        the lanes of several controllers, and the path they draw
    mercmac/decompile/rig.py       what the wires carry, and a call graph with a cluster each
Hardware:
    mercmac/emulator/chain.py      a virtual daisy chain on one pty (`emulate --rig`)
    mercmac/upload/rig.py          a rig's backup paths; pulling a chain into a rig folder
Editor:
    mercmac/lsp/rig.py             rig files and the programs a rig names, in the editor
    mercmac/lsp/links.py           a rig file's `program` values and the files they name
"""

SUFFIX = ".rig.toml"


def is_rig_path(path: str) -> bool:
    """True for a file named like a rig (`*.rig.toml`, any case). Here, not in load.py, so
    that the commands that take a file or a rig (check, sim, fmt, flash) tell them apart
    without importing the rig reader (`check`'s start-up: benchmarks/check_latency.py)."""
    return str(path).lower().endswith(SUFFIX)
