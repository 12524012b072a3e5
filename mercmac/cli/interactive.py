"""`sim --interactive`: a live C-170.PB pushbutton box in the terminal.

Before power-on a short count-down lets keys 1-6 choose the inputs held at
power-on (what the manual's Example 4 reads to select a mode); `--hold 2`
chooses them up front and skips it, Enter cuts it short. After power-on keys
1-4 press and release the buttons (5 and 6: joystick and its button), r resets
(power-on again, like RT: the held buttons stay held), q quits and prints the
summary of the run. Simulated time follows the wall clock times the speed factor.

The keys are the box's, plugged into one controller of the simulation (a lone program's,
or the one a rig names with `box`): they press only what a person can press there (a wired
input keeps its wire's level, rig.presses), and the screen shows that controller; power-on
and the clock are the whole rig's.
"""
from __future__ import annotations

import os
import select
import sys
import time
from typing import IO

from mercmac.cli.common import UsageError
from mercmac.commands import unit
from mercmac.render import sim as render
from mercmac.render.console import write_lines
from mercmac.sim.simulate import Run, Simulation

TICK_S = 0.05  # redraw period
SLICE_MS = 100  # simulated time run between two looks at the wall clock
MAX_SPEED = 1000.0  # 1000 s of a busy loop take more than 1 s to simulate; 1e308 overflows to inf
COUNTDOWN_S = 2.0  # long enough to press a key or two before power-on, short enough to wait for
HELP = ("keys 1-4: press/release a button (5, 6: joystick, joystick button) - r: reset "
        "(power-on) - q: quit")
CLEAR = "\r\x1b[K"  # carriage return, erase to the end of the line (ECMA-48 EL)


def run(sim: Simulation, box: str, *, speed: float = 1.0, hold: tuple[int, ...] = (),
        stdin: IO | None = None, stdout: IO[str] | None = None) -> int:
    """Run the box on controller `box` until q, then print its summary; the number of
    hazards found.

    The terminal is put back as it was, whatever happens.
    """
    stdin, stdout = stdin or sys.stdin, stdout or sys.stdout
    if not 0 < speed <= MAX_SPEED:  # also refuses nan
        raise UsageError(f"--speed {speed:g}: use more than 0 and at most {MAX_SPEED:g} "
                         "(simulated seconds per wall-clock second)")
    if not stdin.isatty():
        raise UsageError("--interactive needs a terminal on standard input")
    import termios
    import tty

    fd = stdin.fileno()
    saved = termios.tcgetattr(fd)
    tty.setcbreak(fd)  # keys arrive one by one, without Enter and without echo
    box_ = _Box(sim, box)
    try:
        _loop(box_, speed, hold, fd, stdout)
    finally:
        _restore(fd, saved, stdout)
    machine, record = box_.machine, sim.records[box]
    write_lines(render.summary(Run(machine, record, round(machine.now_ms))), stdout)
    return len(record.hazards)


class _Box:
    """The C-170.PB box on one controller of the simulation: its keys press what a person can
    press there (a key of an input the box cannot press does nothing: a wire keeps its line)."""

    def __init__(self, sim: Simulation, name: str):
        from mercmac.rig.presses import refusal

        self.sim, self.machine = sim, sim.machines[name]
        self.pressable = {n for n in range(1, 7) if refusal(sim.rig, name, n) is None}

    def toggle(self, n: int) -> None:
        if n in self.pressable:
            self.machine.set_input(n, not self.machine.input(n))


def _restore(fd: int, saved: list, stdout: IO[str]) -> None:
    """The terminal's settings as they were, the cursor on a new line; nothing if the terminal
    has hung up (SIGHUP is on its way: that, not this failure, ends the run, exit 129)."""
    import termios

    try:
        termios.tcsetattr(fd, termios.TCSADRAIN, saved)
        stdout.write("\n")
        stdout.flush()
    except (termios.error, OSError):
        pass


def _loop(box: _Box, speed: float, hold: tuple[int, ...], fd: int, out: IO[str]) -> None:
    pending: list = []
    machine = box.machine
    machine.listeners.append(pending.append)
    out.write(f"{HELP}  (speed x{speed:g})\n")
    for n in hold:
        machine.set_input(n, True)
    if not hold and not _count_down(box, fd, out):
        _show(pending, machine, out)
        return
    box.sim.power_on()
    start = time.monotonic()
    while True:
        ready, _, _ = select.select([fd], [], [], TICK_S)
        _advance(box.sim, (time.monotonic() - start) * 1000 * speed, time.monotonic() + TICK_S)
        for key in os.read(fd, 64).decode(errors="ignore") if ready else "":
            if key in "qQ":
                _show(pending, machine, out)
                return
            if key in "rR":
                _show(pending, machine, out)
                out.write(CLEAR)
                write_lines([render.reset_line(machine.now_us)], out)
                box.sim.power_on()
            elif key in "123456":
                box.toggle(int(key))
        _show(pending, machine, out)


def _count_down(box: _Box, fd: int, out: IO[str]) -> bool:
    """Keys 1-6 toggle the inputs held at power-on until the count-down ends; False on q."""
    end = time.monotonic() + COUNTDOWN_S
    while (left := end - time.monotonic()) > 0:
        out.write(CLEAR + render.countdown_status(left, box.machine.input_lines()))
        out.flush()
        ready, _, _ = select.select([fd], [], [], min(TICK_S, left))
        for key in os.read(fd, 64).decode(errors="ignore") if ready else "":
            if key in "qQ":
                return False
            if key in "\r\n ":
                return True
            if key in "123456":
                box.toggle(int(key))
    return True


def _advance(sim: Simulation, t_ms: float, deadline: float) -> None:
    """Run towards t_ms, but stop at the wall-clock deadline so that keys are read on time."""
    while time.monotonic() < deadline:
        until = min(t_ms, sim.now_ms() + SLICE_MS)
        sim.run_until(until)
        if until == t_ms:
            return


def _show(pending: list, machine, out: IO[str]) -> None:
    """Print what happened since the last tick above the status line, then redraw it."""
    lines = [render.event_line(e, unit(machine.model)) for e in pending
             if isinstance(e, render.LIVE_EVENTS)]
    pending.clear()
    if lines:
        out.write(CLEAR)
        write_lines(lines, out)
    out.write(CLEAR + render.live_status(machine.now_us, machine.outputs_pattern(),
                                         machine.input_lines(), machine.position(),
                                         machine.target, machine.label or "direct mode"))
    out.flush()
