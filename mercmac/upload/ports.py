"""Which port `flash`, `pull` and `scan` talk to, when the command line does not say it all.

In order: the port given (the PORT argument or `-p/--port`; mercmac.cli.upload reads
them), `$MERCMAC_PORT`, then auto-detection: the only serial port with PI's USB
vendor id (0x1A72), else the only serial port there is. Anything else is
`NotChosen` (exit 2), which lists the candidates.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Callable

from mercmac.upload import survey
from mercmac.upload.errors import NotChosen
from mercmac.upload.survey import PortInfo

PORT_VARIABLE = "MERCMAC_PORT"


@dataclass(frozen=True, slots=True)
class Chosen:
    """The port to open, and how it was chosen when the command line did not name it."""

    port: str
    how: str = ""  # '' when given as PORT or -p; else 'MERCMAC_PORT', 'the only PI USB device', ...


def resolve(port: str | None, *, environ=None,
            ports: Callable[[], list[PortInfo]] | None = None) -> Chosen:
    """The port to open: the one given, `$MERCMAC_PORT`, or the only likely Mercury port."""
    if port is not None:
        return Chosen(port)
    if chosen := (os.environ if environ is None else environ).get(PORT_VARIABLE, "").strip():
        return Chosen(chosen, PORT_VARIABLE)
    found = (ports or survey.list_ports)()
    pi = [p for p in found if p.mercury]
    if len(pi) == 1:
        return Chosen(pi[0].device, f"the only PI USB device ({pi[0].mercury})")
    if not pi and len(found) == 1:
        return Chosen(found[0].device, "the only serial port")
    hint = f"name it: PORT, -p PORT or {PORT_VARIABLE}=PORT; `mercmac ports` lists them"
    if not found:
        raise NotChosen("no port given, and this computer has no serial ports",
                        hint="connect the controller (USB) or name the port: PORT, -p PORT or "
                             f"{PORT_VARIABLE}=PORT")
    candidates = pi or found
    kind = "PI USB devices" if pi else "serial ports, none of them a PI USB device"
    listed = ", ".join(_describe(p) for p in candidates)
    raise NotChosen(f"no port given, and there are {len(candidates)} {kind}: {listed}", hint=hint)


def _describe(p: PortInfo) -> str:
    what = p.mercury or p.description
    return f"{p.device} ({what})" if what and what != "n/a" else p.device
