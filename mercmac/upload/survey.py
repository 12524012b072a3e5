"""Looking without writing: `pull` a controller's macros, `scan` addresses, list `ports`."""
from __future__ import annotations

from contextlib import AbstractContextManager, nullcontext
from dataclasses import dataclass
from typing import Callable

from mercmac.upload import backup
from mercmac.upload.controller import (BadReply, Controller, ControllerError, Flood, LinkLost,
                                       NoAnswer)
from mercmac.upload.errors import NotChosen, Refused, UploadError
from mercmac.upload.protocol import Status, Version
from mercmac.upload.connect import Identity, identify, open_controller, refusal
from mercmac.upload.transport import DEFAULT_BAUD, Timing, Transport

PI_VENDOR = 0x1A72  # USB vendor id of Physik Instrumente
PI_PRODUCTS = {0x1007: "C-863"}  # USB product ids known to be Mercury controllers

# Around a search for the controller's address: yields where each address probed is told.
Searching = Callable[[], AbstractContextManager[Callable[[int], None]]]


@dataclass(frozen=True, slots=True)
class Pulled:
    """A controller's macros and the .mcm text that holds them."""

    identity: Identity
    macros: dict[int, str]
    text: str


def pull_file(port: str, *, address: int | None = 0, baud: int = DEFAULT_BAUD,
              timing: Timing = Timing(), searching: Searching | None = None) -> Pulled:
    """The macros of the controller on PORT, for a .mcm file: at `address`, or with None
    found as flash_file finds it (`reach`). Reading stops a running macro (MS176E §3.8.3)."""
    with open_controller(port, address or 0, baud=baud, timing=timing) as c:
        reach(c, address, searching)
        return pull(c)


def reach(controller: Controller, address: int | None, searching: Searching | None = None) -> None:
    """Point CONTROLLER at `address`; None: 0 if anything answers there, else the only one of
    1-15 that answers (find_address), inside `searching()`."""
    if address is None:
        with (searching or _unseen)() as probing:
            controller.address = find_address(controller.transport, probing)


def _unseen() -> AbstractContextManager[Callable[[int], None]]:
    return nullcontext(lambda address: None)


def pull(controller: Controller) -> Pulled:
    """Identify, then read every slot (TM, TZ) into .mcm text."""
    who = identify(controller)
    try:
        macros = controller.read_all()
    except ControllerError as e:
        raise refusal(controller, e) from None
    t = controller.transport
    text = backup.to_mcm(macros, who.version, port=t.port, address=controller.address)
    return Pulled(who, macros, text)


@dataclass(frozen=True, slots=True)
class Found:
    """One address that answered a scan."""

    address: int
    status: Status | None  # None when what came was not a status report (quoted in `note`)
    version: Version | None  # None when a running macro was left alone, or VE was garbled
    note: str = ""
    shared: bool = False  # two controllers answered: both are set to this address

    @property
    def model(self) -> str:
        if self.version:
            return self.version.name
        return self.status.layout if self.status else "?"


def scan(transport: Transport, addresses=range(16), *, stop: bool = False,
         on_address: Callable[[int], None] | None = None) -> list[Found]:
    """Which addresses answer `%`; VE for those not running a macro (or all, with stop).

    An address whose answer is not a status report is listed with what came; a flood
    of such replies ends the scan there, as the line carries nothing readable. An address
    where two status reports answer one `%` is `shared`: two controllers are set to it.
    `on_address(n)` is told each address before it is probed (a progress line).
    """
    found = []
    for address in addresses:
        if on_address:
            on_address(address)
        controller = Controller(transport, address)
        status = None
        try:
            controller.select()  # 0x01 + address: the others deselect (MS176E §3.2)
            status = controller.probe()  # '%' does not stop a running macro (§6.3)
            shared = controller.answered_again(transport.timing.settle)
            if status.macro_running and not stop:
                found.append(_found(address, status, None, "macro running, left alone", shared))
                continue
            found.append(_found(address, status, controller.identify(), "", shared))
        except LinkLost as e:
            raise UploadError(f"scan stopped at address {address}: {e}") from None
        except Flood as e:
            found.append(Found(address, status, None,
                               f"{'VE: ' if status else ''}{e}; scan stopped here"))
            break
        except BadReply as e:
            found.append(Found(address, status, None, f"VE: {e}" if status else str(e)))
        except ControllerError as e:  # NoAnswer: nobody at this address
            if status:
                found.append(Found(address, status, None, f"VE: {e}"))
    return found


