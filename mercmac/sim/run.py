"""What `mercmac sim` does, as a library: compile, simulate one way or another, render."""
from __future__ import annotations

import sys
from dataclasses import dataclass

from mercmac.commands import MAX_INT32
from mercmac.errors import UsageError
from mercmac.outfile import replacing, writable_target
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
    interactive: bool = False
    speed: float = 1.0
    scenario: str | None = None
    target: str | None = None
    cycle_ms: float = 1.0
    servo_off: bool = False
    reference_at: int = 0
    hard_limits: str | None = None


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
    presses = _presses(req.buttons)
    if req.vcd:  # a path that cannot be written is refused before any work (exit 2)
        writable_target(req.vcd)
    options = Options(servo_on=not req.servo_off, reference_at=req.reference_at,
                      hard_limits=_limits(req.hard_limits))
    program = _compile(req)
    if program is None:
        return False
    common = dict(model=req.target or program.target, cycle_ms=req.cycle_ms, options=options)
    if req.interactive:
        from mercmac.sim import interactive
        from mercmac.vm.machine import Machine

        machine = Machine(program, **common)
        schedule(machine, presses)
        return interactive.run(machine, speed=req.speed) == 0
    if req.scenario:
        return _scenario(req, program, presses, common)
    until = _until(req.until, None)
    result = _simulate(req, program, presses, until, common)
    _render(req, result)
    return True


def _simulate(req: Request, program, presses, until: int, common: dict) -> Run:
    if not req.vcd:
        return simulate(program, presses=presses, until_ms=until, trace=req.trace, **common)
    # the old file stays until the new one is complete; Ctrl-C or an error leaves no temp
    limit = round(req.vcd_limit_mb * 1_000_000) if req.vcd_limit_mb else None
    with replacing(req.vcd, encoding="ascii") as vcd:
        result = simulate(program, presses=presses, until_ms=until, trace=req.trace,
                          vcd=vcd, vcd_limit=limit, **common)
    if result.vcd_cut_at is not None:
        from mercmac.render import sim as render

        render.write_vcd_cut(req.vcd, req.vcd_limit_mb, result.vcd_cut_at, sys.stderr)
    return result


def _scenario(req: Request, program, presses, common: dict) -> bool:
    from mercmac.sim import scenario

    plan = scenario.load(req.scenario)
    until = _until(req.until, plan.until_ms)
    machine, record = machine_for(program, trace=req.trace, **common)
    schedule(machine, presses)
    try:
        checked = scenario.run(machine, plan, until)
    except scenario.ScenarioFailed:
        _render(req, Run(machine, record, round(machine.now_ms)))
        raise
    _render(req, Run(machine, record, until))
    if req.fmt == "text":
        from mercmac.render import sim as render

        render.write_scenario_passed(req.scenario, checked, sys.stdout)
    return True


def _render(req: Request, result: Run) -> None:
    from mercmac.render import sim as render

    if req.fmt == "json":
        sys.stdout.write(render.to_json(result) + "\n")
    else:
        render.write_text(result, sys.stdout, with_trace=req.trace)


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
