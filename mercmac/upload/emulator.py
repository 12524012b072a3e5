"""A virtual Mercury controller that speaks SPEC §4 byte for byte.

`VirtualController` is the firmware's front end: address selection, line
assembly, CR repetition, stop-on-character, the 20 ms character gap of
firmware 1.xx, and the macro commands (MD, RM, RMALL, RZ, TM, TZ). Everything
else (motion, waits, reports, TS, TB, VE, running stored macros) is the
simulator's VM, `mercmac.vm.Machine`, advanced with wall time; its reports
module formats every report. `Faults` makes it misbehave the way real links
do. ptyserver.py serves it on a pseudo-terminal.
"""
from __future__ import annotations

import json
import os
import re
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from mercmac.commands import C863, COMMANDS, SINGLE_CHARS, Arg
from mercmac.compiler.program import Macro, Op, Program
from mercmac.upload import protocol
from mercmac.vm import Machine, Options
from mercmac.vm import reports

REPORT_END = b"\r\n\x03"  # MS176E §6.1.3: CR LF ETX after every report
CHAR_GAP_S = 0.020  # MS176E §2 notes: firmware 1.xx drops a line whose characters are > 20 ms apart
MAX_COMMANDS = 16  # MS176E §3.8: up to 16 base commands per macro
# TS error codes (MS176E §6.4 TS, block 6 / block 3)
ERR_TIMEOUT, ERR_MACRO_RANGE, ERR_MACRO_COMMAND, ERR_COMMAND = 0x01, 0x04, 0x05, 0x06
_MACRO_COMMANDS = {"MD", "RM", "RMALL", "RZ", "TM", "TZ", "VE"}
_TOKEN = re.compile(r"^([A-Z]+\??)([+-]?\d+)?$")


@dataclass(slots=True)
class Faults:
    """Misbehaviour on demand, for the uploader's fault tests (issue 4, item 5)."""

    drop_char: dict[int, int] = field(default_factory=dict)  # n-th MD line (1-based) -> index lost
    always_drop_slot: int | None = None  # every MD line for this slot loses a character
    vanish_after_md: int | None = None  # the port disappears after this many MD lines
    tm_framing: str = "etx-per-line"  # or "one-etx": how a TM listing of several macros ends
    empty_slot: str = "empty"  # or "bare": TMn of an empty slot is "" or "MCnnn" (SPEC §4)
    silent: bool = False  # nothing answers at all
    garble: bool = False  # replies arrive mangled, as at a wrong baud rate
    char_gap: bool | None = None  # enforce the 20 ms gap; None = as the firmware version says
    md_delay: float = 0.0  # seconds a flash write keeps the controller from reading on


