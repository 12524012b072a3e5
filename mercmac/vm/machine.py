"""The virtual controller: a bytecode VM over simulated hardware (docs/simulator.md).

One return point, per-RP counters, XN/XF exits, waits and reports as MS176E
§3.8 and §6.4 describe them. The clock, the I/O lines and the axis are objects
handed in (`Hardware`); `step()` runs one instruction, `run(until)` runs to a
time, doing nothing between events (waits cost one comparison, not a loop).
Fast-forward is a collaborator (vm/optimiser.py): the machine tells it what happens
through a few named hooks and jumps over the passes it finds repeating (`_jump`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum
from operator import attrgetter
from types import MappingProxyType
from typing import Callable, Iterable, Mapping, NamedTuple

from mercmac.commands import C663, COMMANDS, MAX_POSITION, Mnemonic
from mercmac.compiler.program import Program
from mercmac.mdtext import slot_name
from mercmac.ops import Op
from mercmac.vm import events as ev
from mercmac.vm import reports
from mercmac.vm import shapes
from mercmac.vm.assemble import DIRECT, Chunk, assemble, assemble_ops
from mercmac.vm.clock import Clock
from mercmac.vm.disasm import instruction
from mercmac.vm.hazards import HazardLog
from mercmac.vm.lines import Inputs, Outputs
from mercmac.vm.models import DEFAULTS, Options, model_name
from mercmac.vm.motion import Axis, Ended
from mercmac.vm.opcodes import Opcode
from mercmac.vm.optimiser import Anchors, FastForward, Jump, Optimiser
from mercmac.vm.skips import Anchor
from mercmac.vm.statekey import items, key, keyed, part, sorted_items, unkeyed
from mercmac.vm.trigger import PULSE_US, Trigger

INF = math.inf
JT_US = 2_000_000  # §6.4 JT: "Executing the JT command takes about 2 seconds"

# §6.4 TS error codes
E_WRONG_COMMAND, E_HARD_STOP, E_SERVO_OFF, E_JOYSTICK = 0x06, 0x07, 0x0A, 0x0B


Listener = Callable[[object], None]  # hears each event (vm/events.py) as it happens


class Wait(Enum):
    """What a blocked wait command waits for (§6.4 WS, WN, WF)."""

    WS = Mnemonic.WS  # the move to end (on target), then n ms
    WN = Mnemonic.WN  # input n ON
    WF = Mnemonic.WF  # input n OFF


class Blocked(NamedTuple):
    """A wait command that blocks: what it waits for, its argument, and when it began (us)."""

    wait: Wait
    arg: int  # WS: the ms to wait once on target; WN, WF: the input line
    began: int

    def ended_by(self, n: int, on: bool) -> bool:
        """Whether input n turning ON (`on`) or OFF ends this wait."""
        return self.wait is not Wait.WS and self.arg == n and on == (self.wait is Wait.WN)


class Return(NamedTuple):
    """The one return point (§3.8.4): after the EM at `ip` - 1 of `chunk`."""

    chunk: Chunk
    ip: int


class Here(Enum):
    """Where a hazard is found unless told otherwise: the instruction just executed (None
    is a place too: no instruction)."""

    HERE = "here"


HERE = Here.HERE


def _return_key(ret: Return | None) -> tuple | None:
    if ret is None:
        return None
    chunk, ip = ret
    return chunk.slot, ip


def _counters_key(m: Machine, own: int | None) -> tuple:
    """All RP counters but the jumping RP's own, which a skip counts down."""
    slot = m.chunk.slot
    return tuple((s, tuple((ip, c) for ip, c in sorted(cs.items())
                           if not (s == slot and ip == own)))
                 for s, cs in sorted(m.counters.items()))


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


