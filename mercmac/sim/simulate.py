"""One simulation: every controller of a rig on one clock, from power-on to a time
(docs/simulator.md, docs/rigs.md). A lone program is a rig of one (Rig.of_program).

Each controller is a Machine of its own (vm/machine.py) running its program with a recorder
(sim/record.py). The controllers that wires join, directly or through others, form a group
(sim/group.py), and each group runs on its own: a controller no wire joins on its own
fast-forward (vm/optimiser.py), for only its box, its joystick and its scripted presses reach
it; the controllers of a wired group together, one instant at a time, by the instant rule of
vm/wiring.py (which the virtual chain of `emulate --rig` follows too), skipping the passes
they repeat jointly (sim/rig_skip.py). When nothing is left to happen, a rig whose
controllers all wait for good is dead-locked (sim/rig_deadlock.py).
"""
from __future__ import annotations

import heapq
import time
from dataclasses import dataclass, replace
from itertools import islice
from typing import Iterable, Mapping, Sequence

from mercmac.compiler.program import Program
from mercmac.errors import signal_of
from mercmac.rig.model import Rig
from mercmac.sim import rig_deadlock
from mercmac.sim.group import Edge, Group, groups_of
from mercmac.sim.record import CAP, Recorder
from mercmac.timespec import Press
from mercmac.vm.machine import Listener, Machine
from mercmac.vm.models import Options
from mercmac.vm.optimiser import FastForward
from mercmac.vm.wiring import INF

DEFAULT_UNTIL_MS = 10_000  # --until defaults to 10s (docs/cli.md, "Commands")
SLICE_S = 0.1  # wall time per slice of a run that reports progress


@dataclass(frozen=True, slots=True)
class Hold:
    """The joystick branch of `controller` held at `deflection` (-1..1) from start_ms to
    end_ms (None: to the end of the run), then back to the middle."""

    controller: str
    deflection: float
    start_ms: float
    end_ms: float | None = None


@dataclass(slots=True)
class Run:
    """What one controller's simulation produced: the recorder, and the machine as it stands
    at the end."""

    machine: Machine
    record: Recorder
    until_ms: int | float
    interrupted: int = 0  # the signal that stopped it at until_ms (SIGINT: Ctrl-C), 0: none;
    # the record is what came so far

    @property
    def halted(self) -> bool:
        """The program ended before until_ms (nothing runs any more)."""
        return not self.machine.running

    def final(self) -> dict:
        m = self.machine
        return {"t_ms": self.until_ms, "position": m.position(), "target": m.target,
                "outputs": m.outputs_pattern(), "velocity": m.velocity(), "macro": m.macro}


@dataclass(slots=True)
class Result:
    """What a simulation produced: each controller's Run, by name in the rig's order, and the
    wires' edges."""

    rig: Rig
    runs: dict[str, Run]
    edges: list[Edge]
    until_ms: int | float
    edges_dropped: int = 0  # past CAP edges are counted, not listed (as a run counts its lists)
    interrupted: int = 0  # the signal that stopped the run (SIGINT: Ctrl-C), 0: none
    vcd_cut_at: int | None = None  # us: where the VCD stopped at its size limit
    edges_copied: int = 0  # edges of skipped passes (sim/rig_skip.py), listed or not

    @property
    def hazards(self) -> int:
        return sum(len(run.record.hazards) for run in self.runs.values())

    @property
    def only(self) -> Run:
        """The one controller's Run of a rig of one (a lone program)."""
        (run,) = self.runs.values()
        return run


def schedule(machine: Machine, presses: Iterable[Press]) -> None:
    """Turn `--buttons` presses into timed input changes."""
    for press in presses:
        for n in press.inputs:
            machine.schedule_input(press.start_ms, n, True)
            if press.end_ms is not None:
                machine.schedule_input(press.end_ms, n, False)


def machine_for(program: Program, *, model: str | None = None, cycle_ms: float = 1.0,
                options: Options | None = None, trace: bool = False,
                fast_forward: str = "all",
                listeners: Sequence[Listener] = ()) -> tuple[Machine, Recorder]:
    """A machine with a recorder listening after `listeners`, not yet powered on.

    The recorder counts what skipped passes emitted, so every repeating pass may
    be skipped (fast_forward "all"); "off" steps every pass (for comparisons).
    """
    record = Recorder()
    machine = Machine(program, model=model, cycle_ms=cycle_ms, options=options,
                      listeners=[*listeners, record.on_event], trace=trace,
                      fast_forward=fast_forward)
    record.know(machine.chunks)
    return machine, record


