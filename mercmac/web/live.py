"""A simulation run against the wall clock for the page of `sim --web`: the buttons the page
presses, the state it draws, and the session kept as a scenario.

Every press goes through the machine's input schedule at a whole millisecond just ahead of
the simulated clock, the way `--buttons` and `--scenario` presses go (sim/simulate.py
`schedule`), so that the session saved as a scenario replays to the same state on the
command line. Time runs at `speed` simulated seconds per wall second, or as fast as the
machine goes (`speed` None), in slices that stop at a wall-clock deadline so that the page
is answered on time. One lock guards the simulation: the HTTP server's threads share it.

What the page draws as it happens is kept as logs that each page reads from its own
cursor: the timeline's lines (hazards marked as such) and, on a rig with two or three axes
(Rig.path_axes), the stage's XY path sampled where each step of the clock ends. A reload
(web/watch.py) replaces the simulation and keeps both logs; a program with errors keeps the
last good one running and lists them (`problems`).
"""
from __future__ import annotations

import math
import threading
import time
from dataclasses import dataclass
from typing import Mapping

from mercmac.commands import unit
from mercmac.render import sim as render
from mercmac.rig.presses import refusal
from mercmac.sim.simulate import Simulation
from mercmac.vm.events import HazardFound

SLICE_MS = 100  # simulated time run between two looks at the wall clock
SPEEDS = (0.1, 100.0)  # the slowest and fastest real-time factors the page offers
LOG = 2000  # timeline lines kept for a page that connects late
PATH = 20_000  # path points kept for a page that connects late
BUTTONS = range(1, 5)  # the C-170.PB's four buttons on inputs 1-4 (MS176E §4.5.1)


@dataclass(frozen=True, slots=True)
class Change:
    """A button pressed (`down`) or released on a controller at a whole millisecond after
    the last power-on."""

    at_ms: int
    controller: str
    button: int
    down: bool


class Log:
    """What happened, in order, the last `keep` of it; each page reads on from its cursor
    (the count of entries it has seen since the session started)."""

    def __init__(self, keep: int):
        self.keep, self.entries, self.dropped = keep, [], 0

    def add(self, entry) -> None:
        self.entries.append(entry)

    def since(self, seen: int) -> tuple[list, int]:
        """The entries after the first `seen`, and the count seen then."""
        return self.entries[max(0, seen - self.dropped):], self.dropped + len(self.entries)

    def trim(self) -> None:
        cut = len(self.entries) - self.keep
        if cut > 0:
            del self.entries[:cut]
            self.dropped += cut

    def clear(self) -> None:
        self.dropped += len(self.entries)
        self.entries.clear()


