"""Opening a port and meeting the controller there: select, stop, identify
(docs/uploader.md, "The serial link").

Errors of the lower layers are reworded here into `UploadError`s that say
what to check; nothing in this module writes a macro.
"""
from __future__ import annotations

import os
import stat
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Callable, Iterator

from mercmac import outfile
from mercmac.commands import MODELS
from mercmac.upload.controller import BadReply, Controller, ControllerError, Flood, LinkLost, NoAnswer
from mercmac.upload.errors import PortError, Refused
from mercmac.upload.protocol import Version, quote
from mercmac.upload.transport import DEFAULT_BAUD, PortUnavailable, Timing, Transport


@dataclass(frozen=True, slots=True)
class Identity:
    """Who answered: VE's model and firmware, and whether we stopped a running macro."""

    version: Version
    stopped_macro: bool
    address: int = 0  # where it answered: --address, or the only one a search found


@contextmanager
def open_controller(port: str, address: int = 0, *, baud: int = DEFAULT_BAUD,
                    timing: Timing = Timing(),
                    tap: Callable[[str, bytes], None] | None = None) -> Iterator[Controller]:
    """A Controller on a freshly opened port, closed again on the way out."""
    not_a_port = _not_a_port(port)
    if not_a_port:
        raise PortError(f"cannot open {port}: {not_a_port}",
                        hint="`mercmac ports` lists the serial ports of this computer")
    try:
        transport = Transport(port, baud, timing, tap)
    except PortUnavailable as e:
        said = str(e)
        if "inappropriate ioctl" in said.lower():  # ENOTTY: a device without a line (/dev/null)
            said = f"cannot open {port}: it is a device, but not a serial port"
        raise PortError(said, hint=_port_hint(said)) from None
    with transport:
        yield Controller(transport, address)


def _not_a_port(port: str) -> str:
    """Why PORT cannot be a serial port, when it names a file that is no device (a regular
    file, a FIFO, a folder): looked at, never opened, so a FIFO cannot hold the open up.
    '' when it may be one (a device, a URL, a name the system has no file for: COM3)."""
    if "://" in port:
        return ""
    try:
        mode = os.stat(port).st_mode
    except (OSError, ValueError):
        return ""  # opening it says what is wrong
    if stat.S_ISCHR(mode):
        return ""
    what = "a regular file" if stat.S_ISREG(mode) else outfile.kind(mode)
    return f"it is {what}, not a serial port"


def identify(controller: Controller) -> Identity:
    """Select the address, stop a running macro, read VE; Refused if nothing fits."""
    try:
        controller.select()
        before = controller.status()  # '%' answers without stopping a macro (MS176E §6.3)
        version = controller.identify()  # 'V' stops a running macro (MS176E §3.8.3)
        running = bool(before and before.macro_running)
        if running and (after := controller.status()) and after.macro_running:
            raise Refused(f"{_where(controller)} keeps running a macro after VE; nothing was written",
                          hint="stop it with any key in a terminal, or power-cycle it")
    except ControllerError as e:
        raise refusal(controller, e) from None
    return Identity(version, running, controller.address)


def refusal(controller: Controller, e: ControllerError) -> Refused:
    """A lower-layer failure before the first write, as a message with a cause and a hint."""
    where = _where(controller)
    if isinstance(e, NoAnswer):
        return Refused(f"nothing answers at {where} ({e}); nothing was written",
                       hint=_silence_hint(controller))
    if isinstance(e, Flood):
        return Refused(f"the device at {where} does not stop sending: {e}; nothing was written",
                       hint="a controller whose macro reports without pause, or a device that is "
                            "not a Mercury controller: power-cycle it, or check the port")
    if isinstance(e, BadReply):
        return Refused(f"the device at {where} does not answer like a Mercury controller: "
                       f"{e}; nothing was written",
                       hint=f"a baud rate other than the controller's garbles replies: check "
                            f"DIP switches 5-6 against --baud {controller.transport.baud}")
    if isinstance(e, LinkLost):
        return Refused(f"the port failed before anything was written: {e}",
                       hint="check the cable and that the USB adapter is still there")
    return Refused(f"{where}: {e}; nothing was written")


def check_model(identity: Identity, target: str | None, file: str, *, force: bool) -> str | None:
    """Refuse when the controller is not the file's target; with force, the warning to show.
    A controller whose VE names no model mercmac knows is taken to be the target."""
    model = identity.version.model
    if model is None:
        return _unknown_model(identity.version, target, file)
    if target is None or target == model:
        return None
    text = f"the controller is a {model}, but {file or 'the program'} targets the {target}"
    if force:
        return text + " (flashing anyway: --force)"
    raise Refused(text + "; nothing was written",
                  hint=f"use --force to flash it anyway, or --target {model} to check the "
                       f"file against this controller")


def _unknown_model(version: Version, target: str | None, file: str) -> str:
    """A VE that names no model mercmac knows (older firmware, the C-862 predecessor): go on
    as the program's target, and say so; refuse only when there is no target to go on with."""
    said = (f"VE answered {quote(version.text)}, which names no model mercmac knows "
            f"({' or '.join(MODELS)})")
    if target is None:
        raise Refused(f"{said}, and {file or 'the program'} names no `target`; nothing was written",
                      hint=f"give the model to flash it as: --target {' or '.join(MODELS)}, "
                           f"or a `target` line in the file")
    return f"{said}; going on as the {target} the program targets"


def _where(controller: Controller) -> str:
    return f"address {controller.address} on {controller.transport.port}"


def _silence_hint(controller: Controller) -> str:
    return (f"check power and cable, that DIP switches 1-4 set address {controller.address} "
            f"(MS176E §3.1.3) and switches 5-6 the baud rate {controller.transport.baud}; "
            f"`mercmac scan {controller.transport.port}` lists the addresses that answer")


def _port_hint(message: str) -> str:
    text = message.lower()
    if "lock" in text or "busy" in text:
        return "another program (a terminal, MMCRun, a second mercmac) has the port open"
    if "permission" in text or "access is denied" in text:
        return "on Linux, add yourself to the group owning the port (often `dialout`)"
    return "`mercmac ports` lists the serial ports of this computer"
