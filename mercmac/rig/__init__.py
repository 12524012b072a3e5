"""Rigs (docs/rigs.md): several controllers on one RS-232/USB daisy chain (MS176E
§3.2), their programs, the box, the joystick and the wires between their I/O lines.

    NAME.rig.toml --load (locate: positions)--> Rig + the file's own diagnostics
                  --checks--> the rig rules (MRnnn, in mercmac.diagnostics) and each program's
                              findings; each program checked with its controller's model
                  --accept--> the Rig and its compiled programs, for the commands that run
                              it (sim, describe, emulate --rig, flash), or RigRefused with
                              `check`'s findings

Where rigs live (docs/architecture.md, "Where rigs live"): every module about rigs, by floor,
each with what it owns. tests/project/test_rig_rooms.py holds this map to the files.

Data and reading:
    mercmac/rig/__init__.py        this map; `is_rig_path`, the `*.rig.toml` test of a path
    mercmac/rig/model.py           what a rig is: controllers, box, joystick, wires (data only)
    mercmac/rig/load.py            NAME.rig.toml -> a Rig, or the file's own findings (MR001-3)
    mercmac/rig/locate.py          line and column of keys, headers and wires in a rig file
    mercmac/rig/presses.py         what a person may press on a rig (box buttons, joystick)
Checking:
    mercmac/rig/checks.py          the rig rules (MR004-MR012) and `check RIG`
    mercmac/rig/accept.py          the one way in for commands that run a rig; RigRefused
Simulating:
    mercmac/vm/wiring.py           the instant rule: machines joined by wires on one clock
    mercmac/sim/rig.py             every controller of a rig on one simulated clock (`sim RIG`)
    mercmac/sim/rig_ff.py          fast-forward over the passes the whole rig repeats
    mercmac/sim/rig_scenario.py    rig scenarios: steps and expectations per controller
    mercmac/sim/rig_vcd.py         one VCD of a rig, a scope per controller
    mercmac/cli/run_rig.py         the work of `sim RIG`: --buttons, --joystick, output
Drawing:
    mercmac/sim/rig_plot.py        the rig's picture (`sim RIG --plot`): lanes and the path
    mercmac/render/rig.py          the merged timeline and JSON of a rig's simulation
    mercmac/decompile/rig.py       a rig in plain words and its call graph (`describe RIG`)
Hardware:
    mercmac/emulator/chain.py      a virtual daisy chain on one pty (`emulate --rig`)
    mercmac/upload/rig.py          flashing every controller of a chain; pulling a chain
Editor:
    mercmac/lsp/rigs.py            rig files and the programs a rig names, in the editor
"""

SUFFIX = ".rig.toml"


def is_rig_path(path: str) -> bool:
    """True for a file named like a rig (`*.rig.toml`, any case). Here, not in load.py, so
    that the commands that take a file or a rig (check, sim, fmt, flash) tell them apart
    without importing the rig reader (`check`'s start-up: benchmarks/check_latency.py)."""
    return str(path).lower().endswith(SUFFIX)
