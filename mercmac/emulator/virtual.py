"""A virtual Mercury controller that speaks the serial protocol byte for byte (docs/uploader.md).

`VirtualController` is the firmware's front end: address selection, line
assembly, CR repetition, stop-on-character, the 20 ms character gap of
firmware 1.xx, a typed line's commands running before the bytes written after
it are read (hosts pipeline: `MA10000\rTS\r` in one write), and the macro
commands (MD, RM, RMALL, RZ, TM, TZ). Everything
else (motion, waits, reports, TS, TB, VE, running stored macros) is the
simulator's VM, `mercmac.vm.Machine`, advanced with wall time; its reports
module formats every report. `Faults` (faults.py) makes it misbehave the way
real links do. ptyserver.py serves it on a pseudo-terminal.

Nothing a host sends stops it: a line it cannot take is refused with the
firmware's TS error code (02, 05, 06), and a `--state` file it cannot read is
refused before it serves, never overwritten.
"""
from __future__ import annotations

import json
import logging
from collections import deque
from pathlib import Path
from typing import Callable

from mercmac import mdtext
from mercmac.commands import C863, SINGLE_CHARS, Mnemonic
from mercmac.compiler.program import Macro, Program
from mercmac.ops import Op, Origin
from mercmac.emulator.faults import EmptySlot, Faults, Framing
from mercmac.errors import InputError
from mercmac import outfile
from mercmac.outfile import OutputError, writable_target, write_text
from mercmac.upload import protocol
from mercmac.vm import Machine, Options
from mercmac.vm import reports
from mercmac.vm.assemble import DIRECT

REPORT_END = b"\r\n\x03"  # MS176E §6.1.3: CR LF ETX after every report
CHAR_GAP_S = 0.020  # MS176E §2 notes: firmware 1.xx drops a line whose characters are > 20 ms apart
BITS_PER_CHAR = 10  # 8N1 on the wire: start bit, 8 data bits, stop bit (Faults.pace)
# Faults.pace: our model of a controller busy with a move, which the manual does not
# describe: while the axis moves, a byte that follows the last one taken by less than
# this is lost (its receiver is read only this often), so text typed at full speed during
# a move arrives garbled, and single-character commands sent alone get through.
MOVE_POLL_S = 0.002
MAX_COMMANDS = mdtext.MAX_COMMANDS  # MS176E §3.8: up to 16 base commands per macro
# A typed line runs its commands that do not wait (at most 16, one cycle each:
# docs/simulator.md, "Time") before the next byte is read: a real controller takes
# microseconds for them, less than one character time, so `MA10000\rTS\r` in one write runs
# the MA. A line that loops without waiting is interrupted after that many cycles by the
# next character (§6.1.1).
SETTLE_CYCLES = MAX_COMMANDS + 1  # + 1: the cycle that ends the line
# TS error codes (MS176E §6.4 TS, block 6 / block 3); the C-663 list ends at 06 too
ERR_TIMEOUT, ERR_OVERFLOW, ERR_STORAGE = 0x01, 0x02, 0x03
ERR_MACRO_RANGE, ERR_MACRO_COMMAND, ERR_COMMAND = 0x04, 0x05, 0x06
# The manual gives no size for the command buffer. The longest legal line is an MD line of
# 16 commands with the longest arguments, "MD31," + 16 x "MA-1073741823" + 15 commas = 228
# characters; 256 holds it with room for a few blanks. A longer line is error 02 "RS-232
# overflow" (§6.4 TS) and the rest of it is dropped up to its CR.
MAX_LINE = 256
LINES_KEPT = 10_000  # `lines` keeps the most recent ones: an emulator may run for weeks
_MACRO_COMMANDS = {Mnemonic.MD, Mnemonic.RM, Mnemonic.RMALL, Mnemonic.RZ, Mnemonic.TM, Mnemonic.TZ,
                   Mnemonic.VE}
_STATE_KEYS = ("model", "macros")
log = logging.getLogger(__name__)


class StateError(InputError):
    """A `--state` file the emulator cannot read or keep; it is left as it is (exit 2)."""


class BadLine(ValueError):
    """A command line the controller refuses (error 05 in MD, 06 in direct mode); says why."""


