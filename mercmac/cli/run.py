"""The work of `mercmac sim`: options to a request, compile, simulate one way or another
(scripted, a scenario, the live box of cli/interactive.py), render; the library's errors
worded as the options' (exit 2)."""
from __future__ import annotations

import os
import sys
from dataclasses import dataclass

from mercmac.commands import MAX_INT32
from mercmac.cli.common import UsageError, say
from mercmac.errors import interrupt
from mercmac.outfile import drafting, writable_target
from mercmac.timespec import TimeSpecError, parse_buttons, parse_duration
from mercmac.vm.models import Options
from mercmac.sim.simulate import DEFAULT_UNTIL_MS, Run, machine_for, schedule, simulate


@dataclass(frozen=True, slots=True)
class Request:
    """The options of one `sim` invocation, as given on the command line."""

    file: str
    buttons: str = ""
    until: str | None = None
    fmt: str = "text"
    trace: bool = False
    vcd: str | None = None
    vcd_limit_mb: float = 100  # 0: no limit
    plot: str | None = None  # FILE.png|.svg|.pdf|.html
    interactive: bool = False
    speed: float = 1.0
    scenario: str | None = None
    target: str | None = None
    cycle_ms: float = 1.0
    servo_off: bool = False
    reference_at: int = 0
    hard_limits: str | None = None
    verbose: int = 0  # timeline: 0 the story, 1 with macro entries and exits, 2 everything
    fail_on_hazard: bool = False
    hold: str = ""  # --interactive: inputs held at power-on, e.g. "2" or "2+3"
    joystick: str = ""  # a rig: NAME=D@T1-T2,... (cli/run_rig.py)


def run(req: Request) -> bool:
    """Carry out a request; False when the file has errors or a scenario fails."""
    from mercmac.vm.clock import CycleError
    from mercmac.vm.models import ModelError
    from mercmac.sim.scenario import ScenarioError

    try:
        return _run(req)
    except CycleError as e:  # the core's own errors are bad options here (exit 2)
        raise UsageError(f"--cycle: {e}") from None
    except (ModelError, ScenarioError) as e:
        raise UsageError(str(e)) from None


def _run(req: Request) -> bool:
    from mercmac.rig import is_rig_path

    if is_rig_path(req.file):  # every controller of the rig on one clock
        from mercmac.cli import run_rig

        return run_rig.run(req)
    if req.joystick:
        raise UsageError("--joystick is for a rig file (*.rig.toml), whose [joystick] table "
                         "says which controller each branch drives")
    presses = _presses(req.buttons)
    if req.scenario and presses:  # two button scripts for one run: which one wins is a guess
        raise UsageError("--scenario and --buttons cannot be used together: the scenario's "
                         "[[step]] tables are its button script; add the presses there "
                         "(at = \"1s\", press = [1], then release = [1])")
    hold = _hold(req)
    if req.vcd:  # a path that cannot be written is refused before any work (exit 2)
        writable_target(req.vcd)
    if req.plot:  # and so is a plot that cannot be drawn: a bad path, no matplotlib
        if req.interactive:
            raise UsageError("--plot does not go with --interactive (a live session has no end to draw)")
        _check_plot(req.plot)
    options = Options(servo_on=not req.servo_off, reference_at=req.reference_at,
                      hard_limits=_limits(req.hard_limits))
    program = _compile(req)
    if program is None:
        return False
    common = dict(model=req.target or program.target, cycle_ms=req.cycle_ms, options=options)
    if req.interactive:
        from mercmac.cli import interactive
        from mercmac.vm.machine import Machine

        machine = Machine(program, **common)
        schedule(machine, presses)
        hazards = interactive.run(machine, speed=req.speed, hold=hold)
        return _hazards_ok(req, hazards)
    if req.scenario:
        return _scenario(req, program, presses, common)
    until = _until(req.until, None)
    result = _simulate(req, program, presses, until, common)
    _render(req, result)
    if result.interrupted:  # Ctrl-C: the timeline so far and the summary, then exit 128+N
        raise interrupt(result.interrupted)
    return _hazards_ok(req, len(result.record.hazards))


def _hazards_ok(req: Request, hazards: int) -> bool:
    """False (exit 1) under --fail-on-hazard when the run found any hazard; says so on stderr."""
    if not (req.fail_on_hazard and hazards):
        return True
    say(f"{hazards} hazard{'s' * (hazards != 1)} found (--fail-on-hazard)")
    return False


def _hold(req: Request) -> tuple[int, ...]:
    """--hold: the inputs held at power-on, only for --interactive."""
    if not req.hold:
        return ()
    if not req.interactive:
        raise UsageError("--hold is for --interactive; in a script, press at 0: "
                         f"--buttons \"{req.hold.strip()}@0-500ms\"")
    try:
        (press,) = parse_buttons(f"{req.hold}@0")
    except (TimeSpecError, ValueError):
        raise UsageError(f"--hold '{req.hold}': inputs are numbers 1-6 joined by '+', "
                         "e.g. --hold 2 or --hold 2+3") from None
    return press.inputs


