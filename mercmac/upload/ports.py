"""Which port `flash`, `pull` and `scan` talk to, when the command line does not say it all.

In order: the PORT argument, `-p/--port`, `$MERCMAC_PORT`, then auto-detection:
the only serial port with PI's USB vendor id (0x1A72), else the only serial
port there is. Anything else is a `UsageError` (exit 2) that lists the candidates.
`flash FILE PORT`, the arguments swapped, is recognised and refused with the right order.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from mercmac.errors import UsageError
from mercmac.upload import survey
from mercmac.upload.survey import PortInfo

PORT_VARIABLE = "MERCMAC_PORT"


@dataclass(frozen=True, slots=True)
class Chosen:
    """The port to open, and how it was chosen when the command line did not name it."""

    port: str
    how: str = ""  # '' when given as PORT or -p; else 'MERCMAC_PORT', 'the only PI USB device', ...


def looks_like_program(text: str) -> bool:
    """A `.mcm` name, or an existing regular file: not a port (devices are not regular files)."""
    if text.lower().endswith(".mcm"):
        return True
    try:
        return Path(text).is_file()
    except (OSError, ValueError):
        return False


def split_flash_args(first: str | None, second: str | None, option: str | None,
                     command: str = "flash") -> tuple[str | None, str]:
    """(PORT or None, FILE) from `flash [PORT] FILE`; refuses a swapped pair or a missing FILE."""
    if second is None:
        if first is None:
            raise UsageError("no program file given",
                             hint=f"mercmac {command} [PORT] FILE.mcm")
        return None, first  # one argument: the file; the port comes from -p, the environment or a search
    if looks_like_program(first) and not looks_like_program(second):
        raise UsageError(f"{first!r} is a program file where the port goes: the arguments are swapped",
                         hint=f"mercmac {command} {second} {first}  (PORT first, then FILE)")
    if option is not None and option != first:
        raise UsageError(f"two ports given: {first!r} and -p/--port {option!r}",
                         hint=f"give the port once: mercmac {command} {first} {second}")
    return first, second


def check_port_arg(port: str | None, option: str | None, command: str) -> str | None:
    """The PORT of `pull`/`scan [PORT]`; a program file there, or two ports, is refused."""
    if port is not None and looks_like_program(port):
        raise UsageError(f"{port!r} is a program file where the port goes",
                         hint=f"mercmac {command} PORT (`mercmac ports` lists them)")
    if port is not None and option is not None and option != port:
        raise UsageError(f"two ports given: {port!r} and -p/--port {option!r}",
                         hint=f"give the port once: mercmac {command} {port}")
    return port if port is not None else option


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
        raise UsageError("no port given, and this computer has no serial ports",
                         hint="connect the controller (USB) or name the port: PORT, -p PORT or "
                              f"{PORT_VARIABLE}=PORT")
    candidates = pi or found
    kind = "PI USB devices" if pi else "serial ports, none of them a PI USB device"
    listed = ", ".join(_describe(p) for p in candidates)
    raise UsageError(f"no port given, and there are {len(candidates)} {kind}: {listed}", hint=hint)


def _describe(p: PortInfo) -> str:
    what = p.mercury or p.description
    return f"{p.device} ({what})" if what and what != "n/a" else p.device
