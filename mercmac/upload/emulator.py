"""A virtual Mercury controller that speaks SPEC §4 byte for byte.

`VirtualController` is the byte-level state machine: address selection,
line assembly, CR repetition, stop-on-character, the macro store and the
protocol commands (MD, RM, RMALL, RZ, TM, TZ, VE, TB, TS, RT). Motion, waits
and reports of stored macros and direct lines run on the simulator's VM
(mercmac.vm.Machine), advanced with wall time. `Faults` lets tests make it
misbehave the way real links do. ptyserver.py serves it on a pseudo-terminal.
"""
from __future__ import annotations

import json
import os
import re
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from mercmac.commands import C663, C863, COMMANDS, SINGLE_CHARS, Arg
from mercmac.upload import protocol

REPORT_END = b"\r\n\x03"  # MS176E §6.1.3: CR LF ETX after every report
CHAR_GAP_S = 0.020  # MS176E §2 notes: firmware 1.xx drops a line whose characters are > 20 ms apart
MAX_COMMANDS = 16  # MS176E §3.8: up to 16 base commands per macro
VE_TEXT = "(c)2009 Physik Instrumente(PI) Karlsruhe, {model}, Ver. {firmware}, 2009-21-07"
# TS error codes (MS176E §6.4 TS, block 6 / block 3)
ERR_TIMEOUT, ERR_MACRO_RANGE, ERR_MACRO_COMMAND, ERR_COMMAND = 0x01, 0x04, 0x05, 0x06
_PROTOCOL_COMMANDS = {"MD", "RM", "RMALL", "RZ", "RT", "TM", "TZ", "VE", "TB", "TS"}
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
    char_gap: bool | None = None  # enforce the 20 ms gap; None = as the firmware version says


@dataclass(slots=True)
class Counters:
    """What arrived, for tests and the byte benchmark."""

    md_lines: int = 0
    lines: list[str] = field(default_factory=list)


class VirtualController:
    """The controller: feed it bytes with `receive`, advance it with `tick`, `take` its output."""

    def __init__(self, model: str = C863, address: int = 0, *, firmware: str = "2.30",
                 macros: dict[int, str] | None = None, faults: Faults | None = None,
                 state: Path | None = None, machine: bool = True):
        self.model, self.address, self.firmware = model, address, firmware
        self.faults = faults or Faults()
        self.state = state
        self.macros: dict[int, str] = dict(macros or {})
        if state and state.exists():
            self.macros = load_state(state)
        self.counters = Counters()
        self.vanished = False
        self.selected = False
        self._out = bytearray()
        self._line = bytearray()
        self._last_char_at = 0.0
        self._last_line: str | None = None
        self._awaiting_address = False
        self._error = 0
        self._engine = _Engine.create(self, machine)
        self.power_on(0.0)

    # -- time and bytes ---------------------------------------------------

    def power_on(self, now: float) -> None:
        """Deselected; parameters at defaults; macro 0 starts if stored (MS176E §3.1, §3.8.5)."""
        self.selected, self._awaiting_address = False, False
        self._line.clear()
        self._last_line = None
        if self._engine:
            self._engine.power_on(now, self.macros)

    def tick(self, now: float) -> None:
        """Let running macros advance to wall time `now` (seconds)."""
        if self._engine:
            self._engine.advance(now)

    def take(self) -> bytes:
        """Bytes waiting to go to the host."""
        data, self._out = bytes(self._out), bytearray()
        return data

    def receive(self, data: bytes, now: float) -> None:
        """Bytes from the host, one at a time, as the firmware sees them."""
        for byte in data:
            if self.vanished:
                return
            self._byte(byte, now)

    def report(self, text: str) -> None:
        """Send a report if selected; deselected controllers stay silent (MS176E §5.1, §5.6)."""
        if self.selected and not self.faults.silent:
            self._out += text.encode("latin-1") + REPORT_END

    @property
    def running(self) -> bool:
        return bool(self._engine and self._engine.running)

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
        if self.running:
            self._engine.stop()  # MS176E §3.8.3: any other character stops a running macro
        if self._line and self._gap_limited() and now - self._last_char_at > CHAR_GAP_S:
            self._line.clear()  # firmware 1.xx: characters too far apart, line dropped
            self._error = ERR_TIMEOUT
        self._line.append(byte)
        self._last_char_at = now

    def _end_of_line(self, now: float) -> None:
        if self._line and self._gap_limited() and now - self._last_char_at > CHAR_GAP_S:
            self._line.clear()
            self._error = ERR_TIMEOUT
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
        if char == "%":
            self.report(self._status())
        elif self._engine:
            self._engine.single(char)

    def _execute(self, text: str, now: float) -> None:
        self.counters.lines.append(text)
        line = re.sub(r"\s+", "", text.upper())
        if line.startswith("MD"):
            self._define(line)
            return
        tokens = [t for t in line.split(",") if t]
        if tokens and all(_mnemonic(t) in _PROTOCOL_COMMANDS for t in tokens):
            for token in tokens:
                self._protocol(token, now)
        elif self._engine:
            self._engine.direct(line, now)
        else:
            self._error = ERR_COMMAND

    def _define(self, line: str) -> None:
        """MDn,...: store silently, overwriting (MS176E §3.8.1, §6.4 MD)."""
        self.counters.md_lines += 1
        line = self._lose_character(line)
        head, _, body = line.partition(",")
        slot = _number(head[2:])
        if slot is None or not 0 <= slot <= 31:
            self._error = ERR_MACRO_RANGE
        elif not _storable(body):
            self._error = ERR_MACRO_COMMAND
        else:
            self.macros[slot] = body
            self._save()
        limit = self.faults.vanish_after_md
        if limit is not None and self.counters.md_lines >= limit:
            self.vanished = True

    def _lose_character(self, line: str) -> str:
        faults, n = self.faults, self.counters.md_lines
        index = faults.drop_char.get(n)
        if index is None and faults.always_drop_slot is not None:
            if _number(line.partition(",")[0][2:]) == faults.always_drop_slot:
                index = len(line) // 2
        if index is None or not line:
            return line
        index = min(index, len(line) - 1)
        return line[:index] + line[index + 1:]

    def _protocol(self, token: str, now: float) -> None:
        name, arg = _mnemonic(token), _number(token[len(_mnemonic(token)):])
        if name == "VE":
            self.report(VE_TEXT.format(model=self.model, firmware=self.firmware))
        elif name == "TB":
            self.report(f"B:{self.address}")  # §6.4 TB gives no format; "B:" per §6.2
        elif name == "TS":
            self.report(self._status())
        elif name == "TZ":
            self._tell([0])
        elif name == "TM":
            self._tell([arg] if arg else [s for s in sorted(self.macros) if s > 0], listing=not arg)
        elif name == "RZ":
            self._remove([0])
        elif name == "RM":
            self._remove([arg] if arg else list(range(1, 32)))
        elif name == "RMALL":
            self._remove(list(range(32)))
            self.power_on(now)
            self.selected = True
        elif name == "RT":
            self.power_on(now)  # §6.4 RT: as after power-on, so deselected (§3.1)

    def _tell(self, slots: list[int], listing: bool = False) -> None:
        """TM/TZ answers, framed as `Faults` says (SPEC §4 leaves both open)."""
        if not self.selected or self.faults.silent:
            return
        lines = []
        for slot in slots:
            if slot in self.macros:
                lines.append(f"MC{slot:03d} {self.macros[slot]}")
            elif not listing and self.faults.empty_slot == "bare":
                lines.append(f"MC{slot:03d}")
        if not lines:
            self._out += REPORT_END  # an empty report
        elif self.faults.tm_framing == "one-etx":
            self._out += "".join(f"{line}\r\n" for line in lines).encode("latin-1") + b"\x03"
        else:
            for line in lines:
                self._out += line.encode("latin-1") + REPORT_END

    def _remove(self, slots: list[int]) -> None:
        for slot in slots:
            if slot is not None and 0 <= slot <= 31:
                self.macros.pop(slot, None)
        self._save()

    def _status(self) -> str:
        """TS: C-863 six blocks, C-663 three (MS176E §6.4 TS); macro-running and error bits."""
        running = 0x10 if self.running else 0
        on_target = self._engine.on_target if self._engine else True
        error, self._error = self._error, 0
        if self.model == C663:
            return f"S:{running | (0x02 if on_target else 0) | 0x01:02X} 00 {error:02X}"
        return f"S:{0x04 if on_target else 0:02X} {running:02X} 00 03 02 {error:02X}"

    def _save(self) -> None:
        if self.state:
            save_state(self.state, self.macros, self.model)