def _simulate(req: Request, program, presses, until: int, common: dict) -> Run:
    watch = _watch(req)
    result = _simulate_with(req, program, presses, until,
                            dict(common, watch=watch, progress=_progress(until)))
    _plot(req, watch, until * 1000)
    return result


def _progress(until_ms: int):
    """A progress line on stderr for a long run, when stderr is a terminal."""
    if not sys.stderr.isatty():
        return None
    from mercmac.render.progress import ProgressLine

    return ProgressLine(sys.stderr, until_ms)


def _simulate_with(req: Request, program, presses, until: int, common: dict) -> Run:
    if not req.vcd:
        return simulate(program, presses=presses, until_ms=until, trace=req.trace, **common)
    # the old file stays until the new one is complete; Ctrl-C or an error leaves no temp
    limit = round(req.vcd_limit_mb * 1_000_000) if req.vcd_limit_mb else None
    with drafting(req.vcd, encoding="ascii") as vcd:
        result = simulate(program, presses=presses, until_ms=until, trace=req.trace,
                          vcd=vcd.file, vcd_limit=limit, **common)
        vcd.keep = not result.interrupted  # a dump cut by Ctrl-C does not replace the old file
    if result.vcd_cut_at is not None and not result.interrupted:
        from mercmac.render import sim as render

        render.write_vcd_cut(req.vcd, req.vcd_limit_mb, result.vcd_cut_at, sys.stderr)
    return result


def _scenario(req: Request, program, presses, common: dict) -> bool:
    from mercmac.sim import scenario

    plan = scenario.load(req.scenario)
    until = _until(req.until, plan.until_ms)
    watch = _watch(req)
    machine, record = machine_for(program, trace=req.trace, **common,
                                  listeners=[watch.on_event] if watch else [])
    schedule(machine, presses)
    try:
        checked = scenario.run(machine, plan, until)
    except scenario.ScenarioFailed:
        _plot(req, watch, round(machine.now_ms * 1000))
        _render(req, Run(machine, record, round(machine.now_ms)))
        raise
    _plot(req, watch, until * 1000)
    _render(req, Run(machine, record, until))
    if req.fmt == "text":
        from mercmac.render import sim as render

        render.write_scenario_passed(req.scenario, checked, sys.stdout)
    return _hazards_ok(req, len(record.hazards))


def _check_plot(path: str) -> None:
    """--plot refused before any simulating: a bad path or kind of file, no matplotlib."""
    from mercmac.sim import plot

    try:
        plot.check_target(path)
    except plot.PlotError as e:  # its message reads on from the option's name
        raise UsageError(f"--plot {e.message}", hint=e.hint) from None


def _watch(req: Request):
    """The plot's listener when --plot asks for one."""
    if not req.plot:
        return None
    from mercmac.sim import plot

    return plot.PlotObserver()


def _plot(req: Request, watch, end_us: int) -> None:
    if watch is not None:
        from mercmac.sim import plot

        title = f"mercmac sim {os.path.basename(req.file)}"
        plot.write(req.plot, watch.close(end_us), title)


def _render(req: Request, result: Run) -> None:
    from mercmac.render import sim as render

    if req.fmt == "json":
        sys.stdout.write(render.to_json(result) + "\n")
    else:
        render.write_text(result, sys.stdout, with_trace=req.trace, verbose=req.verbose)


def _compile(req: Request):
    """The program, or None after showing the errors (a file with errors is not simulated)."""
    from mercmac.compiler import compile_file
    from mercmac.render import report

    compiled = compile_file(req.file, target=req.target)
    if report.write_errors(compiled):
        return None
    return compiled.program


def _presses(spec: str):
    try:
        return parse_buttons(spec)
    except TimeSpecError as e:
        raise UsageError(f"--buttons: {e}") from None


def _until(text: str | None, fallback: int | None) -> int:
    if text is None:
        return DEFAULT_UNTIL_MS if fallback is None else fallback
    try:
        return parse_duration(text)
    except TimeSpecError as e:
        raise UsageError(f"--until: {e}") from None


def _limits(text: str | None) -> tuple[int, int] | None:
    """'-200000,200000' -> (-200000, 200000)."""
    if text is None:
        return None
    try:
        low, high = (int(p) for p in text.split(","))
    except ValueError:
        raise UsageError(f"--hard-limits '{text}': write NEG,POS, e.g. -200000,200000") from None
    if not low < high:
        raise UsageError(f"--hard-limits '{text}': the negative limit must be below the positive one")
    if not -MAX_INT32 <= low < high <= MAX_INT32:  # positions are 32-bit on the controller
        raise UsageError(f"--hard-limits: positions are {-MAX_INT32} to {MAX_INT32}")
    return low, high