@keyed("_state_key")
@dataclass(init=False, eq=False, repr=False)
class Machine:
    """A Mercury controller running stored macros and direct-mode lines.

    Fast-forward compares the fields marked `key` and `part` at each loop anchor: the
    marks give STATE_KEY, `_state_key(own)` and `unshifted(key)` (vm/statekey.py); every
    other field says why a pass may differ in it and still repeat exactly.
    """

    # load, define and RM replace chunks and clear the anchors: a slot stands for one
    chunk: Chunk | None = key(attrgetter("slot"))
    ip: int = key()
    ret: Return | None = key(_return_key)
    block: Blocked | None = key()
    counters: dict[int, dict[int, int]] = key(_counters_key, own=True)  # by slot, RP's ip
    last_rp: dict[int, int] = key(sorted_items)  # the RP that last jumped, by slot (TI)
    params: dict[str, int] = key(items)
    error: int = key()
    brake: bool = key()
    limits_on: bool = key()
    limits_high: bool = key()
    shown: int = key()  # the output pattern the listeners last heard of
    mover: ev.Where | None = key()  # the command a limit hit will be blamed on
    deflection: float | None = key()  # the joystick as set_joystick holds it; None: input 5
    clock: Clock = part()
    outputs: Outputs = part()
    axis: Axis = part(shifts=Axis.unshifted)
    trigger: Trigger = part(shifts=Trigger.unshifted)
    model: str = unkeyed("fixed for the machine's life")
    options: Options = unkeyed("fixed for the machine's life")
    on_report: Callable[[float, str], None] | None = unkeyed("the host, not the machine")
    listeners: list[Listener] = unkeyed("who hears the events, not the machine")
    trace: bool = unkeyed("what the listeners hear, not what the machine does")
    optimiser: Optimiser = unkeyed("fast-forward itself: the visits it compares, and its own "
                                   "record of what passes emitted (Visit.shape)")
    chunks: dict[int, Chunk] = unkeyed("the stored macros: load, define and RM/RZ clear "
                                       "the anchors")
    _lines: Mapping[int, str] | None = unkeyed("the stored macros' lines (TM), read from "
                                              "chunks; None until asked for after a change")
    inputs: Inputs = unkeyed("compared on their own: Visit.inputs counts the changes, and "
                             "scheduled ones bound a skip (_next_hardware)")
    wake: int = unkeyed("the clock: Visit.wake, from which the period of a pass comes")
    hazards: HazardLog = unkeyed("each is reported once: one in a pass makes its shape "
                                 "unrepeatable")
    expected: Mapping[int, frozenset[str]] = unkeyed("the hazards the loaded program accepts, "
                                                     "by source line: fixed with the program")
    active: int = unkeyed("a time: the last instant it did anything (a command or a hardware "
                          "event), when a rig that waits for good went still (sim/rig_deadlock.py)")
    table_done: float = unkeyed("a time: inf unless a JT table is being made, and then it "
                                "bounds a skip as a hardware event (_next_hardware)")
    restarted: bool = unkeyed("for the serial front end (take_restart), never read here; only "
                              "power-on and RT set it, and neither can run in a macro")

    def __init__(self, program: Program | None = None, *, model: str | None = None,
                 cycle_ms: float = 1.0, options: Options | None = None,
                 on_report: Callable[[float, str], None] | None = None,
                 listeners: Iterable[Listener] = (), on_event: Listener | None = None,
                 trace: bool = False, hardware: Hardware | None = None,
                 fast_forward: FastForward | str = FastForward.QUIET):
        self.model = model_name(model or (program.target if program else None))
        self.options = options or Options()
        hw = hardware or Hardware.for_model(self.model, self.options, cycle_ms)
        self.clock, self.inputs, self.outputs = hw.clock, hw.inputs, hw.outputs
        self.axis, self.trigger = hw.axis, hw.trigger
        self.on_report, self.trace = on_report, trace
        # who hears every event, in this order (a plot, a VCD, the recorder); `on_event`:
        # a first one, for callers with a single listener (tests, a REPL)
        self.listeners: list[Listener] = [*([on_event] if on_event else ()), *listeners]
        self.optimiser = Optimiser(self, FastForward(fast_forward))
        self.chunks, self._lines = {}, None
        self.hazards = HazardLog()
        self.expected = {}
        self.active = 0
        self.deflection = None  # hardware: a reset leaves the joystick where it is
        self.restarted = False
        self._reset_state()
        if program is not None:
            self.load(program)

    # ---------------------------------------------------------------- public API
    def _only_listener(self, listener: Listener) -> None:
        self.listeners[:] = [listener]

    # `machine.on_event = f` makes f the only listener: the single-listener spelling, kept
    # for callers with one (it reads nothing: `listeners` is the list)
    on_event = property(None, _only_listener)

    def load(self, program: Program) -> None:
        """Replace the stored macros; the machine state stays."""
        self.chunks = assemble(program, self.model)
        self.expected = program.expected
        self._code_changed()

    def define(self, slot: int, ops: Iterable[Op], name: str = "") -> None:
        """Store one macro, as MDn,... does (§3.8.1: silently replaces the old one)."""
        self.chunks[slot] = assemble_ops(ops, slot, name or slot_name(slot), self.model)
        self._code_changed()

    def power_on(self) -> None:
        """Power-on or RT: defaults per model, position 0; macro 0 starts if stored (§3.8.5)."""
        self.restarted = True  # first: the front end deselects even if what follows fails
        self._reset_state()
        self.outputs.set_bits, self.outputs.pulse_until = 0, -INF
        self.axis.reset()
        self.trigger.reset()
        self._outputs_changed()
        if 0 in self.chunks:
            self._begin(0, ev.Via.POWER_ON)

    def execute_line(self, ops: Iterable[Op]) -> None:
        """Run a direct-mode command line, as if typed (§5.7.1); it stops what ran before."""
        self.stop()
        self.chunk, self.ip = assemble_ops(ops, DIRECT, "direct", self.model), 0
        self.wake = self.clock.now

    def start_macro(self, slot: int) -> None:
        """Like EMn typed in direct mode: nothing if slot n is empty (§6.4 EM)."""
        self.stop()
        if slot in self.chunks:
            self._begin(slot, ev.Via.HOST)

    def stop(self) -> None:
        """Any character stops a running macro or line (§3.8.3); motion goes on."""
        if self.chunk is not None:
            self._emit(ev.MacroLeft(self.clock.now, self.chunk.slot, self.chunk.label,
                                    ev.Exit.STOPPED, None))
            self._emit(ev.ProgramEnded(self.clock.now))
        self.chunk, self.ret, self.block = None, None, None

    @property
    def anchors(self) -> Anchors:
        """The last visit of every loop anchor (fast-forward's)."""
        return self.optimiser.anchors

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
        """How long one executed command takes (docs/simulator.md, "Time")."""
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
        return dict(self._stored_lines())

    def _stored_lines(self) -> Mapping[int, str]:
        """stored_macros(), read-only and read once per change of code: every snapshot holds
        it, and a report loop takes one per report."""
        if self._lines is None:
            self._lines = MappingProxyType({slot: chunk.line
                                           for slot, chunk in sorted(self.chunks.items())})
        return self._lines

    def setting(self, name: str) -> int:
        """The value a setting command stored (DP, FM, SM, ...; §6.2); 0 if it has none."""
        return self.params.get(name, 0)

    def snapshot(self) -> reports.Snapshot:
        """The machine now, as its reports show it (the one thing vm/reports.py reads).

        Taken once per report, so by position, in Snapshot's field order (keywords cost
        three times as much), and the macros' lines are shared until the code changes."""
        t, axis, trigger, options = self.clock.now, self.axis, self.trigger, self.options
        # the settings the axis and the trigger hold, as their queries report them (JH?, ZM?)
        settings = {**self.params, Mnemonic.JH: axis.jh, Mnemonic.JL: axis.jl,
                    Mnemonic.JN: axis.joystick, Mnemonic.ZM: trigger.mode,
                    Mnemonic.ZP: trigger.position, Mnemonic.ZI: trigger.increment}
        return reports.Snapshot(
            self.model, options.address, options.firmware,
            axis.position(t), axis.velocity(t), axis.target, axis.moving(t), axis.sv, axis.sa,
            self.iteration(), settings, tuple(self.inputs.state), self.inputs.pattern(),
            self._stored_lines(), self.macro is not None, self.error,
            axis.referenced, axis.servo, axis.negative, axis.homing, axis.joystick > 0,
            self.brake, self.limits_on, self.limits_high, axis.reference_high(t),
            axis.limit_switch(t))

    def set_error(self, code: int) -> None:
        """Record the error code that TS reports (§6.4 TS), as the serial front end does."""
        self.error = code

    def take_restart(self) -> bool:
        """Whether power-on or RT restarted the machine since the last call, once: the serial
        front end then deselects the controller (MS176E §3.1, "After power-on or reset")."""
        restarted, self.restarted = self.restarted, False
        return restarted

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
        """TI: the counter of the RP that last jumped in the running macro, else 0
        (docs/simulator.md)."""
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

    def set_joystick(self, deflection: float) -> None:
        """Hold the joystick at `deflection` (-1 full negative .. 1 full positive) from now on.

        §3.6: the joystick sets the axis's velocity, not its position: JN's maximum at full
        deflection (§6.4 JN), scaled by the response table (§6.4 JT); input 5 reads the
        joystick ON above mid-scale (lines.py)."""
        self.deflection = max(-1.0, min(1.0, float(deflection)))
        on = self.deflection > 0
        # what the deflection commands, said first: the input change it makes follows
        self._emit(ev.JoystickMoved(self.clock.now, self.deflection,
                                    self.axis.joystick * self._joystick_response(),
                                    self.axis.joystick, self._response_table(), on))
        if self.inputs.set(5, on):
            self._input_changed(5, on)  # which drives the axis when the joystick is on
        elif self.axis.joystick:
            self._drive_joystick()

    # ---------------------------------------------------------------- the loop
    def run(self, until: int, *, through: bool = False) -> None:
        """Process every event and instruction due before `until` (us), or `through` it
        (at `until` too: an instant of wired machines, vm/wiring.py), then stop at `until`,
        so that an input set next happens there."""
        end = until + 1 if through else until  # whole us: due before until + 1 is due by until
        self.optimiser.running_to(end)
        active = None
        while True:
            t_hw = self._next_hardware()
            t_ins = self.wake if self.chunk is not None and self.block is None else INF
            if t_hw <= t_ins and t_hw < end:  # inputs apply before a command at the same time
                active = int(t_hw)
                self._hardware(active)
            elif t_ins < end:
                self.clock.now = active = t_ins
                self.step()
            else:
                break
        if active is not None:
            self.active = active
        self.clock.now = max(self.clock.now, until)

    def step(self) -> None:
        """Execute one instruction at the current time (clox `run()`: one loop, one match)."""
        chunk = self.chunk
        if chunk is None:
            return
        while self.ip >= len(chunk.code):  # end of the line: back to the return point
            if not self._leave(ev.Exit.END):
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
                    self._leave(ev.FAILED_XN[arg])
            case Opcode.XF:
                if self.inputs.state[arg]:
                    self._leave(ev.FAILED_XF[arg])
            case Opcode.EM:
                self._call(arg)
            case Opcode.RP:
                self._repeat(chunk.slot, ip, arg)
            case Opcode.REPORT if arg[0] == Mnemonic.TS:
                self._report(self.read_status())
                self.optimiser.reported(Mnemonic.TS)
            case Opcode.REPORT:
                self._report(reports.report(arg[0], arg[1], self))
                self.optimiser.reported(arg[0])
            case Opcode.WA:  # §6.4 WA: n ms from the start of the command
                self.optimiser.wait_begun()
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
                self._halt(ev.Motion.ABORT)
            case Opcode.AB1:
                self._motion(ev.Motion.STOP, self.axis.decelerate)
            case Opcode.ST:  # §6.4 ST: back to where ST was received, smoothly
                self._motion(ev.Motion.STOP, lambda t: self.axis.move(t, round(self.axis.position(t))))
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
            case Opcode.RT:
                self.power_on()
            case Opcode.RZ | Opcode.RM | Opcode.RMALL:
                self._remove(opcode, arg)
            case Opcode.BAD:
                self.error = E_WRONG_COMMAND

    # ---------------------------------------------------------------- control flow
    def _begin(self, slot: int, via: ev.Via) -> None:
        """Start a macro from outside: power-on or a host's EM (no return point)."""
        self.ret, self.block, self.wake = None, None, self.clock.now
        self._enter(slot, via)

    def _enter(self, slot: int, via: ev.Via) -> None:
        """Enter a macro at its start; its RP counters restart
        (docs/simulator.md, "Repeat counters")."""
        self.chunk, self.ip = self.chunks[slot], 0
        self.counters.pop(slot, None)
        self.last_rp.pop(slot, None)
        self._emit(ev.MacroEntered(self.clock.now, slot, self.chunk.label, via))
        self.optimiser.macro_entered(slot)

    def _call(self, slot: int) -> None:
        """EMn: the ONE return point becomes 'after this EM' (§3.8.4); n empty: nothing."""
        if slot in self.chunks:
            self.ret = Return(self.chunk, self.ip)
            self._enter(slot, ev.Via.EM)

    def _leave(self, why: ev.Exit) -> bool:
        """The macro ends or a condition fails: continue at the return point, or stop."""
        chunk, ret = self.chunk, self.ret
        back, back_slot = (ret.chunk.label, ret.chunk.slot) if ret else (None, None)
        self._emit(ev.MacroLeft(self.clock.now, chunk.slot, chunk.label, why, back, back_slot))
        if ret is None:
            self.chunk = None
            self._emit(ev.ProgramEnded(self.clock.now))
            return False
        (self.chunk, self.ip), self.ret = ret, None
        return True

    def _repeat(self, slot: int, ip: int, n: int) -> None:
        """RPn: counter := n on first arrival, then counts down; jump while > 0
        (docs/simulator.md, "Repeat counters")."""
        counters = self.counters.setdefault(slot, {})
        left = counters[ip] - 1 if ip in counters else n
        if left <= 0:
            counters.pop(ip, None)
            self.optimiser.loop_ended(slot, ip)
            return
        counters[ip] = left
        self.last_rp[slot] = ip
        self.ip = 0
        self.optimiser.loop_jumped(slot, ip, left - 1)

    # ---------------------------------------------------------------- waits
    def _wait_stop(self, n: int) -> None:
        """WSn: until on target (§4.2), then n ms (§6.4 WS)."""
        self.optimiser.wait_begun()
        if self.axis.stalled:
            self._hazard("ws-never-finishes", sv=self.axis.sv, sa=self.axis.sa)
        if self.axis.moving(self.clock.now):
            self.block = Blocked(Wait.WS, n, self.clock.now)
        else:
            self.wake = self.clock.now + max(n * 1000, self.clock.cycle)

    def _wait_input(self, n: int, on: bool) -> None:
        """WNn / WFn: until input n is ON / OFF (§6.4 WN, WF)."""
        self.optimiser.wait_begun()
        if self.inputs.state[n] != on:
            self.block = Blocked(Wait.WN if on else Wait.WF, n, self.clock.now)

    def _unblock(self, t: int) -> None:
        """A wait ends at t; the next command runs then, one cycle after the wait at least."""
        block = self.block
        extra = block.arg * 1000 if block.wait is Wait.WS else 0
        self.wake = max(t + extra, block.began + self.clock.cycle)
        self.block = None

    # ---------------------------------------------------------------- motion
    def _move(self, target: int) -> None:
        """MA/MR/GH: refused with the joystick on or servo off; soft limits clamp (§4.4.2)."""
        if self.axis.joystick:
            return self._refuse("move-joystick-on", E_JOYSTICK)
        if not self.axis.servo:
            return self._refuse("move-servo-off", E_SERVO_OFF, "move")
        clamped = min(max(target, self.axis.jl), self.axis.jh, MAX_POSITION)
        clamped = max(clamped, -MAX_POSITION)
        self.optimiser.move_requested(target)
        if clamped != target:
            side = "upper" if clamped < target else "lower"
            self._hazard("soft-limit-clamp", each=(target, clamped), target=target, side=side,
                         clamped=clamped)
        self._motion(ev.Motion.MOVE, lambda t: self.axis.move(t, clamped))

    def _refuse(self, rule: str, code: int, variant: str = "") -> None:
        if self.model != C663:  # the C-663 error list ends at 06 (§6.4 TS)
            self.error = code
        self._hazard(rule, variant)

    def _motion(self, kind: ev.Motion, command: Callable[[float], bool | None]) -> None:
        """Run an axis command now and tell the listeners about the new profile (or the
        running one, which a move in flight to where it goes keeps: Axis.keeps)."""
        t = self.clock.now
        note = self.optimiser.profile_note()  # (of the state the profile would start from)
        kept = bool(command(t))
        if not kept:
            self.optimiser.profile_started(note)
        self.mover = self._where(self.ip - 1)  # the command a limit hit will be blamed on
        self._emit(ev.MoveStarted(t, kind, self.axis.target,
                                  self.axis.arrival() if self.axis.moving(t) else t,
                                  tuple(self.axis.segs), self.mover, kept,
                                  self.axis.plan if kept else None))

    def _halt(self, kind: ev.Motion) -> None:
        self._motion(kind, self.axis.halt)

    def _define_home(self, value: int) -> None:
        self.axis.define_home(self.clock.now, value)
        self._emit(ev.HomeDefined(self.clock.now, value, self._where(self.ip - 1)))

    def _find_edge(self, mode: int) -> None:
        if not self.axis.servo:
            return self._refuse("move-servo-off", E_SERVO_OFF, "search")
        found = []
        self._motion(ev.Motion.HOME_SEARCH, lambda t: found.append(self.axis.find_edge(t, mode)))
        if not found[0]:
            self._hazard("reference-not-found", mode=mode)

    def _servo(self, on: bool) -> None:
        """MN: servo on, target := position (§6.4 MN); MF: servo off, the profile stops."""
        if self.axis.moving(self.clock.now):
            self._halt(ev.Motion.ABORT)
        elif on:
            self.axis.halt(self.clock.now)  # jerk-free: the target is where the stage is
        self.axis.servo = on

    def _joystick(self, velocity: int) -> None:
        """JN n / JF: joystick velocity n drives the axis while input 5 is ON (§3.6.1)."""
        self.axis.joystick = velocity
        self._drive_joystick()

    def _drive_joystick(self) -> None:
        velocity = self.axis.joystick * self._joystick_response()
        if velocity:
            end = self.axis.jh if velocity > 0 else self.axis.jl  # soft limits apply (§4.4.2)
            self._motion(ev.Motion.JOYSTICK, lambda t: self.axis.move(t, end, abs(velocity)))
        elif self.axis.moving(self.clock.now):
            self._motion(ev.Motion.STOP, self.axis.decelerate)

    def _joystick_response(self) -> float:
        """The share of JN's velocity the joystick asks for: the deflection through the
        response table (§6.4 JT: 0 linear, 1 cubic, 2 and 3 the same inverted); without
        set_joystick, input 5 ON is full positive deflection."""
        d = self.deflection if self.deflection is not None else float(self.inputs.state[5])
        table = self._response_table()
        shaped = d ** 3 if table in (1, 3) else d
        return -shaped if table in (2, 3) else shaped

    def _response_table(self) -> int:
        return self.params.get(Mnemonic.JT, 1)  # §6.4 JT: cubic is the factory default

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
        self.optimiser.trigger_set()

    def _joystick_table(self, table: int) -> None:
        self.params[Mnemonic.JT] = table
        self.table_done = self.clock.now + JT_US
        self.wake = self.table_done

    def _report(self, text: str) -> None:
        t = self.clock.now
        self._emit(ev.Reported(t, text, self._where(self.ip - 1)))
        if self.on_report:
            self.on_report(t / 1000, text)

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
        self._code_changed()

    def _code_changed(self) -> None:
        """The stored macros changed: their lines are read again, their loops compared anew."""
        self._lines = None
        self.optimiser.code_changed()

    # ---------------------------------------------------------------- hardware events
    def _next_hardware(self, axis: bool = True) -> float:
        """When the hardware next does something by itself (with `axis`, the axis too)."""
        if axis:
            t = min(self.inputs.next_change(), self.axis.next_event(), self.table_done)
        else:
            t = min(self.inputs.next_change(), self.table_done)
        if self.outputs.pulse_until > self.clock.now:
            t = min(t, self.outputs.pulse_until)
        if self.trigger.mode and axis:  # pulses of the running profile
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
        self.optimiser.input_changed()
        self._emit(ev.InputChanged(t, n, on))
        if self.block and self.block.ended_by(n, on):
            self._unblock(t)
        if n == 5 and self.axis.joystick:
            self._drive_joystick()

    def _pulse(self, t: int) -> None:
        self.optimiser.pulsed()
        self.trigger.fire(t)
        self.outputs.pulse_until = t + PULSE_US
        self._outputs_changed()

    def _axis_event(self, t: int) -> None:
        ending = self.axis.advance(t)
        if ending is None:
            return
        if ending.how is Ended.LIMIT:
            self.error = E_HARD_STOP
            self._hazard("hard-limit", side=ending.side, position=round(self.axis.final),
                         where=self.mover)
        self._emit(ev.MoveEnded(t, ending.how, round(self.axis.final)))
        if self.block and self.block.wait is Wait.WS:
            self._unblock(t)

    # ---------------------------------------------------------------- fast-forward
    def _jump(self, jump: Jump) -> None:
        """Skip the passes the optimiser found repeating (vm/optimiser.py), each `jump.shift`
        further on than the last: the clock, the position and the target jump exactly."""
        start = self.wake
        if jump.own is not None:
            self.counters[self.chunk.slot][jump.own] -= jump.passes
        if jump.steady:  # the stage goes on along the profile, to the target the passes
            self.wake += jump.passes * jump.period  # moved it on to
            if jump.shift:
                self.axis.retarget(self.axis.target + jump.passes * jump.shift)
        else:
            self._move_on(jump.passes * jump.period, jump.passes * jump.shift)
        if self.on_report is not None:  # the host hears every report (mercmac emulate)
            for r in shapes.expand(jump.shape, start, jump.period, jump.passes, shapes.REPORT,
                                   jump.position, jump.shift):
                self.on_report(r.t / 1000, r.text)
        self._emit(ev.FastForwarded(start, self.wake, jump.passes, jump.period,
                                    self._where_anchor(jump.anchor), jump.shape,
                                    jump.position, jump.shift, self.clock.now,
                                    jump.counted, jump.steady))

    def skip_passes(self, t: int, passes: int, period: int, shape: tuple, position: int,
                    shift: int, spent: Mapping[tuple[int, int], int]) -> None:
        """Skip `passes` passes that a rig found repeating jointly from the instant t
        (sim/rig_skip.py), each `period` us long and `shift` counts further on than the last,
        each counting the RP at (slot, ip) down by spent[(slot, ip)]. A rig skips between two
        instants, so the clock and a wait's start move on too; a jump of its own (_jump) skips
        from a loop anchor, before the clock reaches the next command."""
        span = passes * period
        for (slot, ip), d in spent.items():
            self.counters[slot][ip] -= d * passes
        self.clock.now += span
        if self.block is not None:  # how long it has waited stays the same
            self.block = self.block._replace(began=self.block.began + span)
        self._move_on(span, shift * passes)
        if self.chunk is not None:  # one that runs nothing did nothing in the passes
            self.tell(ev.FastForwarded(t, t + span, passes, period, self._place(), shape,
                                       position, shift))

    def _move_on(self, span: int, moved: int) -> None:
        """What every skip moves on: the next command by `span` us; the axis, at rest or on
        its way, and the trigger by `span` us and `moved` counts, exactly (Axis.translate)."""
        self.wake += span
        self.axis.translate(span, moved)
        self.trigger.translate(span, moved)

    def rp_counters(self) -> dict[tuple[int, int], int]:
        """The RP counters by (slot, RP's place): what each loop has left to count down."""
        return {(slot, ip): c for slot, cs in self.counters.items() for ip, c in cs.items()}

    def _joint_state(self, t: int) -> tuple:
        """The state key as a rig compares it at the instant t (Optimiser.joint_key): which RPs
        count, not by how much (the rig counts them down itself, sim/rig_skip.py), and a wait
        by how long it has waited, up to a cycle (its start matters only to the first cycle
        after it). Machine is the one module that knows where fields stand in its key."""
        key = list(self._state_key(None))
        key[_COUNTERS] = tuple(sorted(self.rp_counters()))
        block = self.block
        if block is not None:
            key[_BLOCK] = (block.wait, block.arg, min(t - block.began, self.clock.cycle))
        return tuple(key)

    def _busy_loop(self, anchor: Anchor) -> None:
        """The optimiser found a long loop without a wait at `anchor`."""
        self._hazard("busy-loop", macro=self.chunk.label, where=self._where_anchor(anchor))

    # ---------------------------------------------------------------- bookkeeping
    def _reset_state(self) -> None:
        self.chunk = None
        self.ip = 0
        self.ret = None
        self.block = None
        self.wake = self.clock.now
        self.counters = {}
        self.last_rp = {}
        self.params = dict(DEFAULTS[self.model].settings)
        self.error = 0
        self.brake, self.limits_on = True, True  # §3.4: BN, LN
        self.limits_high = DEFAULTS[self.model].limits_high
        self.table_done = INF
        self.shown = 0
        self.mover = None
        self.optimiser.code_changed()

    def last_command(self) -> ev.Where | None:
        """The command the machine ran last (a blocked one: its wait), as events name a place;
        None when it runs nothing."""
        return self._where(self.ip - 1)

    def _place(self) -> ev.Where:
        """Where a running machine stands in its pass: the command it ran last, or its next."""
        return self._where(min(max(self.ip - 1, 0), len(self.chunk.code) - 1))

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

    def _hazard(self, rule: str, variant: str = "", /, *,
                where: ev.Where | None | Here = HERE, each: tuple = (), **values) -> None:
        """Report `rule` in the words of its `variant` message (mercmac/hazards.py), once per place
        (and per `each`: what makes one occurrence another), accepted when the run or the
        program's line accepts it."""
        where = self._where(self.ip - 1) if where is HERE else where
        place = (where.slot, where.ip, *each) if where else None
        message = self.hazards.add(rule, place, variant, **values)
        if message is not None:
            self._emit(ev.HazardFound(self.clock.now, rule, message, where,
                                      self.accepts(rule, where)))

    def accepts(self, rule: str, where: ev.Where | None) -> bool:
        """Whether the user accepts hazard `rule` here: for the whole run (Options.accepted),
        or on the source line of the command (Program.expected)."""
        if rule in self.options.accepted:
            return True
        line = where.line if where is not None else None
        return line is not None and rule in self.expected.get(line, ())

    def _emit(self, event: object) -> None:
        self.optimiser.emitted(event)
        self.tell(event)

    def tell(self, event: object) -> None:
        """Have the listeners hear `event`. From outside (a rig's skip or dead-lock,
        sim/rig_skip.py, sim/rig_deadlock.py) the optimiser does not log it: it is no effect
        of one of this machine's passes."""
        for listener in self.listeners:
            listener(event)


# where the fields that a rig compares its own way stand in the state key (_joint_state)
_COUNTERS = Machine.STATE_KEY.index("counters")
_BLOCK = Machine.STATE_KEY.index("block")
