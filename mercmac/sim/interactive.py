"""`sim --interactive`: a live C-170.PB pushbutton box in the terminal (issue 3).

Keys 1-4 press and release the buttons (5 and 6: joystick and its button),
q quits. Simulated time follows the wall clock times the speed factor.
"""
from __future__ import annotations

import os
import select
import sys
import time
from typing import IO

from mercmac.errors import UsageError
from mercmac.render import sim as render
from mercmac.render.console import write_lines
from mercmac.vm import events as ev
from mercmac.vm.machine import Machine

TICK_S = 0.05  # redraw period
SLICE_MS = 100  # simulated time run between two looks at the wall clock
MAX_SPEED = 1000.0  # 1000 s of a busy loop take more than 1 s to simulate; 1e308 overflows to inf
HELP = "keys 1-4: press/release a button (5, 6: joystick, joystick button) - q: quit"
CLEAR = "\r\x1b[K"  # carriage return, erase to the end of the line (ECMA-48 EL)
SHOWN = (ev.InputChanged, ev.OutputsChanged, ev.Reported, ev.HazardFound, ev.MoveStarted,
         ev.MoveEnded, ev.HomeDefined, ev.ProgramEnded)


def run(machine: Machine, *, speed: float = 1.0, stdin: IO | None = None,
        stdout: IO[str] | None = None) -> int:
    """Run the box until q; the terminal is put back as it was, whatever happens."""
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
    try:
        return _loop(machine, speed, fd, stdout)
    finally:
        termios.tcsetattr(fd, termios.TCSADRAIN, saved)
        stdout.write("\n")
        stdout.flush()


def _loop(machine: Machine, speed: float, fd: int, out: IO[str]) -> int:
    pending: list = []
    machine.on_event = pending.append
    out.write(f"{HELP}  (speed x{speed:g})\n")
    machine.power_on()
    start = time.monotonic()
    while True:
        ready, _, _ = select.select([fd], [], [], TICK_S)
        _advance(machine, (time.monotonic() - start) * 1000 * speed, time.monotonic() + TICK_S)
        for key in os.read(fd, 64).decode(errors="ignore") if ready else "":
            if key in "qQ":
                _show(pending, machine, out)
                return 0
            if key in "123456":
                n = int(key)
                machine.set_input(n, not machine.input(n))
        _show(pending, machine, out)


def _advance(machine: Machine, t_ms: float, deadline: float) -> None:
    """Run towards t_ms, but stop at the wall-clock deadline so that keys are read on time."""
    while time.monotonic() < deadline:
        until = min(t_ms, machine.now_ms + SLICE_MS)
        machine.run_until(until)
        if until == t_ms:
            return


def _show(pending: list, machine: Machine, out: IO[str]) -> None:
    """Print what happened since the last tick above the status line, then redraw it."""
    lines = [render.event_line(e) for e in pending if isinstance(e, SHOWN)]
    pending.clear()
    if lines:
        out.write(CLEAR)
        write_lines(lines, out)
    out.write(CLEAR + render.live_status(machine.now_us, machine.outputs_pattern(),
                                         machine.input_lines(), machine.position(),
                                         machine.target, machine.label or "direct mode"))
    out.flush()