class VirtualController:
    """The controller: feed it bytes with `receive`, advance it with `tick`, `take` its output."""

    def __init__(self, model: str = C863, address: int = 0, *, firmware: str = "2.30",
                 macros: dict[int, str] | None = None, faults: Faults | None = None,
                 state: Path | None = None):
        self.model, self.address, self.firmware = model, address, firmware
        self.faults = faults or Faults()
        self.state = state
        self.lines: list[str] = []  # every command line received, for tests and benchmarks
        self.md_count = 0
        self.busy_until = 0.0  # while storing a macro, further bytes wait in the input buffer
        self._held = bytearray()
        self.vanished = False
        self.selected = False
        self._out = bytearray()
        self._line = bytearray()
        self._last_char_at = 0.0
        self._last_line: str | None = None
        self._awaiting_address = False
        self._now = 0.0
        self.machine = Machine(model=model, options=Options(address=address),
                               on_report=lambda t_ms, text: self.report(text))
        stored = load_state(state) if state and state.exists() else dict(macros or {})
        self.machine.load(Program({s: _macro(s, ops) for s, text in stored.items()
                                   if (ops := _ops(text, s, model)) is not None}, model))
        self.power_on(0.0)

    # -- time and bytes ---------------------------------------------------

    @property
    def macros(self) -> dict[int, str]:
        """What the flash memory holds, as TM would list it."""
        return {slot: chunk.line for slot, chunk in sorted(self.machine.chunks.items())}

    @property
    def running(self) -> bool:
        return self.machine.running

    def power_on(self, now: float) -> None:
        """Deselected, defaults restored, macro 0 started if stored (MS176E §3.1, §3.8.5)."""
        self.machine.run_until(now * 1000)
        self.selected, self._awaiting_address = False, False
        self._line.clear()
        self._last_line = None
        self.machine.power_on()
        self._self_select()

    def tick(self, now: float) -> None:
        """Let running macros advance to wall time `now` (seconds since power-on)."""
        self.machine.run_until(now * 1000)
        self._self_select()
        self._now = now
        while self._held and now >= self.busy_until and not self.vanished:
            byte = self._held.pop(0)
            self._byte(byte, now)

    def take(self) -> bytes:
        """Bytes waiting to go to the host."""
        data, self._out = bytes(self._out), bytearray()
        if self.faults.garble:
            # a receiver at the wrong baud rate sees other bits, and rarely an ETX
            data = bytes((b * 37 + 11) & 0xFF or 0x80 for b in data).replace(b"\x03", b"\x83")
        return data

    def receive(self, data: bytes, now: float) -> None:
        """Bytes from the host, one at a time, as the firmware sees them."""
        self._held += data  # held while a macro is being stored (Faults.md_delay)
        self.tick(now)

    def report(self, text: str) -> None:
        """Send a report if selected; deselected controllers stay silent (MS176E §5.1, §5.6)."""
        if self.selected and not self.faults.silent:
            self._out += text.encode("latin-1") + REPORT_END

    def _self_select(self) -> None:
        """SCn in the autostart macro selects the controller (MS176E §3.1.2)."""
        if self.machine.params.pop("SC", None) == self.address:
            self.selected = True

    # -- the byte-level rules -----------------------------------------------

    def _byte(self, byte: int, now: float) -> None:
        if self._awaiting_address:
            # second character of the address selection code (MS176E §3.1.3)
            self._awaiting_address = False
            self.selected = chr(byte).upper() == protocol.ADDRESS_CHARS[self.address]
            self._line.clear()
            return
        if byte == protocol.SELECT:
            self._awaiting_address = True
            return
        if not self.selected or byte in (protocol.NUL, protocol.LF):
            return  # MS176E §5.1: deselected, everything but address codes is ignored
        char = chr(byte)
        if not self._line and char in SINGLE_CHARS:
            self._single(char)  # MS176E §6.3: executed at once, a macro keeps running
        elif byte == protocol.CR:
            self._end_of_line(now)
        else:
            self._char(byte, now)

    def _char(self, byte: int, now: float) -> None:
        self.machine.stop()  # MS176E §3.8.3, §6.1.1: any other character stops a macro
        if self._line and self._gap_limited() and now - self._last_char_at > CHAR_GAP_S:
            self._line.clear()  # firmware 1.xx: characters too far apart, line dropped
            self.machine.error = ERR_TIMEOUT
        self._line.append(byte)
        self._last_char_at = now

    def _end_of_line(self, now: float) -> None:
        if self._line and self._gap_limited() and now - self._last_char_at > CHAR_GAP_S:
            self._line.clear()
            self.machine.error = ERR_TIMEOUT
            return
        if not self._line:
            if self._last_line is not None:  # MS176E §5.2: a bare CR repeats the last line
                self._execute(self._last_line, now)
            return
        text = self._line.decode("latin-1")
        self._line.clear()
        self._last_line = text
        self._execute(text, now)

    def _gap_limited(self) -> bool:
        if self.faults.char_gap is not None:
            return self.faults.char_gap
        return self.firmware.startswith("1.")

    # -- commands -------------------------------------------------------------

    def _single(self, char: str) -> None:
        """MS176E §6.3: the same report as the equivalent command; `\\` is 0 or 1 (moving)."""
        equivalent = SINGLE_CHARS[char].equivalent
        if equivalent is None:
            self.report("1" if self.machine.axis.moving(self.machine.clock.now) else "0")
        elif equivalent == "AB":
            self.machine.execute_line([Op("AB")])
        elif char in ("+", "(") and self.model != C863:
            return  # TE/TF exist on the C-863 only (§6.3 footnote)
        else:
            name, arg = _split(equivalent)
            self.report(reports.report(name, arg, self.machine))

    def _execute(self, text: str, now: float) -> None:
        self.lines.append(text)
        line = re.sub(r"\s+", "", text.upper())
        if line.startswith("MD"):
            self._define(line)
            return
        tokens = [t for t in line.split(",") if t]
        if tokens and all(_split(t)[0] in _MACRO_COMMANDS for t in tokens):
            for token in tokens:
                self._macro_command(*_split(token), now)
        elif (ops := _ops(line, -1, self.model)) is not None:
            self.machine.execute_line(ops)
            self.machine.run_until(now * 1000)  # reports of the line come at once
        else:
            self.machine.error = ERR_COMMAND

    def _define(self, line: str) -> None:
        """MDn,...: store silently, overwriting (MS176E §3.8.1, §6.4 MD)."""
        self.md_count += 1
        line = self._lose_character(line)
        head, _, body = line.partition(",")
        slot = _number(head[2:])
        ops = _ops(body, slot, self.model) if slot is not None and 0 <= slot <= 31 else None
        if slot is None or not 0 <= slot <= 31:
            self.machine.error = ERR_MACRO_RANGE
        elif ops is None:
            self.machine.error = ERR_MACRO_COMMAND
        else:
            self.machine.define(slot, ops)
            self._save()
            self.busy_until = self._now + self.faults.md_delay
        if self.faults.vanish_after_md is not None and self.md_count >= self.faults.vanish_after_md:
            self.vanished = True

    def _lose_character(self, line: str) -> str:
        faults = self.faults
        index = faults.drop_char.get(self.md_count)
        if index is None and faults.always_drop_slot is not None:
            if _number(line.partition(",")[0][2:]) == faults.always_drop_slot:
                index = len(line) // 2
        if index is None or not line:
            return line
        index = min(index, len(line) - 1)
        return line[:index] + line[index + 1:]

    def _macro_command(self, name: str, arg: int | None, now: float) -> None:
        if name == "VE":
            text = reports.report("VE", None, self.machine)
            self.report(text.replace("Ver. 2.30", f"Ver. {self.firmware}"))
        elif name in ("TZ", "TM"):
            self._tell([0] if name == "TZ" else [arg] if arg else
                       [s for s in sorted(self.machine.chunks) if s > 0], listing=name == "TM" and not arg)
        else:  # RZ, RMn, RM, RMALL (§6.4): the VM erases; the state file follows
            self.machine.execute_line([Op(name, arg)])
            self.machine.run_until(now * 1000 + 1)
            self._save()

    def _tell(self, slots: list[int], listing: bool = False) -> None:
        """TM/TZ answers, framed as `Faults` says (SPEC §4 leaves both open)."""
        lines = protocol.lines(reports.macros(self.machine, slots))
        if not lines and not listing and self.faults.empty_slot == "bare":
            lines = [f"MC{slots[0]:03d}"]
        if not lines:
            self.report("")  # an empty report
        elif self.faults.tm_framing == "one-etx":
            self.report("\r\n".join(lines))
        else:
            for line in lines:
                self.report(line)

    def _save(self) -> None:
        if self.state:
            save_state(self.state, self.macros, self.model)


