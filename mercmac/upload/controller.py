"""Commands to one controller over a transport: select, identify, read and write macros.

Every reply is checked against the shape MS176E gives it; reports that do not
fit (stale output of a macro that ran when we connected) are skipped and
quoted if nothing else comes. Reads are repeated once, writes never: a write
is checked by reading it back (flasher.py).
"""
from __future__ import annotations

import time
from typing import Callable

from mercmac import mdtext
from mercmac.commands import Mnemonic
from mercmac.upload import protocol
from mercmac.upload.protocol import ProtocolError, Status, Version
from mercmac.upload.transport import LONGEST_REPLY, PortLost, ReadTimeout, Transport, TransportError

READ_ATTEMPTS = 2  # a read is harmless to repeat; a lost character in `TM5` costs one retry
MAX_SKIPPED = 32  # stale reports skipped per exchange: a macro's last few lines, never a flood
LISTED = frozenset(range(1, 32))  # the slots `TM` lists (MS176E §6.4 TM): at most 31 lines
SHORT_REPORT = 64  # bytes: a TS report is 20, so '%' needs far less than a TM listing


class ControllerError(Exception):
    """A command did not get the reply it needs; says what was sent and what came."""

    def __init__(self, message: str, *, sent: str = "", reply: str | None = None):
        super().__init__(message)
        self.sent, self.reply = sent, reply


class NoAnswer(ControllerError):
    """Silence where the manual promises a report."""


class BadReply(ControllerError):
    """Something came, but not what the command reports."""


class Flood(BadReply):
    """Replies kept coming, none of them the answer: the exchange was cut off by count or time."""


class LinkLost(ControllerError):
    """The port failed under us."""


