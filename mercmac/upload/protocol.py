"""The Mercury serial protocol as pure bytes: framing, address codes, report parsing.

Nothing here touches a port. The transport feeds received bytes to a
`ReportSplitter`; the controller layer frames the lines mercmac.mdtext builds
with `select` and `command` and reads replies with the `parse_*` functions (docs/uploader.md).
"""
from __future__ import annotations

import re
from dataclasses import dataclass

from mercmac import mdtext
from mercmac.commands import MODELS

SELECT = 0x01  # MS176E §3.1.1: first character of the address selection code (Ctrl-A)
CR = 0x0D  # MS176E §6.1.2: every command line ends with CR
LF = 0x0A  # MS176E §6.1.3: reports end CR LF ETX
ETX = 0x03  # MS176E §6.1.3: last byte of every report
NUL = 0x00  # USB-serial adapters emit stray NULs at power-up and on breaks
ADDRESS_CHARS = "0123456789ABCDEF"  # MS176E §3.1.3: ASCII 48-57 for 0-9, 65-70 for 10-15
STATUS_CHAR = b"%"  # MS176E §6.3: single-character TS, answered without stopping a macro
MAX_REPORT = 8192  # the longest real report (TM of 31 full macros) is under 4 KB
MAX_LINE = 250  # well above 16 commands (MS176E §3.8) of 9 digits each plus MDnn

_FORBIDDEN = {SELECT, CR, LF, ETX, NUL}


class ProtocolError(Exception):
    """Bytes that do not have the shape MS176E gives; `reply` quotes what came."""

    def __init__(self, message: str, reply: str | None = None):
        super().__init__(message)
        self.reply = reply


def select(address: int) -> bytes:
    """The two-byte address selection code for address 0-15 (MS176E §3.1.3, §5.1)."""
    if not 0 <= address <= 15:
        raise ProtocolError(f"address {address} is outside 0-15 (MS176E §3.1.3)")
    # 0x01: address selection; then '0'-'9' or 'A'-'F', no terminator (§3.1.1)
    return bytes([SELECT]) + ADDRESS_CHARS[address].encode("ascii")


def command(line: str) -> bytes:
    """One command line with its CR; never a bare CR, which repeats the last line (§5.3)."""
    if not line.strip():
        raise ProtocolError("refusing to send an empty line: a bare CR re-executes "
                            "the previous command (MS176E §5.3)")
    data = line.encode("ascii", errors="strict")
    if any(b in _FORBIDDEN for b in data):
        raise ProtocolError(f"control character in command line {line!r}")
    if len(data) > MAX_LINE:
        raise ProtocolError(f"command line of {len(data)} characters is too long")
    return data + bytes([CR])  # 0x0D: CR ends the line (§6.1.2)


def show(data: bytes) -> str:
    """Bytes as a person reads them: printable text, control bytes as <01>, <CR>."""
    names = {SELECT: "<01>", CR: "<CR>", LF: "<LF>", ETX: "<ETX>", NUL: "<NUL>"}
    return "".join(names.get(b) or (chr(b) if 32 <= b < 127 else f"<{b:02X}>") for b in data)


class ReportSplitter:
    """Cuts received bytes into reports at ETX (MS176E §6.1.3), dropping NULs."""

    def __init__(self) -> None:
        self._buffer = bytearray()

    def feed(self, data: bytes) -> list[str]:
        """Complete reports in `data` (text before each ETX); the rest is kept."""
        self._buffer += bytes(b for b in data if b != NUL)
        reports = []
        while (end := self._buffer.find(ETX)) >= 0:
            reports.append(self._buffer[:end].decode("latin-1"))
            del self._buffer[:end + 1]
        if len(self._buffer) > MAX_REPORT:
            junk = self.pending()
            self._buffer.clear()
            raise ProtocolError(f"{MAX_REPORT} bytes without an end of report (ETX)", junk)
        return reports

    def pending(self) -> str:
        """What arrived after the last ETX, for error messages."""
        return self._buffer.decode("latin-1")

    def clear(self) -> None:
        self._buffer.clear()


def lines(report: str) -> list[str]:
    """The non-empty lines of a report, without CR/LF."""
    return [part.strip() for part in re.split(r"[\r\n]+", report) if part.strip()]


def quote(report: str, limit: int = 80) -> str:
    """A reply for an error message: escaped, and cut when long."""
    text = show(report.encode("latin-1", errors="replace"))
    return repr(text if len(text) <= limit else text[:limit] + "...")


# -- VE (MS176E §6.4 VE: "(c)2009 Physik Instrumente(PI) Karlsruhe, C-863, Ver. 2.30, ...")

@dataclass(frozen=True, slots=True)
class Version:
    """What `VE` says: the model (None when it names none mercmac knows), the firmware
    version ('?' when it gives none) and the whole text."""

    model: str | None
    firmware: str
    text: str

    @property
    def name(self) -> str:
        """The model for people: 'C-863', or 'unknown model'."""
        return self.model or "unknown model"

    @property
    def char_gap_limited(self) -> bool:
        """Firmware 1.xx drops characters more than 20 ms apart (MS176E §2 notes); an
        unknown version is taken to be that old."""
        return self.firmware.startswith("1.") or self.firmware == UNKNOWN_FIRMWARE