def _mnemonic(token: str) -> str:
    m = re.match(r"[A-Z]+\??", token)
    name = m.group(0) if m else ""
    return "RMALL" if name == "RMALL" else name


def _number(text: str) -> int | None:
    try:
        return int(text) if text else None
    except ValueError:
        return None


def _storable(body: str) -> bool:
    """Whether every command of a macro body is one the firmware stores (MS176E §3.8, §6.2)."""
    tokens = body.split(",") if body else []
    if not tokens or len(tokens) > MAX_COMMANDS:
        return False
    for token in tokens:
        if token == "":
            continue  # `DI,` in MMCRun files (MS176E §3.8.6 Example 4)
        m = _TOKEN.match(token)
        spec = COMMANDS.get(m.group(1)) if m else None
        if spec is None or not spec.storable:
            return False
        if (m.group(2) is None and spec.arg is Arg.REQUIRED) or (m.group(2) and spec.arg is Arg.NONE):
            return False
    return True


def load_state(path: Path) -> dict[int, str]:
    """The macros of a `--state` file; a missing or broken file is an empty controller."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
        return {int(k): str(v) for k, v in data.get("macros", {}).items() if 0 <= int(k) <= 31}
    except (OSError, ValueError, AttributeError):
        return {}


def save_state(path: Path, macros: dict[int, str], model: str) -> None:
    """Keep the flash memory across runs; written atomically like real flash pages."""
    data = {"model": model, "macros": {str(k): v for k, v in sorted(macros.items())}}
    fd, tmp = tempfile.mkstemp(prefix=".mercmac-state-", dir=path.parent or Path("."))
    with os.fdopen(fd, "w", encoding="utf-8") as f:
        json.dump(data, f, indent=1)
    os.replace(tmp, path)


class _Engine:
    """The VM behind the virtual controller: runs macros and direct lines with wall time."""

    @staticmethod
    def create(controller: VirtualController, wanted: bool) -> "_Engine | None":
        if not wanted:
            return None
        try:
            from mercmac.vm import Machine  # noqa: F401
        except ImportError:
            return None
        return _Engine(controller)

    def __init__(self, controller: VirtualController):
        self.controller = controller

    running = False
    on_target = True