class VirtualController:
    """The controller: feed it bytes with `receive`, advance it with `tick`, `take` its output."""

    def __init__(self, model: str = C863, address: int = 0, *, firmware: str = "2.30",
                 macros: dict[int, str] | None = None, faults: Faults | None = None,
                 state: Path | None = None):
        self.model, self.address, self.firmware = model, address, firmware
        self.faults = faults or Faults()
        self.state = _state_target(state) if state else None
        self.lines: deque[str] = deque(maxlen=LINES_KEPT)  # command lines, for tests and benchmarks
        self.md_count = 0
        self.busy_until = 0.0  # while storing a macro, further bytes wait in the input buffer
        # bytes from the host not yet read by the firmware: [time written, bytes] per write
        self._held: deque[tuple[float, bytearray]] = deque()
        self._wire_at = -1.0  # when the last byte read from `_held` reached the controller
        self._taken_at = -1.0  # ... and the last one the firmware took (not lost, Faults.pace)
        self._settle_until = 0.0  # a typed line's commands run before the next byte until then
        self.lost = 0  # bytes lost while a move ran (Faults.pace)
        self.vanished = False
        self.selected = False
        self._out = bytearray()
        self._line = bytearray()
        self._overflow = False  # the line outgrew MAX_LINE: drop bytes up to its CR
        self._bugs: set[str] = set()  # failures already logged, each once
        self._last_char_at = 0.0
        self._last_line: str | None = None
        self._awaiting_address = False
        self._now = 0.0
        self.machine = Machine(model=model, options=Options(address=address, firmware=firmware),
                               on_report=lambda t_ms, text: self.report(text))
        exists = self.state is not None and self.state.exists()
        self._store(load_state(self.state, model) if exists else dict(macros or {}))
        self._saved = self.macros  # what the state file holds
        self.power_on(0.0)

    # -- time and bytes ---------------------------------------------------

    @property
    def macros(self) -> dict[int, str]:
        """What the flash memory holds, as TM would list it."""
        return self.machine.stored_macros()

    @property
    def running(self) -> bool:
        return self.machine.running

    @property
    def waiting(self) -> int:
        """Bytes the host sent that the firmware has not read yet (a line still runs, ...)."""
        return sum(len(data) for _, data in self._held)

    def power_on(self, now: float) -> None:
        """Deselected, defaults restored, macro 0 started if stored (MS176E §3.1, §3.8.5)."""
        self._run(now)
        self._safely("power-on", self.machine.power_on)
        self._self_select()

    def _restarted(self) -> None:
        """The front end after power-on or RT, which restarts the firmware "as if from a
        power-off condition" (MS176E §6.4 RT): deselected, on a chain or alone, since "After
        power-on or reset, a Mercury controller is not addressed" (§3.1); no line half read
        and none for a bare CR to repeat."""
        self.selected, self._awaiting_address = False, False
        self._line.clear()
        self._overflow = False
        self._last_line = None

    def tick(self, now: float) -> None:
        """Let running macros advance to wall time `now` (seconds since power-on), and read
        the bytes that have arrived by then, one at a time, as the firmware does."""
        self._run(now)
        self._self_select()
        self._now = now
        while self._held and now >= self.busy_until and not self.vanished:
            written, data = self._held[0]
            at = self._arrival(written)
            if at > now or self._settling(now):
                return
            byte = data[0]
            del data[0]  # O(1) at the front of a bytearray; pop(0) copies the rest
            if not data:
                self._held.popleft()
            self._wire_at = at
            if self._lost(at):
                continue
            self._taken_at = at
            self._safely(f"byte 0x{byte:02X}", self._byte, byte, at)

    def take(self) -> bytes:
        """Bytes waiting to go to the host."""
        data, self._out = bytes(self._out), bytearray()
        if self.faults.garble:
            # a receiver at the wrong baud rate sees other bits, and rarely an ETX
            data = bytes((b * 37 + 11) & 0xFF or 0x80 for b in data).replace(b"\x03", b"\x83")
        return data

    def receive(self, data: bytes, now: float) -> None:
        """Bytes the host wrote at `now`; `tick` hands them to the firmware in order."""
        if data:
            self._held.append((now, bytearray(data)))
        self.tick(now)

    def _arrival(self, written: float) -> float:
        """When the next byte of a write made at `written` has reached the controller."""
        if not self.faults.pace:
            return written  # a pseudo-terminal has no baud rate: the whole write is there
        return max(written, self._wire_at) + BITS_PER_CHAR / self.faults.baud  # after the last

    def _settling(self, now: float) -> bool:
        """Whether the line the host typed is still running commands that do not wait, so
        the next byte waits in the receive buffer (SETTLE_CYCLES); a wait lets it in."""
        m = self.machine
        return now < self._settle_until and m.next_command_ms() <= m.now_ms + m.cycle_ms

    def _lost(self, at: float) -> bool:
        """Faults.pace: a byte too close behind the last one while a move runs (MOVE_POLL_S)."""
        if not (self.faults.pace and at - self._taken_at < MOVE_POLL_S and self.machine.moving()):
            return False
        self.lost += 1
        return True

    def report(self, text: str) -> None:
        """Send a report if selected; deselected controllers stay silent (MS176E §5.1, §5.6)."""
        self._self_select()  # macro 0 may report in the very run of the RT that deselected it
        if self.selected and not self.faults.silent:
            self._out += text.encode("latin-1") + REPORT_END

    def _run(self, now: float) -> None:
        """Advance the VM to wall time `now` (seconds)."""
        self.advance(now * 1000)

    def advance(self, t_ms: float) -> None:
        """Run the VM to `t_ms`; a failure stops the macro, not the controller."""
        self.run_safely(lambda: self.machine.run_until(t_ms))

    def run_safely(self, work: Callable[[], None]) -> None:
        """`work` on the VM (a chain steps its wired machines together, vm/wiring.py); a
        failure stops the macro, not the controller."""
        self._safely("a running macro", work)

    def _run_due(self, now: float) -> None:
        """Also run what is due at `now` itself: the first command of a line just typed,
        whose report must come before anything the host sends after it."""
        due = max(now * 1000, self.machine.now_ms) + 0.001  # 1 us: the VM counts in us
        self._safely("a running macro", self.machine.run_until, due)

    def _safely(self, what: str, work: Callable, *args) -> None:
        """Run one step of the firmware; a bug in it is error 06 and a message, never a crash."""
        try:
            work(*args)
        except Exception as e:  # noqa: BLE001 - the controller must go on serving
            self.machine.stop()
            self.machine.set_error(ERR_COMMAND)
            self._log_once(f"emulator: {what} failed ({type(e).__name__}: {e}); "
                           "answered with error 06 and went on")

    def _log_once(self, message: str) -> None:
        if message not in self._bugs:
            self._bugs.add(message)
            log.error(message, exc_info=log.isEnabledFor(logging.DEBUG))

    def _self_select(self) -> None:
        """A restart deselects the controller (MS176E §3.1); then SCn in the autostart macro
        selects it (§3.1.2: "self-addressing at power-on", which RT repeats, §6.4 SC)."""
        if self.machine.take_restart():
            self._restarted()
        if self.machine.take_self_select() == self.address:
            self.selected = True

    # -- the byte-level rules -----------------------------------------------

    def _byte(self, byte: int, now: float) -> None:
        if self._awaiting_address:
            # second character of the address selection code (MS176E §3.1.3)
            self._awaiting_address = False
            self.selected = chr(byte).upper() == protocol.ADDRESS_CHARS[self.address]
            self._line.clear()
            self._overflow = False
            return
        if byte == protocol.SELECT:
            self._awaiting_address = True
            return
        if not self.selected or byte in (protocol.NUL, protocol.LF, protocol.ETX):
            # MS176E §5.1: deselected, everything but address codes is ignored. NUL comes from
            # adapters; LF and ETX end reports (§6.1.3), never commands (CR does, §6.1.2), but
            # hosts that frame commands like reports send them after the CR (PI's GCS ends
            # lines with LF, §5.2; basil's serial transport appends ETX by default). Taken as
            # characters they would stop a macro just started and spoil the next command.
            return
        char = chr(byte)
        if not self._line and not self._overflow and char in SINGLE_CHARS:
            self._single(char)  # MS176E §6.3: executed at once, a macro keeps running
        elif byte == protocol.CR:
            self._end_of_line(now)
        else:
            self._char(byte, now)

    def _char(self, byte: int, now: float) -> None:
        self.machine.stop()  # MS176E §3.8.3, §6.1.1: any other character stops a macro
        if (self._line or self._overflow) and self._timed_out(now):
            self._line.clear()  # firmware 1.xx: characters too far apart, line dropped
            self._overflow = False
            self.machine.set_error(ERR_TIMEOUT)
        self._last_char_at = now
        if self._overflow:
            return  # the rest of an overlong line goes nowhere
        if len(self._line) >= MAX_LINE:
            self._line.clear()
            self._overflow = True
            self.machine.set_error(ERR_OVERFLOW)
            return
        self._line.append(byte)

    def _timed_out(self, now: float) -> bool:
        return self._gap_limited() and now - self._last_char_at > CHAR_GAP_S

    def _end_of_line(self, now: float) -> None:
        if self._overflow:  # the overlong line is not executed, nor repeated by a bare CR
            self._overflow, self._last_line = False, None
            return
        if self._line and self._timed_out(now):
            self._line.clear()
            self.machine.set_error(ERR_TIMEOUT)
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
        if self.faults.pace:
            return True  # the hardest case a host meets: firmware 1.xx (MS176E §2 notes)
        return self.firmware.startswith("1.")

    # -- commands -------------------------------------------------------------

    def _single(self, char: str) -> None:
        """MS176E §6.3: the same report as the equivalent command; `\\` is 0 or 1 (moving)."""
        equivalent = SINGLE_CHARS[char].equivalent
        if equivalent is None:
            self.report("1" if self.machine.moving() else "0")
        elif equivalent == Mnemonic.AB:
            self.machine.execute_line([Op(Mnemonic.AB)])
        elif equivalent == Mnemonic.TS:
            self.report(self.machine.read_status())  # "%" equals TS (§6.1.3): it reads the error
        elif char in ("+", "(") and self.model != C863:
            return  # TE/TF exist on the C-863 only (§6.3 footnote)
        else:
            [op] = mdtext.parse_line(equivalent, stored=False).ops  # 'TA2' -> TA 2
            self.report(reports.report(op.mnemonic, op.arg, self.machine))

    def _execute(self, text: str, now: float) -> None:
        self.lines.append(text)
        self._settle_until = now + SETTLE_CYCLES * self.machine.cycle_ms / 1000
        self._safely(f"the line {text[:40]!r}", self._command, mdtext.canonical(text), now)
        self._self_select()  # an RT in it: the bytes after it find the controller deselected
        self._save()

    def _command(self, line: str, now: float) -> None:
        """One command line; a refused one is error 06 (§6.4 TS) and changes nothing."""
        if line.startswith(Mnemonic.MD):
            self._define(line)
            return
        try:
            ops = self._ops(line, DIRECT)
        except BadLine:
            self.machine.set_error(ERR_COMMAND)
            return
        if all(op.mnemonic in _MACRO_COMMANDS for op in ops):
            for op in ops:
                self._macro_command(op.mnemonic, op.arg, now)
        else:
            self.machine.execute_line(ops)
            self._run_due(now)  # its first command runs now, its report comes at once

    def _define(self, line: str) -> None:
        """MDn,...: store silently, overwriting (MS176E §3.8.1, §6.4 MD)."""
        self.md_count += 1
        line = self._lose_character(line)
        slot, body = mdtext.split_md(line)
        if slot is None or not 0 <= slot <= 31:
            self.machine.set_error(ERR_MACRO_RANGE)
        else:
            try:
                self.machine.define(slot, self._ops(body, slot))
                self.busy_until = self._now + self.faults.md_delay
            except BadLine:
                self.machine.set_error(ERR_MACRO_COMMAND)
        if self.faults.vanish_after_md is not None and self.md_count >= self.faults.vanish_after_md:
            self.vanished = True

    def _lose_character(self, line: str) -> str:
        faults = self.faults
        index = faults.drop_char.get(self.md_count)
        if index is None and faults.always_drop_slot is not None:
            if mdtext.split_md(line)[0] == faults.always_drop_slot:
                index = len(line) // 2
        if index is None or not line:
            return line
        index = min(index, len(line) - 1)
        return line[:index] + line[index + 1:]

    def _macro_command(self, name: str, arg: int | None, now: float) -> None:
        if name == Mnemonic.VE:
            self.report(self.faults.version or reports.report(Mnemonic.VE, None, self.machine))
        elif name in (Mnemonic.TZ, Mnemonic.TM):
            self._tell([0] if name == Mnemonic.TZ else [arg] if arg else
                       [s for s in self.machine.stored_macros() if s > 0],
                       listing=name == Mnemonic.TM and not arg)
        else:  # RZ, RMn, RM, RMALL (§6.4): the VM erases; the state file follows
            self.machine.execute_line([Op(name, arg)])
            self.machine.run_until(now * 1000 + 1)

    def _tell(self, slots: list[int], listing: bool = False) -> None:
        """TM/TZ answers, framed as `Faults` says (the protocol leaves both open:
        docs/uploader.md)."""
        lines = protocol.lines(reports.macros(self.machine.stored_macros(), slots))
        if not lines and not listing and self.faults.empty_slot is EmptySlot.BARE:
            lines = [mdtext.tm_line(slots[0])]
        if not lines:
            self.report("")  # an empty report
            return
        match self.faults.tm_framing:
            case Framing.ONE_ETX:
                self.report("\r\n".join(lines))
            case Framing.ETX_PER_LINE:
                for line in lines:
                    self.report(line)

    def _save(self) -> None:
        """Write a changed flash memory to the state file; if that fails, the change is undone."""
        macros = self.macros
        if self.state is None or macros == self._saved:
            self._saved = macros
            return
        try:
            save_state(self.state, macros, self.model)
        except OutputError as e:  # the folder went away, the disk is full, ...
            log.error("emulator: %s; error 03, the macros stay as they were", e.message)
            self.machine.set_error(ERR_STORAGE)  # MS176E §6.4 TS: 03 macro storage full
            self._store(self._saved)
        else:
            self._saved = macros

    def _store(self, macros: dict[int, str]) -> None:
        """Make the flash memory hold exactly these macros."""
        self.machine.load(Program({s: _macro(s, self._ops(text, s)) for s, text in macros.items()},
                                  self.model))

    def _ops(self, line: str, slot: int) -> list[Op]:
        """The ops of a line, checked as `mercmac check` checks it (range, model, macro rules)."""
        return _ops(line, slot, self.model)