_MODEL = re.compile(r"\bC-?(\d{3})\b", re.IGNORECASE)
_FIRMWARE = re.compile(r"\bVer(?:sion)?\.?\s*(\d+(?:\.\d+)*)", re.IGNORECASE)
_MAKER = re.compile(r"Physik\s*Instrumente", re.IGNORECASE)  # §6.4 VE: the copyright notice
UNKNOWN_FIRMWARE = "?"


def parse_version(report: str) -> Version:
    """Model and firmware from a VE report; ProtocolError when it is not one.

    A report with a version number or PI's copyright notice is a version report even
    when it names no model mercmac knows: older firmware and the C-862 predecessor may
    answer so, and the caller decides (connect.check_model); the model is None then.
    """
    text = " ".join(lines(report))
    found = [f"C-{m}" for m in _MODEL.findall(text)]
    model = next((m for m in found if m in MODELS), None)
    firmware = _FIRMWARE.search(text)
    if firmware is None and not _MAKER.search(text):
        raise ProtocolError("not a version report (expected PI's notice, a model such as "
                            "C-863 and 'Ver. n.nn', MS176E §6.4 VE)", report)
    return Version(model, firmware.group(1) if firmware else UNKNOWN_FIRMWARE, text)


def is_version(report: str) -> bool:
    try:
        parse_version(report)
    except ProtocolError:
        return False
    return True


# -- TS (MS176E §6.4 TS: C-863 "S:04 02 00 03 02 00", C-663 "s:03 07 00")

@dataclass(frozen=True, slots=True)
class Status:
    """A TS report: its bytes, whether a macro runs, and the error code."""

    blocks: tuple[int, ...]

    @property
    def layout(self) -> str:
        """The model whose layout the report has: 6 blocks C-863, 3 blocks C-663."""
        return "C-863" if len(self.blocks) == 6 else "C-663"

    @property
    def macro_running(self) -> bool:
        # C-863: block 2 bit 4; C-663: block 1 bit 4 (MS176E §6.4 TS tables)
        flags = self.blocks[1] if len(self.blocks) == 6 else self.blocks[0]
        return bool(flags & 0x10)

    @property
    def error(self) -> int:
        """The last block: 0 no error, 1 RS-232 timeout, 6 wrong command, ..."""
        return self.blocks[-1]


_STATUS = re.compile(r"^S:\s*((?:[0-9A-F]{2}\s*){3}|(?:[0-9A-F]{2}\s*){6})$", re.IGNORECASE)


def parse_status(report: str) -> Status:
    """The blocks of a TS report; ProtocolError when it is not one."""
    for line in lines(report):
        if m := _STATUS.match(line):
            return Status(tuple(int(b, 16) for b in m.group(1).split()))
    raise ProtocolError("not a status report (expected 'S:' and 3 or 6 hex bytes, "
                        "MS176E §6.4 TS)", report)


def is_status(report: str) -> bool:
    return any(_STATUS.match(line) for line in lines(report))


# -- TM / TZ (MS176E §6.4 TM: "MC001 MR55555"; TZ: "MC000 MR5000,WS100,GH")

def _told(line: str) -> mdtext.Listed | None:
    """A line of a TM/TZ report as mdtext reads macro listings, or None when it is none."""
    found = mdtext.listed(line)
    return found if found is not None and found.form is mdtext.Form.TM else None


def parse_macro_line(line: str) -> tuple[int, str]:
    """Slot and contents of one `MCnnn ...` line; a bare `MCnnn` is an empty slot
    (docs/uploader.md)."""
    found = _told(line.strip())
    if found is None or found.slot > 31:
        raise ProtocolError("not a macro listing (expected 'MCnnn commands', "
                            "MS176E §6.4 TM)", line)
    return found.slot, found.body.strip()


def is_macro_report(report: str) -> bool:
    """An empty report or one made only of `MCnnn` lines: an answer to TM/TZ."""
    return all(_told(line) for line in lines(report))


def parse_macros(report: str) -> dict[int, str]:
    """Slots named in a TM/TZ report, empty ones left out; both framings (docs/uploader.md)."""
    found: dict[int, str] = {}
    for line in lines(report):
        slot, text = parse_macro_line(line)
        if slot in found and found[slot] != text:
            raise ProtocolError(f"macro {slot} listed twice with different contents", report)
        found[slot] = text
    return {slot: text for slot, text in found.items() if text}


def same_macro(a: str | None, b: str | None) -> bool:
    """Whether two stored lines mean the same; None is an empty slot. Compared as
    the controller may store them (MMCRun files write `EM+9` where mercmac sends `EM9`)."""
    return mdtext.normal(a) == mdtext.normal(b)


def difference(expected: str | None, got: str | None) -> str:
    """How a read-back differs from what was sent, for a person."""
    want, have = mdtext.normal(expected), mdtext.normal(got)
    if not have:
        return f"expected {want!r}, the slot reads back empty"
    if not want:
        return f"expected an empty slot, it reads back {have!r}"
    at = next((i for i, (x, y) in enumerate(zip(want, have)) if x != y), min(len(want), len(have)))
    return f"expected {want!r}, read back {have!r} (first difference at character {at + 1})"
