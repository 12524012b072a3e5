"""All controllers of a rig on one simulated clock (`sim RIG`, docs/rigs.md).

Each controller is a Machine of its own (vm/machine.py) running its program; the rig
advances them together, one instant at a time, by the instant rule of vm/wiring.py (which
the virtual chain of `emulate --rig` follows too): the earliest event of any machine, of
the joystick, or of a button script.
"""
from __future__ import annotations

import heapq
from dataclasses import dataclass, replace
from typing import Iterable, Mapping, Sequence

from mercmac.compiler.program import Program
from mercmac.errors import signal_of
from mercmac.rig.model import Rig, Wire
from mercmac.sim.record import CAP
from mercmac.sim.rig_ff import JointForward
from mercmac.sim.simulate import DEFAULT_UNTIL_MS, Run, machine_for, schedule
from mercmac.timespec import Press
from mercmac.vm import events as ev
from mercmac.vm.machine import Listener, Machine, Wait
from mercmac.vm.wiring import INF, Wired
from mercmac.vm.models import Options

DEADLOCK = "rig-deadlock"  # vm/hazards.py MH008


@dataclass(frozen=True, slots=True)
class Edge:
    """A wire changed level at t (us): the driving output's new level."""

    t: int
    wire: Wire
    level: bool


@dataclass(frozen=True, slots=True)
class Hold:
    """The joystick branch of `controller` held at `deflection` (-1..1) from start_ms to
    end_ms (None: to the end of the run), then back to the middle."""

    controller: str
    deflection: float
    start_ms: float
    end_ms: float | None = None


@dataclass(slots=True)
class RigRun:
    """What a rig simulation produced: each controller's Run and the wires' edges."""

    rig: Rig
    runs: dict[str, Run]
    edges: list[Edge]
    until_ms: int
    edges_dropped: int = 0  # past CAP edges are counted, not listed (as a single run counts them)
    interrupted: int = 0  # the signal that stopped the run (SIGINT: Ctrl-C), 0: none

    @property
    def hazards(self) -> int:
        return sum(len(run.record.hazards) for run in self.runs.values())