def _ops(line: str, slot: int, model: str | None = None) -> list[Op]:
    """The base commands of a line, read by mercmac.mdtext; BadLine says what is wrong."""
    stored = slot != DIRECT
    parsed = mdtext.parse_line(line, model=model, stored=stored, slot=slot if stored else None)
    if parsed.errors:
        raise BadLine(parsed.errors[0].message)
    if not parsed.ops:
        raise BadLine("no command")
    return list(parsed.ops)


def _macro(slot: int, ops: list[Op]) -> Macro:
    return Macro(slot, mdtext.slot_name(slot), ops, origin=Origin.STORED)


def _state_target(path: Path) -> Path:
    """PATH if the state can be kept there; checked before serving, not mid-flash."""
    try:
        writable_target(path)
    except OutputError as e:
        raise StateError(f"--state: {e.message}", hint="give a file in a folder that exists "
                         "and can be written; it is created on the first write") from None
    return path


def load_state(path: Path, model: str) -> dict[int, str]:
    """The macros of a `--state` file, read as the controller reads MD lines; else StateError."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"), object_pairs_hook=_no_duplicates)
    except UnicodeDecodeError:
        raise _unreadable(path, "it is not UTF-8 text") from None
    except ValueError as e:
        raise _unreadable(path, f"it is not valid JSON ({e})") from None
    except OSError as e:
        raise _unreadable(path, outfile.reason(e)) from None
    if not isinstance(data, dict):
        raise _unreadable(path, "it is not a JSON object")
    if unknown := [k for k in data if k not in _STATE_KEYS]:
        raise _unreadable(path, f"unknown key {unknown[0]!r} (expected {', '.join(_STATE_KEYS)})")
    if data.get("model", model) != model:
        raise StateError(f"the state file {path} holds the macros of a {data['model']}, "
                         f"not of a {model}; it is left as it is",
                         hint=f"run with --target {data['model']}, or give another --state file")
    macros = data.get("macros", {})
    if not isinstance(macros, dict):
        raise _unreadable(path, "'macros' is not an object of macro numbers and lines")
    return dict(_state_entry(path, key, text, model) for key, text in macros.items())


def _no_duplicates(pairs: list[tuple[str, object]]) -> dict:
    """A JSON object; a key given twice would silently lose one of the two."""
    data = {}
    for key, value in pairs:
        if key in data:
            raise ValueError(f"{key!r} appears twice")
        data[key] = value
    return data


def _state_entry(path: Path, key: str, text: object, model: str) -> tuple[int, str]:
    """One stored macro: upper-cased and checked as an MD line would be (MS176E §6.4 MD)."""
    slot = mdtext.number(key) if key.isascii() and key.strip() == key else None
    if slot is None or not 0 <= slot <= 31:
        raise _unreadable(path, f"{key!r} is not a macro number 0-31")
    if not isinstance(text, str):
        raise _unreadable(path, f"macro {slot} is not a line of text")
    try:
        ops = _ops(mdtext.canonical(text), slot, model)
    except BadLine as e:
        raise _unreadable(path, f"macro {slot} is not a valid macro line: {e}") from None
    return slot, mdtext.format_ops(ops)


def _unreadable(path: Path, why: str) -> StateError:
    return StateError(f"cannot read the state file {path}: {why}; it is left as it is",
                      hint="repair it, or move it aside to start with an empty controller")


def save_state(path: Path, macros: dict[int, str], model: str) -> None:
    """Keep the flash memory across runs: the whole file or the old one (OutputError)."""
    data = {"model": model, "macros": {str(k): v for k, v in sorted(macros.items())}}
    write_text(path, json.dumps(data, indent=1) + "\n")