class Controller:
    """The controller at one address on an open transport."""

    def __init__(self, transport: Transport, address: int = 0):
        self.transport, self.address = transport, address

    def select(self) -> None:
        """Send the address selection code; a deselected controller ignores all else (§3.1)."""
        self._send(protocol.select(self.address))  # 0x01 + address character, no CR (§3.1.1)

    def status(self, timeout: float | None = None) -> Status | None:
        """TS by its single character `%`, which does not stop a running macro (§6.3); None if silent."""
        try:
            return self.probe(timeout)
        except (NoAnswer, BadReply):
            return None  # silence or noise here is judged by the VE that follows

    def probe(self, timeout: float | None = None) -> Status:
        """Like `status`, but NoAnswer or BadReply (quoting what came) instead of None."""
        self._discard("%")
        self._send(protocol.STATUS_CHAR)  # '%': single-character TS, no CR (§6.3)
        report = self._await("%", protocol.is_status, timeout, size=SHORT_REPORT)
        return protocol.parse_status(report)

    def answered_again(self, timeout: float) -> bool:
        """Whether a second status report follows the one `probe` took within TIMEOUT: two
        controllers set to this address both answered `%` (MS176E §3.2: each answers the code
        of its own DIP-switch address, so two set alike talk at once)."""
        try:
            report = self.transport.read_report(timeout)
        except ReadTimeout:
            return False
        except PortLost as e:
            raise LinkLost(str(e), sent=protocol.STATUS_CHAR) from None
        return protocol.is_status(report)

    def identify(self) -> Version:
        """VE: model and firmware (§3.3). Its first character also stops a running macro (§3.8.3)."""
        return protocol.parse_version(self._ask(mdtext.ve(), protocol.is_version))

    def read_slot(self, slot: int) -> str | None:
        """One macro by `TMn`, or `TZ` for macro 0 (`TM0` lists all but 0); None when empty."""
        line = mdtext.tell(slot)
        report = self._ask(line, lambda r: _lists_only(r, {slot}))
        return self._macros(report, line).get(slot)

    def read_all(self) -> dict[int, str]:
        """Every stored macro: `TM` for 1-31 in either framing, then `TZ`."""
        first = self._ask(mdtext.tm(), lambda r: _lists_only(r, LISTED))
        stop = time.monotonic() + self.transport.timing.budget(self.transport.baud)
        macros = self._macros(first, Mnemonic.TM)
        if len(protocol.lines(first)) == 1:
            # One line then ETX: either the only macro, or the first of an
            # ETX-per-line listing (docs/uploader.md, "Reading macros back"). More lines
            # follow without a pause.
            self._listing_rest(macros, stop)
        zero = self.read_slot(0)
        if zero:
            macros[0] = zero
        return dict(sorted(macros.items()))

    def define(self, slot: int, line: str) -> None:
        """MDn,...: store a macro; the controller neither answers nor warns (§3.8.1)."""
        self._send(protocol.command(mdtext.md(slot, line)))

    def remove(self, slot: int) -> None:
        """Erase one macro: `RZ` for 0, `RMn` otherwise; never a bare `RM`, which erases all (§6.4 RM)."""
        self._send(protocol.command(mdtext.remove(slot)))  # ValueError outside 0-31

    def reset(self) -> None:
        """RT: restart as after power-on, so macro 0 runs; the controller is then deselected (§6.4 RT, §3.1)."""
        self._send(protocol.command(mdtext.rt()))

    def _send(self, data: bytes) -> None:
        try:
            self.transport.write(data)
        except TransportError as e:
            raise LinkLost(str(e), sent=protocol.show(data)) from None

    def _ask(self, line: str, accept: Callable[[str], bool]) -> str:
        """Send a report command and return the first report `accept` takes."""
        data = protocol.command(line)
        for attempt in range(READ_ATTEMPTS):
            self._discard(line)
            self._send(data)
            try:
                return self._await(line, accept)
            except Flood:
                raise  # asking again only prolongs a flood
            except (NoAnswer, BadReply):
                if attempt + 1 == READ_ATTEMPTS:
                    raise

    def _discard(self, line: str) -> None:
        try:
            self.transport.discard_input()
        except TransportError as e:
            raise LinkLost(str(e), sent=line) from None

    def _await(self, line: str, accept: Callable[[str], bool], timeout: float | None = None,
               *, size: int = LONGEST_REPLY) -> str:
        """Reports until one fits; stale ones skipped, at most MAX_SKIPPED of them and
        for no longer than `size` bytes take plus a timeout (a flood of junk ends too)."""
        skipped: list[str] = []
        stop = time.monotonic() + self.transport.timing.budget(self.transport.baud, size)
        while True:
            try:
                report = self.transport.read_report(timeout, stop)
            except PortLost as e:
                raise LinkLost(str(e), sent=line) from None
            except ReadTimeout as e:
                raise self._silence(line, skipped, e) from None
            if accept(report):
                return report
            skipped.append(report)
            if len(skipped) > MAX_SKIPPED or time.monotonic() > stop:
                raise Flood(f"unexpected answer to {line}: {len(skipped)} reports, none an "
                            f"answer to it, the last {protocol.quote(report)}",
                            sent=line, reply=report)

    def _silence(self, line: str, skipped: list[str], cause: ReadTimeout) -> ControllerError:
        """What a read that ended without the answer means: silence, junk, or endless bytes."""
        timeout, partial = self.transport.timing.timeout, cause.partial
        if cause.endless:
            came = partial or (skipped[-1] if skipped else "")
            return Flood(f"unexpected answer to {line}: {cause}: {protocol.quote(came)}",
                         sent=line, reply=came)
        if skipped or partial.strip():
            last = skipped[-1] if skipped else partial
            return BadReply(f"unexpected answer to {line}: {protocol.quote(last)}",
                            sent=line, reply=last)
        return NoAnswer(f"no answer to {line} within {timeout:g} s", sent=line)

    def _macros(self, report: str, line: str) -> dict[int, str]:
        if len(protocol.lines(report)) > len(LISTED):
            raise BadReply(f"unexpected answer to {line}: {len(protocol.lines(report))} lines, more "
                           f"than the {len(LISTED)} slots it lists: {protocol.quote(report)}",
                           sent=line, reply=report)
        try:
            return protocol.parse_macros(report)
        except ProtocolError as e:
            raise BadReply(f"unexpected answer to {line}: {e} {protocol.quote(report)}",
                           sent=line, reply=report) from None

    def _listing_rest(self, macros: dict[int, str], stop: float) -> None:
        """Further one-line reports of a TM listing, until `settle` seconds of quiet;
        at most 31 lines in all and no later than `stop` (an endless listing is refused)."""
        count = 1
        while True:
            try:
                report = self.transport.read_report(self.transport.timing.settle, stop)
            except PortLost as e:
                raise LinkLost(str(e), sent=Mnemonic.TM) from None
            except ReadTimeout as e:
                if e.endless:
                    raise self._silence(Mnemonic.TM, [], e) from None
                if e.partial.strip():
                    raise BadReply(f"TM listing cut short: {protocol.quote(e.partial)}",
                                   sent=Mnemonic.TM, reply=e.partial) from None
                return
            count += len(protocol.lines(report))
            if count > len(LISTED):
                raise Flood(f"TM listed {count} lines, more than the {len(LISTED)} slots it "
                               f"lists; the last {protocol.quote(report)}", sent=Mnemonic.TM,
                               reply=report)
            if time.monotonic() > stop:
                raise Flood(f"TM listing still going after {count} lines; the last "
                               f"{protocol.quote(report)}", sent=Mnemonic.TM, reply=report)
            if _lists_only(report, LISTED):
                for slot, text in self._macros(report, Mnemonic.TM).items():
                    if macros.get(slot, text) != text:
                        raise BadReply(f"TM listed macro {slot} twice with different contents",
                                       sent=Mnemonic.TM, reply=report)
                    macros[slot] = text


def _lists_only(report: str, slots: set[int]) -> bool:
    """A TM/TZ answer naming only `slots`: empty, or `MCnnn` lines of those (docs/uploader.md)."""
    if not protocol.is_macro_report(report):
        return False
    return all(protocol.parse_macro_line(line)[0] in slots for line in protocol.lines(report))