class Live:
    """The simulation of one program or rig, its clock tied to the wall clock."""

    def __init__(self, sim: Simulation, file: str, *, speed: float | None = 1.0,
                 held: Mapping[str, tuple[int, ...]] | None = None):
        """`held`: the inputs held at power-on, by controller (`--hold`)."""
        self.file = file
        self.lock = threading.Lock()
        self.speed: float | None = speed
        self.paused = False
        self.log = Log(LOG)  # (text, kind): kind "line", "hazard" or "note"
        self.path = Log(PATH)  # [x, y] or [x, y, z] of the path axes
        self.problems: list[str] = []  # the file's errors since it last changed, as check words them
        self._start(sim, held or {})

    def _start(self, sim: Simulation, held: Mapping[str, tuple[int, ...]]) -> None:
        """Power-on of `sim` (a new session's, or the file's again after a reload)."""
        self.sim = sim
        self.changes: list[Change] = []  # since the last power-on
        self.power_ms = 0  # simulated time of the last power-on
        self.hazard: dict[str, str] = {}  # each controller's last hazard since power-on
        for name, machine in sim.machines.items():
            machine.listeners.append(self._listener(name, unit(machine.model)))
        self.path_axes = sim.rig.path_axes()
        self.axes = [sim.machines[name] for name in self.path_axes]
        self.pressable = {name: [refusal(sim.rig, name, n) is None for n in BUTTONS]
                          for name in sim.machines}  # the wires say it, once per program
        for name, inputs in held.items():
            for n in inputs:
                sim.machines[name].set_input(n, True)
                self.changes.append(Change(0, name, n, True))
        sim.power_on()
        self.path.clear()
        self._sample()
        self._rebase()

    def _listener(self, name: str, unit_: str):
        several = len(self.sim.machines) > 1

        def heard(event) -> None:
            if isinstance(event, render.LIVE_EVENTS):
                line = render.event_line(event, unit_)
                if line is not None:
                    text = "".join(part for part, _ in line)
                    kind = "line"
                    if isinstance(event, HazardFound) and not event.accepted:
                        kind, self.hazard[name] = "hazard", f"{event.rule}: {event.message}"
                    self.log.add((f"{name}  {text}" if several else text, kind))
        return heard

    # ------------------------------------------------------------ the clock
    def advance(self, budget_s: float = 0.02) -> None:
        """Run to where the wall clock says simulated time is, at most `budget_s` of work."""
        with self.lock:
            if self.paused:
                return
            deadline = time.monotonic() + budget_s
            if self.speed is None:  # as fast as it goes: whatever the budget allows
                while time.monotonic() < deadline:
                    self.sim.run_until(self.sim.now_ms() + SLICE_MS)
                    self._sample()
                self._trim()
                return
            # whole milliseconds only: a press is scheduled at one, and a saved scenario
            # expects what the controllers show at one
            goal = math.floor(self._anchor_ms
                              + (time.monotonic() - self._anchor_wall) * 1000 * self.speed)
            while self.sim.now_ms() < goal and time.monotonic() < deadline:
                self.sim.run_until(min(goal, self.sim.now_ms() + SLICE_MS))
                self._sample()
            if self.sim.now_ms() < goal:  # behind: the wall clock waits for the simulation
                self._rebase()
            self._trim()

    def _rebase(self) -> None:
        self._anchor_wall, self._anchor_ms = time.monotonic(), self.sim.now_ms()

    def _trim(self) -> None:
        self.log.trim()
        self.path.trim()

    def _sample(self) -> None:
        """A point of the path where the clock stands, if the rig draws one and it moved."""
        if len(self.axes) < 2:
            return
        point = [m.position() for m in self.axes]
        last = self.path.entries[-1] if self.path.entries else None
        if point != last:
            self.path.add(point)

    def set_speed(self, speed: float | None) -> None:
        """Real-time factor `speed` (SPEEDS), or None: as fast as it goes."""
        if speed is not None and not (SPEEDS[0] <= speed <= SPEEDS[1]):  # refuses nan too
            raise ValueError(f"speed {speed!r}: from {SPEEDS[0]:g} to {SPEEDS[1]:g}, or null "
                             "for as fast as it goes")
        with self.lock:
            self.speed = speed
            self._rebase()

    def set_paused(self, paused: bool) -> None:
        with self.lock:
            self.paused = paused
            self._rebase()

    # ------------------------------------------------------------ what a person does
    def press(self, controller: str, button: int, down: bool) -> None:
        """Button `button` of the box on `controller` down or up, at the next whole ms; a
        button the box cannot press there (a wire drives that input) is refused."""
        if controller not in self.sim.machines or button not in BUTTONS:
            raise ValueError(f"no button {button!r} on a controller {controller!r}")
        why = refusal(self.sim.rig, controller, button)
        if why is not None:
            raise ValueError(why)
        with self.lock:
            at = math.floor(self.sim.now_ms()) + 1
            self.sim.machines[controller].schedule_input(at, button, down)
            self.changes.append(Change(at - self.power_ms, controller, button, down))

    def power_cycle(self) -> None:
        """Power-on of the whole rig now: macro 0 runs again; held buttons stay held, and
        the scenario starts here (with them pressed at 0 ms)."""
        with self.lock:
            self.sim.run_until(math.ceil(self.sim.now_ms()))
            self.power_ms = round(self.sim.now_ms())
            held = [Change(0, name, n, True) for name, m in self.sim.machines.items()
                    for n in BUTTONS if m.input(n) and self.pressable[name][n - 1]]
            self.changes = held
            self.hazard.clear()
            self.sim.power_on()
            self._note("power cycle: macro 0 runs again")

    def reload(self, sim: Simulation) -> None:
        """The file changed on disk and checks clean: `sim` (its new simulation) powers on
        in place of the old one, with the buttons held now still held."""
        with self.lock:
            held: dict[str, tuple[int, ...]] = {}
            for name, m in self.sim.machines.items():
                if name in sim.machines:
                    inputs = tuple(n for n in BUTTONS if m.input(n) and self.pressable[name][n - 1]
                                   and refusal(sim.rig, name, n) is None)
                    if inputs:
                        held[name] = inputs
            self.problems = []
            self._start(sim, held)
            self._note(f"{self.file} changed: reloaded, macro 0 runs")

    def refuse(self, problems: list[str]) -> None:
        """The file changed on disk and has `problems` (its errors, as check words them):
        they are shown, and the last good program keeps running."""
        with self.lock:
            if problems != self.problems:
                self._note(f"{self.file} changed: not reloaded, {len(problems)} problem"
                           f"{'s' if len(problems) != 1 else ''}; the last good program "
                           "keeps running")
            self.problems = problems

    def _note(self, text: str) -> None:
        self.log.add((f"{render.clock(self.sim.now_ms() * 1000)}  {text}", "note"))

    def set_joystick(self, controller: str, deflection: float) -> None:
        """The joystick branch that goes to `controller` held at `deflection` (-1..1)."""
        if controller not in self.sim.rig.joystick.values():
            raise ValueError(f"no joystick branch goes to {controller!r}")
        if not -1 <= deflection <= 1:
            raise ValueError(f"deflection {deflection!r}: from -1 to 1")
        with self.lock:
            self.sim.machines[controller].set_joystick(deflection)

    # ------------------------------------------------------------ what the page shows
    def state(self, seen: tuple[int, int] = (0, 0)) -> tuple[dict, tuple[int, int]]:
        """The state the page draws, with the timeline entries and path points after the
        `seen` ones (counted from the start of the session); and the counts seen then."""
        with self.lock:
            log, seen_log = self.log.since(seen[0])
            path, seen_path = self.path.since(seen[1])
            sticks = set(self.sim.rig.joystick.values())
            return {"t_ms": round(self.sim.now_ms(), 3), "paused": self.paused,
                    "speed": self.speed, "file": self.file,
                    "controllers": [self._controller(name, m, name in sticks)
                                    for name, m in self.sim.machines.items()],
                    "wires": [{"from": str(w.source), "to": str(w.target),
                               "high": self.sim.machines[w.source.controller].outputs_pattern()
                               >> (w.source.number - 1) & 1 == 1} for w in self.sim.rig.wires],
                    "path_axes": self.path_axes, "path": path,
                    "log": [list(entry) for entry in log],
                    "problems": self.problems}, (seen_log, seen_path)

    def _controller(self, name: str, m, stick: bool) -> dict:
        low, high = m.axis.soft_range()
        lines = m.input_lines()
        return {"name": name, "model": m.model, "unit": unit(m.model),
                "leds": [m.outputs_pattern() >> i & 1 == 1 for i in range(4)],
                "buttons": [bool(lines[n]) for n in BUTTONS],
                "pressable": self.pressable[name],
                "position": m.position(), "target": m.target,
                "macro": m.label or "direct mode", "soft_limits": [low, high],
                "joystick": (m.deflection or 0.0) if stick else None,
                "hazard": self.hazard.get(name), **_stage(m)}

    # ------------------------------------------------------------ the session as a test
    def scenario(self) -> str:
        """The presses since the last power-on as a `sim --scenario` file, expecting what
        each controller shows now: its position, LEDs and macro (docs/simulator.md)."""
        from mercmac.sim.scenario import text

        with self.lock:
            self.sim.run_until(math.ceil(self.sim.now_ms()))  # the state at a whole ms
            end = round(self.sim.now_ms())
            steps = [(c.at_ms, c.controller, c.button, c.down) for c in self.changes
                     if c.at_ms + self.power_ms <= end]
            expect = {name: (m.position(), m.outputs_pattern(), m.macro)
                      for name, m in self.sim.machines.items()}
            lone = self.sim.rig.lone
        return text(self.file, end - self.power_ms, steps, expect, lone=lone)


def _stage(m) -> dict:
    """The stage's switches where the axis counts now (DH shifts them, MS176E §4.4.2): the
    reference switch's edge (§4.3) and whether a reference move found it, the hard limit
    switches as the bench has them (`--hard-limits`; their span is the travel), and the one
    pressed now."""
    axis, now = m.axis, m.clock.now
    switches = axis.switches()
    pressed = axis.limit_switch(now)
    return {"reference": round(axis.options.reference_at + axis.shift),
            "referenced": axis.referenced,
            "limit_switches": None if switches is None else [round(s) for s in switches],
            "at_limit": None if pressed is None else str(pressed)}