class Simulation:
    """The machines of a rig, their wires and the joystick on one clock."""

    def __init__(self, rig: Rig, programs: Mapping[str, Program], *, cycle_ms: float = 1.0,
                 options: Options | None = None, trace: bool = False,
                 listeners: Mapping[str, Sequence[Listener]] | None = None,
                 fast_forward: FastForward | str = FastForward.ALL):
        mode = FastForward(fast_forward)
        self.rig = rig
        self.machines: dict[str, Machine] = {}
        self.records: dict[str, Recorder] = {}
        for c in rig.controllers:
            own = replace(options or Options(), address=c.address)  # TB reports it (§6.4 TB)
            self.machines[c.name], self.records[c.name] = machine_for(
                programs[c.name], model=c.model, cycle_ms=cycle_ms, options=own, trace=trace,
                listeners=(listeners or {}).get(c.name, ()), fast_forward=mode)
        joint = mode is FastForward.ALL and not trace
        self.groups = [Group({n: self.machines[n] for n in names},
                             [w for w in rig.wires if w.source.controller in names],
                             joint=joint)
                       for names in groups_of(list(self.machines), rig.wires)]
        self._group_of = {name: g for g in self.groups for name in g.machines}
        self.deadlocked = False

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
        self._group_of[controller].hold(round(t_ms * 1000), controller, deflection)

    def power_on(self) -> None:
        """All controllers power on together, at t = 0 or now (a reset of the whole rig;
        macro 0 starts on each, §3.8.5); their outputs go off, and so do the wires."""
        for m in self.machines.values():
            m.power_on()
        self.deadlocked = False
        now = self.now_us()
        for group in self.groups:
            group.power_on(now)

    # ------------------------------------------------------------ the clock
    def run_until(self, until_ms: float) -> None:
        """Advance every group to until_ms on its own (the module's rule); then see whether
        the rig is dead-locked."""
        until = round(until_ms * 1000)
        for group in self.groups:
            group.run_until(until)
        if not self.deadlocked and self._still():
            self.deadlocked = rig_deadlock.check(self)

    def next_us(self) -> float:
        """The earliest event of any machine or of the joystick; inf when none."""
        return min(g.next_us() for g in self.groups)

    @property
    def held_at(self) -> int:
        """The last joystick change (us): activity, for a dead-lock's time."""
        return max(g.held_at for g in self.groups)

    def _still(self) -> bool:
        """Whether nothing is left to happen: no machine has an event or a command due, no
        joystick change is scripted."""
        return self.next_us() == INF

    def edges(self) -> tuple[list[Edge], int]:
        """The wires' edges of every group merged by time (at one instant, in the groups'
        order), up to CAP; and how many more there were."""
        merged = list(islice(heapq.merge(*(g.edges for g in self.groups),
                                         key=lambda e: e.t), CAP))
        return merged, sum(g.edges_seen for g in self.groups) - len(merged)

    def now_us(self) -> int:
        """Where the rig's clock stands: the machines that lag (none runs ahead of it)."""
        return min(m.now_us for m in self.machines.values())

    def now_ms(self) -> float:
        return self.now_us() / 1000

    # ------------------------------------------------------------ a whole run
    def run(self, until_ms: int, progress=None) -> Result:
        """Power on and run to until_ms; Ctrl-C, SIGTERM or SIGHUP ends the run where it is
        (`interrupted`: the signal). `progress` (`update(now_ms)`, `close()`) hears the
        simulated time reached as the run goes."""
        self.power_on()
        try:
            if progress is None:
                self.run_until(until_ms)
            else:
                self._run_reporting(until_ms, progress.update)
        except KeyboardInterrupt as e:
            return self.result(self.now_ms(), interrupted=signal_of(e))
        finally:
            if progress is not None:
                progress.close()
        return self.result(until_ms)

    def _run_reporting(self, until_ms: float, update) -> None:
        """Run to until_ms in slices of about SLICE_S of wall time, calling update(now_ms)
        after each. The slices change what is skipped at once, not what happens."""
        step = 1.0
        while self.now_ms() < until_ms:
            began = time.perf_counter()
            self.run_until(min(until_ms, self.now_ms() + step))
            spent = time.perf_counter() - began
            step = step * 2 if spent < SLICE_S / 2 else max(step / 2, 1.0) \
                if spent > SLICE_S else step
            update(self.now_ms())

    def result(self, until_ms: int | float, interrupted: int = 0) -> Result:
        runs = {name: Run(m, self.records[name], until_ms, interrupted)
                for name, m in self.machines.items()}
        edges, dropped = self.edges()
        return Result(self.rig, runs, edges, until_ms, dropped, interrupted,
                      edges_copied=sum(g.edges_copied for g in self.groups))


def simulate(rig: Rig, programs: Mapping[str, Program], *,
             presses: Mapping[str, Iterable[Press]] | None = None,
             holds: Iterable[Hold] = (), until_ms: int = DEFAULT_UNTIL_MS,
             cycle_ms: float = 1.0, options: Options | None = None, trace: bool = False,
             listeners: Mapping[str, Sequence[Listener]] | None = None,
             fast_forward: FastForward | str = FastForward.ALL, progress=None) -> Result:
    """Power every controller on at t = 0 (macro 0 starts on each, docs/simulator.md,
    "Power-on") and run the rig to until_ms. Ctrl-C ends the run where it is: the Result
    is marked `interrupted`."""
    sim = Simulation(rig, programs, cycle_ms=cycle_ms, options=options, trace=trace,
                     listeners=listeners, fast_forward=fast_forward)
    for name, script in (presses or {}).items():
        sim.press(name, script)
    for hold in holds:
        sim.hold(hold)
    return sim.run(until_ms, progress)


def simulate_program(program: Program, *, presses: Iterable[Press] = (),
                     until_ms: int = DEFAULT_UNTIL_MS, model: str | None = None,
                     watch=None, **kw) -> Run:
    """A lone program's run (a rig of one, Rig.of_program), for a caller that has a Program
    and no file; `watch` is one more listener (with `on_event`, a plot's) that hears every
    event first; the other keywords are simulate's."""
    rig = Rig.of_program("program.mcm", model or program.target)
    name = rig.controllers[0].name
    listeners = {name: [watch.on_event]} if watch is not None else None
    return simulate(rig, {name: program}, presses={name: presses}, until_ms=until_ms,
                    listeners=listeners, **kw).only