def _split(token: str) -> tuple[str, int | None]:
    """'TM12' -> ('TM', 12); 'RMALL' -> ('RMALL', None)."""
    m = re.match(r"([A-Z]+\??)(.*)$", token)
    name, rest = (m.group(1), m.group(2)) if m else (token, "")
    return name, _number(rest)


def _number(text: str) -> int | None:
    try:
        return int(text) if text else None
    except ValueError:
        return None


def _ops(body: str, slot: int, model: str) -> list[Op] | None:
    """The base commands of a line, or None if one is unknown or malformed (error 05/06)."""
    tokens = body.split(",") if body else []
    if not tokens or len(tokens) > MAX_COMMANDS:
        return None
    ops = []
    for token in tokens:
        if token == "":
            continue  # `DI,` in MMCRun files (MS176E §3.8.6 Example 4)
        m = _TOKEN.match(token)
        spec = COMMANDS.get(m.group(1)) if m else None
        if spec is None or (slot >= 0 and not spec.storable):
            return None
        arg = _number(m.group(2) or "")
        if (arg is None and spec.arg is Arg.REQUIRED) or (arg is not None and spec.arg is Arg.NONE):
            return None
        ops.append(Op(spec.mnemonic, arg))
    return ops


def _macro(slot: int, ops: list[Op]) -> Macro:
    return Macro(slot, f"MC{slot:02d}", ops, origin="stored")


def load_state(path: Path) -> dict[int, str]:
    """The macros of a `--state` file; a missing or broken file is an empty controller."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
        return {int(k): str(v) for k, v in data.get("macros", {}).items() if 0 <= int(k) <= 31}
    except (OSError, ValueError, AttributeError):
        return {}


def save_state(path: Path, macros: dict[int, str], model: str) -> None:
    """Keep the flash memory across runs; written atomically like a flash page."""
    data = {"model": model, "macros": {str(k): v for k, v in sorted(macros.items())}}
    fd, tmp = tempfile.mkstemp(prefix=".mercmac-state-", dir=path.parent)
    with os.fdopen(fd, "w", encoding="utf-8") as f:
        json.dump(data, f, indent=1)
    os.replace(tmp, path)
