"""Looking without writing: `pull` a controller's macros, `scan` addresses, list `ports`."""
from __future__ import annotations

from dataclasses import dataclass

from mercmac.upload import backup
from mercmac.upload.controller import BadReply, Controller, ControllerError, Flood, LinkLost
from mercmac.upload.errors import UploadError
from mercmac.upload.protocol import Status, Version
from mercmac.upload.connect import Identity, identify, refusal
from mercmac.upload.transport import Transport

PI_VENDOR = 0x1A72  # USB vendor id of Physik Instrumente
PI_PRODUCTS = {0x1007: "C-863"}  # USB product ids known to be Mercury controllers


@dataclass(frozen=True, slots=True)
class Pulled:
    """A controller's macros and the .mcm text that holds them."""

    identity: Identity
    macros: dict[int, str]
    text: str


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

    @property
    def model(self) -> str:
        if self.version:
            return self.version.name
        return self.status.layout if self.status else "?"


def scan(transport: Transport, addresses=range(16), *, stop: bool = False) -> list[Found]:
    """Which addresses answer `%`; VE for those not running a macro (or all, with stop).

    An address whose answer is not a status report is listed with what came; a flood
    of such replies ends the scan there, as the line carries nothing readable.
    """
    found = []
    for address in addresses:
        controller = Controller(transport, address)
        status = None
        try:
            controller.select()  # 0x01 + address: the others deselect (MS176E §3.2)
            status = controller.probe()  # '%' does not stop a running macro (§6.3)
            if status.macro_running and not stop:
                found.append(Found(address, status, None, "macro running, left alone"))
                continue
            found.append(Found(address, status, controller.identify()))
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