def _found(address: int, status: Status, version: Version | None, note: str,
           shared: bool) -> Found:
    """A Found; a shared address says so first in its note."""
    if shared:
        note = "; ".join(filter(None, ["two controllers answered: both are set to this "
                                       "address (DIP switches 1-4, MS176E §3.1.3)", note]))
    return Found(address, status, version, note, shared)


def find_address(transport: Transport,
                 on_address: Callable[[int], None] | None = None) -> int:
    """The address to use when none was given: 0 if anything answers there (the default
    of old, and no search), else the only one of 1-15 that answers `%`.

    Addresses 1-15 are probed with the transport's search timing (Timing.search each: with
    the default 0.3 s, about 5 s in all).
    Refused when none answers; NotChosen (exit 2) when several do: say which with --address.
    """
    at_zero = Controller(transport, 0)
    try:
        at_zero.select()
        at_zero.probe()  # '%' does not stop a running macro (§6.3)
        return 0
    except LinkLost as e:
        raise refusal(at_zero, e) from None
    except NoAnswer:
        pass  # nobody at 0: search 1-15
    except ControllerError:
        return 0  # an answer at 0, even a garbled one: 0, as without the search (identify says why)
    timing = transport.timing
    try:
        with transport.per_address():
            found = scan(transport, range(1, 16), on_address=on_address)
    except UploadError as e:
        raise Refused(f"the port failed while looking for the controller: {e}; nothing was written",
                      hint="check the cable and that the USB adapter is still there") from None
    answering = [f for f in found if f.status]
    if len(answering) == 1:
        return answering[0].address
    where = f"on {transport.port}"
    if answering:
        listed = ", ".join(f"{f.address} ({f.model})" for f in answering)
        raise NotChosen(f"no --address given, and {len(answering)} controllers answer {where}: "
                        f"addresses {listed}; nothing was written",
                        hint=f"say which one: --address {answering[0].address}")
    if found:
        raise Refused(f"no controller answers like a Mercury at addresses 0-15 {where} "
                      f"(garbled replies at {', '.join(str(f.address) for f in found)}); "
                      f"nothing was written",
                      hint=f"a baud rate other than the controller's garbles replies: check "
                           f"DIP switches 5-6 against --baud {transport.baud}")
    raise Refused(f"nothing answers at addresses 0-15 {where}; nothing was written",
                  hint=f"check power and cable, and that DIP switches 5-6 set the baud rate "
                       f"{transport.baud}; each address was given {timing.search:g} s "
                       f"(--timeout gives more)")


def answered(found: list[Found]) -> bool:
    """Whether any controller answered the scan with a status report."""
    return any(f.status for f in found)


@dataclass(frozen=True, slots=True)
class PortInfo:
    """One serial port of this computer, and whether it looks like a Mercury."""

    device: str
    description: str
    vid: int | None
    pid: int | None
    serial_number: str | None

    @property
    def mercury(self) -> str | None:
        """'C-863' for a known product id, 'PI device' for PI's vendor id, else None."""
        if self.vid != PI_VENDOR:
            return None
        return PI_PRODUCTS.get(self.pid or -1, "PI device")


def list_ports() -> list[PortInfo]:
    """The serial ports pyserial sees, PI's first."""
    from serial.tools import list_ports as lp

    ports = [PortInfo(p.device, p.description or "", p.vid, p.pid, p.serial_number)
             for p in lp.comports()]
    return sorted(ports, key=lambda p: (p.mercury is None, p.device))
