"""One scripted simulation: power on, press buttons on schedule, run to a time
(docs/simulator.md)."""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import IO, Iterable, Sequence

from mercmac.compiler.program import Program
from mercmac.errors import signal_of
from mercmac.timespec import Press
from mercmac.vm.machine import Listener, Machine
from mercmac.vm.models import Options
from mercmac.sim.record import Recorder

DEFAULT_UNTIL_MS = 10_000  # --until defaults to 10s (docs/cli.md, "Commands")


@dataclass(slots=True)
class Run:
    """What a simulation produced: the recorder, and the machine as it stands at the end."""

    machine: Machine
    record: Recorder
    until_ms: int
    vcd_cut_at: int | None = None  # us: where the VCD stopped at its size limit
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


def simulate(program: Program, *, presses: Iterable[Press] = (), until_ms: int = DEFAULT_UNTIL_MS,
             model: str | None = None, cycle_ms: float = 1.0, options: Options | None = None,
             trace: bool = False, vcd: IO[str] | None = None,
             vcd_limit: int | None = None, watch=None, progress=None) -> Run:
    """Power on at t = 0 (macro 0 starts, docs/simulator.md, "Power-on") and run to until_ms.

    A VCD stops (a valid file) before it would pass `vcd_limit` bytes; the run goes on.
    `watch` is one more listener (a plot) with `on_event`; it hears every event first.
    `progress` (`update(now_ms)`, `close()`) hears the simulated time reached as the run goes.
    Ctrl-C (KeyboardInterrupt, or Signalled: SIGTERM, SIGHUP) ends the run where it is: the
    Run's `interrupted` is the signal.
    """
    dump = None
    if vcd is not None:
        from mercmac.sim.vcd import VcdObserver

        dump = VcdObserver(vcd, vcd_limit)
    listeners = [listener.on_event for listener in (watch, dump) if listener is not None]
    machine, record = machine_for(program, model=model, cycle_ms=cycle_ms, options=options,
                                  trace=trace, listeners=listeners)
    schedule(machine, presses)
    machine.power_on()
    interrupted = 0
    try:
        if progress is None:
            machine.run_until(until_ms)
        else:
            run_reporting(machine, until_ms, progress.update)
    except KeyboardInterrupt as e:
        interrupted, until_ms = signal_of(e), machine.now_ms
    finally:
        if progress is not None:
            progress.close()
    if dump is None:
        return Run(machine, record, until_ms, interrupted=interrupted)
    dump.close(round(until_ms * 1000))
    return Run(machine, record, until_ms, dump.cut_at, interrupted)


SLICE_S = 0.1  # wall time per slice of a run that reports progress


def run_reporting(machine: Machine, until_ms: float, update) -> None:
    """Run to until_ms in slices of about SLICE_S of wall time, calling update(now_ms) after
    each. The slices change what is skipped at once, not what happens (vm/skips.py)."""
    step = 1.0
    while machine.now_ms < until_ms:
        began = time.perf_counter()
        machine.run_until(min(until_ms, machine.now_ms + step))
        spent = time.perf_counter() - began
        step = step * 2 if spent < SLICE_S / 2 else max(step / 2, 1.0) if spent > SLICE_S else step
        update(machine.now_ms)
