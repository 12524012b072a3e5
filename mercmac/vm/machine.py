"""The virtual controller: a bytecode VM over simulated hardware (SPEC §3).

One return point, per-RP counters, XN/XF exits, waits and reports as MS176E
§3.8 and §6.4 describe them. The clock, the I/O lines and the axis are objects
handed in (`Hardware`); `step()` runs one instruction, `run(until)` runs to a
time, doing nothing between events (waits cost one comparison, not a loop).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum
from typing import Callable, Iterable

from mercmac.commands import C663, COMMANDS, MAX_POSITION, Mnemonic
from mercmac.compiler.program import Op, Program
from mercmac.vm import events as ev
from mercmac.vm import fastforward as ff
from mercmac.vm import reports
from mercmac.vm.assemble import DIRECT, Chunk, assemble, assemble_ops
from mercmac.vm.clock import Clock
from mercmac.vm.disasm import instruction
from mercmac.vm.fastforward import (Anchor, Anchors, Loop, Mark, Visit, same_pass,
                                    same_shifted_pass, shifted_passes, skippable)
from mercmac.vm.hazards import HazardLog
from mercmac.vm.lines import Inputs, Outputs
from mercmac.vm.models import DEFAULTS, Options, model_name
from mercmac.vm.motion import Axis
from mercmac.vm.opcodes import Opcode
from mercmac.vm.trigger import PULSE_US, Trigger

INF = math.inf
JT_US = 2_000_000  # §6.4 JT: "Executing the JT command takes about 2 seconds"
BUSY_PASSES = 1000  # a loop without waits this long (or endless) is a busy loop hazard
LOG_LIMIT = 100_000  # effects kept for comparing passes; a longer pass is not skipped
FAST_FORWARD = ("off", "quiet", "all")  # skip no passes, passes that emit nothing, or any

# reports that show the position (fastforward.Mark): TP, TD, TT shift with it; TE and TV
# do not at rest; TS shows the limit and reference switches; all but TT vary while moving
POSITIONAL = {Mnemonic.TP, Mnemonic.TD, Mnemonic.TT, Mnemonic.TE, Mnemonic.TV, Mnemonic.TS}

# §6.4 TS error codes
E_WRONG_COMMAND, E_HARD_STOP, E_SERVO_OFF, E_JOYSTICK = 0x06, 0x07, 0x0A, 0x0B


class Wait(Enum):
    """What a blocked wait command waits for (§6.4 WS, WN, WF)."""

    WS = Mnemonic.WS  # the move to end (on target), then n ms
    WN = Mnemonic.WN  # input n ON
    WF = Mnemonic.WF  # input n OFF


@dataclass(slots=True)
class Hardware:
    """The simulated parts around the processor."""

    clock: Clock
    inputs: Inputs
    outputs: Outputs
    axis: Axis
    trigger: Trigger

    @classmethod
    def for_model(cls, model: str, options: Options, cycle_ms: float = 1.0) -> Hardware:
        return cls(Clock(cycle_ms), Inputs(), Outputs(), Axis(DEFAULTS[model], options), Trigger())


class Machine:
    """A Mercury controller running stored macros and direct-mode lines."""

    # Fast-forward compares this state at each loop anchor (`_state_key`). Every field is
    # here or in NOT_KEYED with the reason it may be left out; tests/test_vm_surface.py
    # fails when a new field is in neither, which would make a skip silently inexact.
    STATE_KEY = ("chunk", "ip", "ret", "block", "counters", "last_rp", "params", "error",
                 "brake", "limits_on", "limits_high", "shown", "mover",
                 "clock", "outputs", "axis", "trigger")  # the parts: their own state_key()
    NOT_KEYED = {
        "model": "fixed for the machine's life",
        "options": "fixed for the machine's life",
        "on_report": "the observer, not the machine",
        "on_event": "the observer, not the machine",
        "trace": "what the observer hears, not what the machine does",
        "fast_forward": "how far to skip, not what a pass does",
        "_log": "fast-forward's own record of what passes emitted (Visit.shape)",
        "_log_base": "fast-forward's own record of what passes emitted (Visit.shape)",
        "anchors": "fast-forward's own record of the visits",
        "_horizon": "the end of the run: it bounds a skip (skippable)",
        "chunks": "the stored macros: load, define and RM/RZ clear the anchors",
        "inputs": "compared on their own: Visit.inputs counts the changes, and scheduled "
                  "ones bound a skip (_next_hardware)",
        "wake": "the clock: Visit.wake, from which the period of a pass comes",
        "waits": "compared on their own: Visit.waits (busy-loop hazard)",
        "hazards": "each is reported once: one in a pass makes its shape unrepeatable",
        "table_done": "a time: inf unless a JT table is being made, and then it bounds a "
                      "skip as a hardware event (_next_hardware)",
    }

    def __init__(self, program: Program | None = None, *, model: str | None = None,
                 cycle_ms: float = 1.0, options: Options | None = None,
                 on_report: Callable[[float, str], None] | None = None,
                 on_event: Callable[[object], None] | None = None, trace: bool = False,
                 hardware: Hardware | None = None, fast_forward: str = "quiet"):
        self.model = model_name(model or (program.target if program else None))
        self.options = options or Options()
        hw = hardware or Hardware.for_model(self.model, self.options, cycle_ms)
        self.clock, self.inputs, self.outputs = hw.clock, hw.inputs, hw.outputs
        self.axis, self.trigger = hw.axis, hw.trigger
        self.on_report, self.on_event, self.trace = on_report, on_event, trace
        # "all" skips passes that report or switch outputs too: the observer must count
        # them from FastForwarded.shape (the Recorder does; on_report gets each report)
        if fast_forward not in FAST_FORWARD:
            raise ValueError(f"fast_forward must be one of {FAST_FORWARD}")
        self.fast_forward = fast_forward
        self._log: list = []  # effects since _log_base: what passes emitted (fastforward.shape)
        self._log_base = 0
        self.chunks: dict[int, Chunk] = {}
        self.anchors = Anchors()
        self.hazards = HazardLog()
        self.waits = 0
        self._horizon = INF
        self._reset_state()
        if program is not None:
            self.load(program)

    # ---------------------------------------------------------------- public API
    def load(self, program: Program) -> None:
        """Replace the stored macros; the machine state stays."""
        self.chunks = assemble(program, self.model)
        self.anchors.clear()

    def define(self, slot: int, ops: Iterable[Op], name: str = "") -> None:
        """Store one macro, as MDn,... does (§3.8.1: silently replaces the old one)."""
        self.chunks[slot] = assemble_ops(ops, slot, name or f"MC{slot:02d}", self.model)
        self.anchors.clear()

    def power_on(self) -> None:
        """Power-on or RT: defaults per model, position 0; macro 0 starts if stored (§3.8.5)."""
        self._reset_state()
        self.outputs.set_bits, self.outputs.pulse_until = 0, -INF
        self.axis.reset()
        self.trigger.reset()
        self._outputs_changed()
        if 0 in self.chunks:
            self._begin(0, "power-on")

    def execute_line(self, ops: Iterable[Op]) -> None:
        """Run a direct-mode command line, as if typed (§5.7.1); it stops what ran before."""
        self.stop()
        self.chunk, self.ip = assemble_ops(ops, DIRECT, "direct", self.model), 0
        self.wake = self.clock.now

    def start_macro(self, slot: int) -> None:
        """Like EMn typed in direct mode: nothing if slot n is empty (§6.4 EM)."""
        self.stop()
        if slot in self.chunks:
            self._begin(slot, "host")

    def stop(self) -> None:
        """Any character stops a running macro or line (§3.8.3); motion goes on."""
        if self.chunk is not None:
            self._emit(ev.MacroLeft(self.clock.now, self.chunk.slot, self.chunk.label,
                                    "stopped", None))
            self._emit(ev.ProgramEnded(self.clock.now))
        self.chunk, self.ret, self.block = None, None, None

    @property
    def running(self) -> bool:
        return self.chunk is not None

    @property
    def now_ms(self) -> float:
        return self.clock.now_ms

    @property
    def now_us(self) -> int:
        return self.clock.now

    @property
    def cycle_ms(self) -> float:
        """How long one executed command takes (SPEC §3 Time)."""
        return self.clock.cycle / 1000

    @property
    def macro(self) -> int | None:
        """The running macro's number; None in direct mode or when a typed line runs."""
        return None if self.chunk is None or self.chunk.slot == DIRECT else self.chunk.slot

    @property
    def label(self) -> str | None:
        """What runs: 'main (MC05)', 'MC05', 'direct' for a typed line; None when nothing does."""
        return None if self.chunk is None else self.chunk.label

    def stored_macros(self) -> dict[int, str]:
        """The stored command lines by macro number, as TM lists them: {5: 'MR5000,WS100'}."""
        return {slot: chunk.line for slot, chunk in sorted(self.chunks.items())}

    def setting(self, name: str) -> int:
        """The value a setting command stored (DP, FM, SM, ...; §6.2); 0 if it has none."""
        return self.params.get(name, 0)

    def set_error(self, code: int) -> None:
        """Record the error code that TS reports (§6.4 TS), as the serial front end does."""
        self.error = code

    def take_self_select(self) -> int | None:
        """The address an SCn in macro 0 selected since the last call (§3.1.2), once."""
        return self.params.pop(Mnemonic.SC, None)

    def input(self, n: int) -> bool:
        """Whether input line n (1-6) is ON."""
        return self.inputs[n]

    def input_lines(self) -> tuple[bool, ...]:
        """Inputs 1-6 by number (index 0 is unused, as the lines count from 1)."""
        return tuple(self.inputs.state)

    def position(self) -> int:
        return round(self.axis.position(self.clock.now))

    @property
    def target(self) -> int:
        return self.axis.target

    def velocity(self) -> int:
        return round(self.axis.velocity(self.clock.now))

    def moving(self) -> bool:
        """Whether the axis moves (or is stuck trying to: SV0 or SA0) now."""
        return self.axis.moving(self.clock.now)

    def outputs_pattern(self) -> int:
        return self.outputs.pattern(self.clock.now)

    def status(self) -> str:
        """The TS report (§6.4 TS), without reading it: the error code stays."""
        return reports.status(self)

    def read_status(self) -> str:
        """TS or `%` as the firmware answers it: the report, after which the error code is 00.

        MS176E is silent on when the error code of §6.4 TS (block 6, C-663 block 3)
        clears, and has no command that clears it; so reading it does, as ERR? ("get the
        error code ... and reset the error to 0") does in the GCS command set (MS163E)
        that these controllers also speak (§1.1). A code that never cleared would make
        every later TS report an old mistake.
        """
        text = reports.status(self)
        self.error = 0
        return text

    def iteration(self) -> int:
        """TI: the counter of the RP that last jumped in the running macro, else 0 (SPEC §3)."""
        if self.chunk is None:
            return 0
        slot = self.chunk.slot
        ip = self.last_rp.get(slot)
        return self.counters.get(slot, {}).get(ip, 0)

    def next_command_ms(self) -> float:
        """When the running line or macro executes its next command; inf while it waits for
        a move or an input line, when nothing runs, and when all that is left is to end."""
        if self.chunk is None or self.block is not None:
            return INF
        if self.ip >= len(self.chunk.code) and self.ret is None:
            return INF  # no return point: the program just ends (§3.8.4)
        return self.wake / 1000

    def next_event_ms(self) -> float:
        """When the next hardware event or command is due; inf when nothing will happen."""
        t_ins = self.wake if self.chunk is not None and self.block is None else INF
        return min(self._next_hardware(), t_ins) / 1000

    def set_input(self, n: int, on: bool) -> None:
        """Set input line n (1-6) now."""
        if self.inputs.set(n, on):
            self._input_changed(n, on)

    def schedule_input(self, t_ms: float, n: int, on: bool) -> None:
        """Set input line n at a later time (a button script)."""
        self.inputs.schedule(round(t_ms * 1000), n, on)

    def run_until(self, t_ms: float) -> None:
        """Advance simulated time to t_ms; motion continues when nothing runs."""
        self.run(round(t_ms * 1000))

    # ---------------------------------------------------------------- the loop
    def run(self, until: int) -> None:
        """Process every event and instruction due before `until` (us), then stop there."""
        self._horizon = until
        while True:
            t_hw = self._next_hardware()
            t_ins = self.wake if self.chunk is not None and self.block is None else INF
            if t_hw <= t_ins and t_hw < until:  # inputs apply before a command at the same time
                self._hardware(int(t_hw))
            elif t_ins < until:
                self.clock.now = t_ins
                self.step()
            else:
                break
        self.clock.now = max(self.clock.now, until)

    def step(self) -> None:
        """Execute one instruction at the current time (clox `run()`: one loop, one match)."""
        chunk = self.chunk
        if chunk is None:
            return
        while self.ip >= len(chunk.code):  # end of the line: back to the return point
            if not self._leave("end"):
                return
            chunk = self.chunk
        ip = self.ip
        opcode, arg = chunk.code[ip]
        self.ip = ip + 1
        now = self.clock.now
        self.wake = now + self.clock.cycle  # §3 Time: each command takes one cycle
        if self.trace:
            self._emit(ev.Executed(now, self._where(ip), instruction(chunk, ip)))
        match opcode:
            case Opcode.XN:
                if not self.inputs.state[arg]:
                    self._leave(f"{Mnemonic.XN}{arg}")
            case Opcode.XF:
                if self.inputs.state[arg]:
                    self._leave(f"{Mnemonic.XF}{arg}")
            case Opcode.EM:
                self._call(arg)
            case Opcode.RP:
                self._repeat(chunk.slot, ip, arg)
            case Opcode.WA:  # §6.4 WA: n ms from the start of the command
                self.waits += 1
                self.wake = now + max(arg * 1000, self.clock.cycle)
            case Opcode.WS:
                self._wait_stop(arg)
            case Opcode.WN | Opcode.WF:
                self._wait_input(arg, opcode is Opcode.WN)
            case Opcode.MR:
                self._move(self.axis.target + arg)
            case Opcode.MA:
                self._move(arg)
            case Opcode.GH:  # §6.4 GH: equivalent to MA0
                self._move(0)
            case Opcode.AB:
                self._halt("abort")
            case Opcode.AB1:
                self._motion("stop", self.axis.decelerate)
            case Opcode.ST:  # §6.4 ST: back to where ST was received, smoothly
                self._motion("stop", lambda t: self.axis.move(t, round(self.axis.position(t))))
            case Opcode.DH:
                self._define_home(arg)
            case Opcode.FE:
                self._find_edge(arg)
            case Opcode.CN:
                self._set_outputs(self.outputs.set_bits | 1 << (arg - 1))
            case Opcode.CF:
                self._set_outputs(self.outputs.set_bits & ~(1 << (arg - 1)))
            case Opcode.CP:
                self._set_outputs(arg)
            case Opcode.SV:
                self.axis.sv = arg
            case Opcode.SA:
                self.axis.sa = arg
            case Opcode.JH:
                self.axis.jh = arg
            case Opcode.JL:
                self.axis.jl = arg
            case Opcode.JC:  # §6.4 JC: +/- 2,147,483,647
                self.axis.jh, self.axis.jl = 2_147_483_647, -2_147_483_647
            case Opcode.MN:
                self._servo(True)
            case Opcode.MF:
                self._servo(False)
            case Opcode.JN:
                self._joystick(arg)
            case Opcode.JF:
                self._joystick(0)
            case Opcode.BN | Opcode.BF:
                self.brake = opcode is Opcode.BN
            case Opcode.LN | Opcode.LF:
                self.limits_on = opcode is Opcode.LN
            case Opcode.LH | Opcode.LL:
                self.limits_high = opcode is Opcode.LH
            case Opcode.ZM | Opcode.ZP | Opcode.ZI:
                self._trigger(opcode, arg)
            case Opcode.JT:
                self._joystick_table(arg)
            case Opcode.SET:
                self.params[arg[0]] = arg[1] if arg[1] is not None else COMMANDS[arg[0]].default or 0
            case Opcode.REPORT if arg[0] == Mnemonic.TS:
                self._report(self.read_status())
                self._mark_report(Mnemonic.TS)
            case Opcode.REPORT:
                self._report(reports.report(arg[0], arg[1], self))
                if arg[0] in POSITIONAL:
                    self._mark_report(arg[0])
            case Opcode.RT:
                self.power_on()
            case Opcode.RZ | Opcode.RM | Opcode.RMALL:
                self._remove(opcode, arg)
            case Opcode.BAD:
                self.error = E_WRONG_COMMAND

    # ---------------------------------------------------------------- control flow
    def _begin(self, slot: int, via: str) -> None:
        """Start a macro from outside: power-on or a host's EM (no return point)."""
        self.ret, self.block, self.wake = None, None, self.clock.now
        self._enter(slot, via)

    def _enter(self, slot: int, via: str) -> None:
        """Enter a macro at its start; its RP counters restart (SPEC §3 Repeat counters)."""
        self.chunk, self.ip = self.chunks[slot], 0
        self.counters.pop(slot, None)
        self.last_rp.pop(slot, None)
        self.anchors.forget_slot(slot)
        self._emit(ev.MacroEntered(self.clock.now, slot, self.chunk.label, via))
        self._loop_anchor(Anchor(Loop.EM, slot), None, INF)

    def _call(self, slot: int) -> None:
        """EMn: the ONE return point becomes 'after this EM' (§3.8.4); n empty: nothing."""
        if slot in self.chunks:
            self.ret = (self.chunk, self.ip)
            self._enter(slot, Mnemonic.EM)

    def _leave(self, why: str) -> bool:
        """The macro ends or a condition fails: continue at the return point, or stop."""
        chunk, ret = self.chunk, self.ret
        back, back_slot = (ret[0].label, ret[0].slot) if ret else (None, None)
        self._emit(ev.MacroLeft(self.clock.now, chunk.slot, chunk.label, why, back, back_slot))
        if ret is None:
            self.chunk = None
            self._emit(ev.ProgramEnded(self.clock.now))
            return False
        (self.chunk, self.ip), self.ret = ret, None
        return True

    def _repeat(self, slot: int, ip: int, n: int) -> None:
        """RPn: counter := n on first arrival, then counts down; jump while > 0 (SPEC §3)."""
        counters = self.counters.setdefault(slot, {})
        left = counters[ip] - 1 if ip in counters else n
        if left <= 0:
            counters.pop(ip, None)
            self.anchors.forget(Anchor(Loop.RP, slot, ip))
            return
        counters[ip] = left
        self.last_rp[slot] = ip
        self.ip = 0
        self._loop_anchor(Anchor(Loop.RP, slot, ip), ip, left - 1)

    # ---------------------------------------------------------------- waits
    def _wait_stop(self, n: int) -> None:
        """WSn: until on target (§4.2), then n ms (§6.4 WS)."""
        self.waits += 1
        if self.axis.stalled:
            self._hazard("ws-never-finishes",
                         f"WS waits for a move that never ends: SV is {self.axis.sv}, "
                         f"SA is {self.axis.sa}")
        if self.axis.moving(self.clock.now):
            self.block = (Wait.WS, n, self.clock.now)
        else:
            self.wake = self.clock.now + max(n * 1000, self.clock.cycle)

    def _wait_input(self, n: int, on: bool) -> None:
        """WNn / WFn: until input n is ON / OFF (§6.4 WN, WF)."""
        self.waits += 1
        if self.inputs.state[n] != on:
            self.block = (Wait.WN if on else Wait.WF, n, self.clock.now)

    def _unblock(self, t: int) -> None:
        """A wait ends at t; the next command runs then, one cycle after the wait at least."""
        kind, value, began = self.block
        extra = value * 1000 if kind is Wait.WS else 0
        self.wake = max(t + extra, began + self.clock.cycle)
        self.block = None

    # ---------------------------------------------------------------- motion
    def _move(self, target: int) -> None:
        """MA/MR/GH: refused with the joystick on or servo off; soft limits clamp (§4.4.2)."""
        if self.axis.joystick:
            return self._refuse("move-joystick-on", E_JOYSTICK,
                                "move refused: the joystick is on (JN); send JF first")
        if not self.axis.servo:
            return self._refuse("move-servo-off", E_SERVO_OFF,
                                "move while the servo is off: the stage will not hold or move; "
                                "send MN first")
        clamped = min(max(target, self.axis.jl), self.axis.jh, MAX_POSITION)
        clamped = max(clamped, -MAX_POSITION)
        self._log.append(Mark(ff.REQUESTED, (target, *self._soft_range())))
        if clamped != target:
            side = "upper" if clamped < target else "lower"
            self._hazard("soft-limit-clamp",
                         f"target {target} lies beyond the {side} soft limit: the stage stops at {clamped}")
        self._motion("move", lambda t: self.axis.move(t, clamped))

    def _refuse(self, rule: str, code: int, message: str) -> None:
        if self.model != C663:  # the C-663 error list ends at 06 (§6.4 TS)
            self.error = code
        self._hazard(rule, message)

    def _motion(self, kind: str, command: Callable[[float], None]) -> None:
        """Run an axis command now and tell the observer about the new profile."""
        t = self.clock.now
        axis = self.axis
        if axis.segs or axis.stalled or not float(axis.final).is_integer():
            self._log.append(Mark(ff.UNSHIFTABLE))  # not from rest on a count: floats differ
        command(t)
        self.mover = self._where(self.ip - 1)  # the command a limit hit will be blamed on
        self._emit(ev.MoveStarted(t, kind, self.axis.target,
                                  self.axis.arrival() if self.axis.moving(t) else t,
                                  tuple(self.axis.segs), self.mover))

    def _halt(self, kind: str) -> None:
        self._motion(kind, self.axis.halt)

    def _define_home(self, value: int) -> None:
        self.axis.define_home(self.clock.now, value)
        self._emit(ev.HomeDefined(self.clock.now, value, self._where(self.ip - 1)))

    def _find_edge(self, mode: int) -> None:
        if not self.axis.servo:
            return self._refuse("move-servo-off", E_SERVO_OFF,
                                "reference search while the servo is off; send MN first")
        found = []
        self._motion("home search", lambda t: found.append(self.axis.find_edge(t, mode)))
        if not found[0]:
            self._hazard("reference-not-found",
                         f"{Mnemonic.FE}{mode} searches away from the reference switch and runs "
                         "to the end of travel")

    def _servo(self, on: bool) -> None:
        """MN: servo on, target := position (§6.4 MN); MF: servo off, the profile stops."""
        if self.axis.moving(self.clock.now):
            self._halt("abort")
        elif on:
            self.axis.halt(self.clock.now)  # jerk-free: the target is where the stage is
        self.axis.servo = on

    def _joystick(self, velocity: int) -> None:
        """JN n / JF: joystick velocity n drives the axis while input 5 is ON (§3.6.1)."""
        self.axis.joystick = velocity
        self._drive_joystick()

    def _drive_joystick(self) -> None:
        if self.axis.joystick and self.inputs.state[5]:
            self._motion("joystick", lambda t: self.axis.move(t, self.axis.jh, self.axis.joystick))
        elif self.axis.moving(self.clock.now):
            self._motion("stop", self.axis.decelerate)

    # ---------------------------------------------------------------- I/O
    def _set_outputs(self, bits: int) -> None:
        self.outputs.set_bits = bits
        self._outputs_changed()

    def _outputs_changed(self) -> None:
        pattern = self.outputs.pattern(self.clock.now)
        if pattern != self.shown:
            self.shown = pattern
            self._emit(ev.OutputsChanged(self.clock.now, pattern))

    def _trigger(self, opcode: Opcode, value: int) -> None:
        """ZM/ZP/ZI set the trigger on output 4 (§4.5.2); each one rearms it."""
        if opcode is Opcode.ZM:
            self.trigger.mode = value
        elif opcode is Opcode.ZP:
            self.trigger.position = value
        else:
            self.trigger.increment = value
        self.trigger.rearm()
        if self.trigger.mode:  # pulses at positions: not counted as boundaries
            self._log.append(Mark(ff.UNSHIFTABLE))

    def _joystick_table(self, table: int) -> None:
        self.params[Mnemonic.JT] = table
        self.table_done = self.clock.now + JT_US
        self.wake = self.table_done

    def _report(self, text: str) -> None:
        t = self.clock.now
        self._emit(ev.Reported(t, text, self._where(self.ip - 1)))
        if self.on_report:
            self.on_report(t / 1000, text)

    def _mark_report(self, mnemonic: str) -> None:
        """Note how the report just made depends on the position (fastforward.moved_shape)."""
        axis = self.axis
        if mnemonic == Mnemonic.TT:
            self._log.append(Mark(ff.PLACED, (COMMANDS[mnemonic].report, axis.target)))
        elif axis.segs or axis.stalled or not float(axis.final).is_integer():
            self._log.append(Mark(ff.UNSHIFTABLE))
        elif mnemonic == Mnemonic.TS:
            self._log.append(Mark(ff.ABSOLUTE))
        elif mnemonic in (Mnemonic.TP, Mnemonic.TD):
            self._log.append(Mark(ff.PLACED, (COMMANDS[mnemonic].report, int(axis.final))))

    def _soft_range(self) -> tuple[int, int]:
        """Where a target is not clamped: the soft limits within the 32-bit range (§4.4.2)."""
        return max(self.axis.jl, -MAX_POSITION), min(self.axis.jh, MAX_POSITION)

    def _remove(self, opcode: Opcode, slot: int | None) -> None:
        """RZ, RM n, RM, RMALL (§6.4): erase stored macros; RMALL resets parameters too."""
        if opcode is Opcode.RZ:
            self.chunks.pop(0, None)
        elif opcode is Opcode.RM and slot:
            self.chunks.pop(slot, None)
        else:
            keep = {0: self.chunks[0]} if opcode is Opcode.RM and 0 in self.chunks else {}
            self.chunks = keep
        if opcode is Opcode.RMALL:
            self.params = dict(DEFAULTS[self.model].settings)
            self.axis.sv, self.axis.sa = DEFAULTS[self.model].sv, DEFAULTS[self.model].sa
        self.anchors.clear()

    # ---------------------------------------------------------------- hardware events
    def _next_hardware(self) -> float:
        t = min(self.inputs.next_change(), self.axis.next_event(), self.table_done)
        if self.outputs.pulse_until > self.clock.now:
            t = min(t, self.outputs.pulse_until)
        if self.trigger.mode:
            t = min(t, self.trigger.next_time(self.axis, self.clock.now))
        return t

    def _hardware(self, t: int) -> None:
        """Everything the hardware does at time t, before any command at t runs."""
        self.clock.now = t
        for n, on in self.inputs.pop_due(t):
            self._input_changed(n, on)
        if self.trigger.mode and self.trigger.next_time(self.axis, t - 1) <= t:
            self._pulse(t)
        self._outputs_changed()  # a pulse that ended
        self._axis_event(t)
        if self.table_done <= t:
            self.table_done = INF
            self._report(reports.TABLE_DONE)

    def _input_changed(self, n: int, on: bool) -> None:
        t = self.clock.now
        self._emit(ev.InputChanged(t, n, on))
        if self.block and self.block[0] in (Wait.WN, Wait.WF) and self.block[1] == n:
            if on == (self.block[0] is Wait.WN):
                self._unblock(t)
        if n == 5 and self.axis.joystick:
            self._drive_joystick()

    def _pulse(self, t: int) -> None:
        self._log.append(Mark(ff.UNSHIFTABLE))
        self.trigger.fire(t)
        self.outputs.pulse_until = t + PULSE_US
        self._outputs_changed()

    def _axis_event(self, t: int) -> None:
        happened = self.axis.advance(t)
        if happened is None:
            return
        if happened[0] == "limit":
            self.error = E_HARD_STOP
            self._hazard("hard-limit", f"the stage hit the {happened[1]} limit switch at "
                         f"{round(self.axis.final)} and stopped abruptly", where=self.mover)
        self._emit(ev.MoveEnded(t, happened[0], round(self.axis.final)))
        if self.block and self.block[0] is Wait.WS:
            self._unblock(t)

    # ---------------------------------------------------------------- fast-forward
    def _loop_anchor(self, anchor: Anchor, own: int | None, remaining: float) -> None:
        """A loop came round: report a busy loop, skip identical passes (fastforward.py)."""
        previous = self.anchors.visits.get(anchor)
        key = self._state_key(own)
        if previous is not None:
            self._busy_loop(anchor, key, previous, remaining)
        visit = self._visit(key, previous)
        self.anchors.arrive(anchor, visit)
        if previous is None or self.fast_forward == "off":
            return
        if not same_pass(previous, visit):
            if self.fast_forward == "all" and same_shifted_pass(previous, visit):
                self._skip_shifted(anchor, own, previous, visit, remaining)
            return
        if visit.shape and self.fast_forward != "all":
            return
        passes = skippable(previous, visit, min(self._horizon, self._next_hardware()), remaining)
        if passes > 0:
            self._skip(anchor, own, passes, visit.wake - previous.wake, visit)

    def _skip_shifted(self, anchor: Anchor, own: int | None, previous: Visit, visit: Visit,
                      remaining: float) -> None:
        """Skip passes that repeat `visit.delta` further on, up to the next boundary."""
        period = visit.wake - previous.wake
        fit = skippable(previous, visit, min(self._horizon, self._next_hardware()), remaining)
        hard = self.options.hard_limits
        if hard is not None:
            hard = (hard[0] + self.axis.shift, hard[1] + self.axis.shift)
        passes = shifted_passes(visit, period, fit, self._soft_range(), hard)
        if passes < fit:  # a boundary, not the counter, ends it: enclosing passes differ
            self._log.append(Mark(ff.UNSHIFTABLE))
        if passes > 0:
            self._skip(anchor, own, passes, period, visit, visit.delta)

    def _busy_loop(self, anchor: Anchor, key: tuple | None, previous: Visit,
                   remaining: float) -> None:
        """Report a long loop without waits, once; it ends the pass, so that pass is not
        skipped (a loop is skipped after two passes without a new hazard, as plain
        stepping would report none in the passes skipped)."""
        looped = anchor.loop is Loop.RP or (key is not None and key == previous.key)
        if looped and self.waits == previous.waits and remaining >= BUSY_PASSES:
            self._hazard("busy-loop", f"{self.chunk.label} loops without a wait: it runs at "
                         f"the full command rate; add WA", where=self._where_anchor(anchor))

    def _visit(self, key: tuple | None, previous: Visit | None) -> Visit:
        """This arrival at an anchor, with what the pass since `previous` emitted."""
        if len(self._log) > LOG_LIMIT:  # passes this long are not compared
            self._log_base += len(self._log)
            self._log.clear()
        pass_shape = moved = delta = None
        whole = previous is not None and previous.logged >= self._log_base
        if whole and key is not None and key == previous.key:
            pass_shape = ff.shape(self._log[previous.logged - self._log_base:], previous.wake)
        skey, position = self._shift_key(key)
        if (whole and pass_shape is None and skey is not None and skey == previous.skey
                and self.fast_forward == "all"):
            delta = position - previous.position
            moved = ff.moved_shape(self._log[previous.logged - self._log_base:],
                                   previous.wake, previous.position)
        return Visit(key, self.wake, self.inputs.version, self.waits,
                     self._log_base + len(self._log), pass_shape, skey, position, delta, moved)

    def _shift_key(self, key: tuple | None) -> tuple[tuple | None, int]:
        """The state key without the axis's position and target, and the target; (None, 0)
        unless the axis rests on its target, a whole count, with no trigger set."""
        axis = self.axis
        if key is None or axis.final != axis.target or self.trigger.mode:
            return None, 0
        axis_key = key[-2]  # Axis.STATE_KEY: segs, final, target, ...
        return key[:-2] + (axis_key[:1] + axis_key[3:], key[-1]), axis.target

    def _skip(self, anchor: Anchor, own: int | None, passes: int, period: int,
              visit: Visit, shift: int = 0) -> None:
        """Skip `passes` copies of the pass that ended at `visit`, each `shift` further on
        than the last; the clock, the position and the target jump exactly."""
        start, position = self.wake, visit.position
        shape = visit.moved if shift or visit.shape is None else visit.shape
        self.wake += passes * period
        if own is not None:
            self.counters[self.chunk.slot][own] -= passes
        if shift:  # at rest on the target (_shift_key): both move on by whole counts
            self.axis.target += passes * shift
            self.axis.final = float(self.axis.target)
        if self.on_report is not None:  # the host hears every report (mercmac emulate)
            for r in ff.expand(shape, start, period, passes, ff.REPORT, position, shift):
                self.on_report(r.t / 1000, r.text)
        self._emit(ev.FastForwarded(start, self.wake, passes, period,
                                    self._where_anchor(anchor), shape, position, shift))
        # after the skip's own event: it belongs to enclosing loops, not to the next pass
        key = self._state_key(own)
        skey, now = self._shift_key(key)
        self.anchors.arrive(anchor, Visit(key, self.wake, self.inputs.version, self.waits,
                                          self._log_base + len(self._log), visit.shape,
                                          skey, now, visit.delta, visit.moved))

    def _state_key(self, own: int | None) -> tuple | None:
        """The whole machine state except the clock and the jumping RP's own counter
        (STATE_KEY); None while the axis moves."""
        if self.axis.moving(self.clock.now) or self.axis.segs:
            return None
        # written out, in STATE_KEY's order, as it runs at every anchor; the chunks are
        # replaced only by load, define and RM, which clear the anchors: a slot stands for one
        slot = self.chunk.slot
        counters = tuple((s, tuple((ip, c) for ip, c in sorted(cs.items())
                                   if not (s == slot and ip == own)))
                         for s, cs in sorted(self.counters.items()))
        ret = (self.ret[0].slot, self.ret[1]) if self.ret else None
        return (slot, self.ip, ret, self.block, counters, tuple(sorted(self.last_rp.items())),
                tuple(self.params.items()), self.error, self.brake, self.limits_on,
                self.limits_high, self.shown, self.mover, self.clock.state_key(),
                self.outputs.state_key(), self.axis.state_key(), self.trigger.state_key())

    # ---------------------------------------------------------------- bookkeeping
    def _reset_state(self) -> None:
        self.chunk: Chunk | None = None
        self.ip = 0
        self.ret: tuple[Chunk, int] | None = None
        self.block: tuple | None = None
        self.wake = self.clock.now
        self.counters: dict[int, dict[int, int]] = {}
        self.last_rp: dict[int, int] = {}
        self.params = dict(DEFAULTS[self.model].settings)
        self.error = 0
        self.brake, self.limits_on = True, True  # §3.4: BN, LN
        self.limits_high = DEFAULTS[self.model].limits_high
        self.table_done = INF
        self.shown = 0
        self.mover: ev.Where | None = None
        self.anchors.clear()

    def _where(self, ip: int) -> ev.Where | None:
        chunk = self.chunk
        if chunk is None or not 0 <= ip < len(chunk.code):
            return None
        return ev.Where(chunk.label, chunk.slot, ip, chunk.spans[ip])

    def _where_anchor(self, anchor: Anchor) -> ev.Where:
        chunk = self.chunks.get(anchor.slot, self.chunk)
        ip = anchor.ip
        span = chunk.spans[ip] if ip < len(chunk.spans) else None
        return ev.Where(chunk.label, chunk.slot, ip, span)

    def _hazard(self, rule: str, message: str, where: ev.Where | None | str = "here") -> None:
        where = self._where(self.ip - 1) if where == "here" else where
        place = (where.slot, where.ip) if where else None
        if self.hazards.first(rule, place):
            self._emit(ev.HazardFound(self.clock.now, rule, message, where))

    def _emit(self, event: object) -> None:
        if ff.logged(event):
            self._log.append(event)
        if self.on_event is not None:
            self.on_event(event)