class RigSim:
    """The machines of a rig, their wires and the joystick on one clock."""

    def __init__(self, rig: Rig, programs: Mapping[str, Program], *, cycle_ms: float = 1.0,
                 options: Options | None = None, trace: bool = False,
                 listeners: Mapping[str, Sequence[Listener]] | None = None,
                 fast_forward: bool = True):
        self.rig = rig
        self.machines: dict[str, Machine] = {}
        self.records = {}
        for c in rig.controllers:
            own = replace(options or Options(), address=c.address)  # TB reports it (§6.4 TB)
            self.machines[c.name], self.records[c.name] = machine_for(
                programs[c.name], model=c.model, cycle_ms=cycle_ms, options=own, trace=trace,
                listeners=(listeners or {}).get(c.name, ()))
        self.wired = Wired(self.machines, rig.wires,
                           on_edge=lambda t, wire, level: self.add_edge(Edge(t, wire, level)))
        self.edges: list[Edge] = []
        self.edges_dropped = 0
        self.holds: list[tuple[int, int, str, float]] = []  # (t_us, order, controller, d)
        self.deadlocked = False
        self.joint = JointForward(self) if fast_forward and not trace else None

    # ------------------------------------------------------------ what happens to it
    def press(self, controller: str, presses: Iterable[Press]) -> None:
        """Buttons of the box pressed on `controller`'s inputs (`--buttons`, docs/cli.md)."""
        schedule(self.machines[controller], presses)

    def hold(self, hold: Hold) -> None:
        """The joystick deflected on `hold.controller` over a time range (§3.6)."""
        self._at(hold.start_ms, hold.controller, hold.deflection)
        if hold.end_ms is not None:
            self._at(hold.end_ms, hold.controller, 0.0)

    def _at(self, t_ms: float, controller: str, deflection: float) -> None:
        heapq.heappush(self.holds, (round(t_ms * 1000), len(self.holds), controller, deflection))

    def power_on(self) -> None:
        """All controllers power on together, at t = 0 or now (a reset of the whole rig;
        macro 0 starts on each, §3.8.5); their outputs go off, and so do the wires."""
        for m in self.machines.values():
            m.power_on()
        self.deadlocked = False
        if self.joint is not None:
            self.joint.seen.clear()  # passes before the reset are no pattern for after it
        self.wired.carry(round(self.now_ms() * 1000))

    # ------------------------------------------------------------ the clock
    def run_until(self, until_ms: float) -> None:
        """Advance every machine to until_ms, instant by instant (the module's rule)."""
        until = round(until_ms * 1000)
        while not self.deadlocked:
            t = self.next_us()
            if t >= until:
                break
            self._instant(t)
            if self.joint is not None:
                self.joint.arrive(t, until)
        for m in self.machines.values():
            m.run(until)

    def next_us(self) -> float:
        """The earliest event of any machine or of the joystick; inf when none is left."""
        t = self.wired.next_us()
        return min(t, self.holds[0][0]) if self.holds else t

    @property
    def levels(self) -> dict[Wire, bool]:
        """Each wire's level now (its driving output's)."""
        return self.wired.levels

    def _instant(self, t: int) -> None:
        self._joystick(t)
        self.wired.instant(t)
        if self.next_us() == INF:
            self._check_deadlock(t)

    def _joystick(self, t: int) -> None:
        while self.holds and self.holds[0][0] <= t:
            _, _, name, deflection = heapq.heappop(self.holds)
            self.wired.at(name, t).set_joystick(deflection)

    def add_edge(self, edge: Edge) -> None:
        """Keep an edge, up to CAP; past it, count it."""
        if len(self.edges) < CAP:
            self.edges.append(edge)
        else:
            self.edges_dropped += 1

    # ------------------------------------------------------------ dead-lock (MH008)
    def _check_deadlock(self, t: int) -> None:
        """Nothing is due any more (no timer, move, scripted button or joystick change), so
        no output and no wire will change: a controller that waits (WN/WF) on an input no
        box button drives waits for good, whether a wire or nothing drives it. When every
        controller has ended or waits for good, and one waits on a line, the rig is
        dead-locked (docs/rigs.md). A wait on a box button is a wait for a person, who may
        still come: never a dead-lock."""
        running = {name: m for name, m in self.machines.items() if m.running}
        stuck = {name: m for name, m in running.items() if self._stuck(name, m)}
        waiting = {name: m for name, m in stuck.items() if m.block.wait is not Wait.WS}
        if not waiting or len(stuck) < len(running):
            return
        self.deadlocked = True
        waits = "; ".join(self._waiting_text(name, m) for name, m in waiting.items())
        for name, m in waiting.items():
            message = m.hazards.add(DEADLOCK, (name,), waits=waits)
            if message is not None:
                m.tell(ev.HazardFound(t, DEADLOCK, message, m.last_command()))

    def _stuck(self, name: str, m: Machine) -> bool:
        """Whether `m`, with nothing due, waits for good: on an input line no button of the
        box drives, or in WS for a move that never ends (MH005)."""
        block = m.block
        return block is not None and (block.wait is Wait.WS
                                      or block.arg not in self.rig.box_inputs(name))

    def _waiting_text(self, name: str, m: Machine) -> str:
        block = m.block
        wanted = block.wait is Wait.WN
        return (f"{name} waits in {m.label} at {block.wait.name}{block.arg} for in{block.arg} "
                f"{_word(wanted)} ({self._why_never(name, block.arg, not wanted)})")

    def _why_never(self, name: str, number: int, level: bool) -> str:
        """Why input `number` of `name` stays at `level`: nothing drives it, or the output
        at the far end of its wire stays there, its controller ended or waiting too."""
        wires = self.rig.drivers(name, number)
        if not wires:
            return "no wire or box button drives it"
        source = wires[0].source.controller
        m = self.machines[source]
        state = ("has ended" if not m.running
                 else "waits for a move that never ends" if m.block.wait is Wait.WS
                 else "waits too")
        return f"from {wires[0].source}, which stays {_word(level)}: {source} {state}"

    def run(self, until_ms: int) -> RigRun:
        """Power on and run to until_ms; Ctrl-C, SIGTERM or SIGHUP ends the run where it is
        (`interrupted`: the signal)."""
        self.power_on()
        try:
            self.run_until(until_ms)
        except KeyboardInterrupt as e:
            return self.result(round(self.now_ms()), interrupted=signal_of(e))
        return self.result(until_ms)

    def now_ms(self) -> float:
        """Where the rig's clock stands: the machines that lag (none runs ahead of it)."""
        return min(m.now_ms for m in self.machines.values())

    # ------------------------------------------------------------ the result
    def result(self, until_ms: int, interrupted: int = 0) -> RigRun:
        runs = {name: Run(m, self.records[name], until_ms, interrupted=interrupted)
                for name, m in self.machines.items()}
        return RigRun(self.rig, runs, self.edges, until_ms, self.edges_dropped, interrupted)


def _word(on: bool) -> str:
    return "ON" if on else "OFF"


def simulate_rig(rig: Rig, programs: Mapping[str, Program], *,
                 presses: Mapping[str, Iterable[Press]] | None = None,
                 holds: Iterable[Hold] = (), until_ms: int = DEFAULT_UNTIL_MS,
                 cycle_ms: float = 1.0, options: Options | None = None, trace: bool = False,
                 listeners: Mapping[str, Sequence[Listener]] | None = None,
                 fast_forward: bool = True) -> RigRun:
    """Power every controller on at t = 0 and run the rig to until_ms.
    Ctrl-C ends the run where it is: the RigRun is marked `interrupted`."""
    sim = RigSim(rig, programs, cycle_ms=cycle_ms, options=options, trace=trace,
                 listeners=listeners, fast_forward=fast_forward)
    for name, script in (presses or {}).items():
        sim.press(name, script)
    for hold in holds:
        sim.hold(hold)
    return sim.run(until_ms)
