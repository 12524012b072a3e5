"""Rigs (docs/rigs.md): several controllers on one RS-232/USB daisy chain (MS176E
§3.2), their programs, the box, the joystick and the wires between their I/O lines.

    NAME.rig.toml --load (locate: positions)--> Rig + the file's own diagnostics
                  --checks--> the rig rules (MRnnn, in mercmac.diagnostics) and each program's
                              findings; each program checked with its controller's model
                  --accept--> the Rig and its compiled programs, for the commands that run
                              it (sim, describe, emulate --rig, flash), or RigRefused with
                              `check`'s findings
"""

SUFFIX = ".rig.toml"


def is_rig_path(path: str) -> bool:
    """True for a file named like a rig (`*.rig.toml`, any case). Here, not in load.py, so
    that the commands that take a file or a rig (check, sim, fmt, flash) tell them apart
    without importing the rig reader (`check`'s start-up: benchmarks/check_latency.py)."""
    return str(path).lower().endswith(SUFFIX)
