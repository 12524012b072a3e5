"""The work of `mercmac sim RIG` (docs/rigs.md): the rig file and its programs in,
every controller on one clock (sim/rig.py), the merged timeline or JSON out.

`--buttons NAME:B@T1-T2` presses button B of the box, which must be plugged into controller
NAME (without NAME: the rig's box controller), or the joystick's input 5 or 6 of a controller
a branch goes to, never an input a wire drives (rig.presses); `--joystick NAME=D@T1-T2` holds
the joystick branch of controller NAME (or of branch X, Y, Z) at deflection D (-1..1) from T1
to T2, then back to the middle.
"""
from __future__ import annotations

import os
import re
import sys

from mercmac.cli.common import UsageError
from mercmac.cli.run import _hazards_ok, _until  # the single controller's, alike
from mercmac.cli.run import _hold as _held_at_power_on
from mercmac.errors import interrupt
from mercmac.outfile import drafting, writable_target
from mercmac.rig.model import Rig
from mercmac.sim.rig import Hold, RigRun, RigSim
from mercmac.timespec import TimeSpecError, merge, parse_buttons, parse_duration
from mercmac.vm.models import Options

_HOLD = re.compile(r"\s*(\w+)\s*=\s*([+-]?(?:\d+\.?\d*|\.\d+))\s*@\s*([^-]+?)\s*(?:-\s*(.+?))?\s*")
_NAMED = re.compile(r"\s*(\w+)\s*:(.*)", re.DOTALL)


def run(req) -> bool:
    """Carry out a `sim` request on a rig file; False when a file has errors or, under
    --fail-on-hazard, the run found hazards."""
    _refuse_single_only(req)
    accepted = checked_rig(req.file)
    if accepted is None:
        return False
    rig = accepted.rig
    script = buttons(rig, req.buttons), joystick(rig, req.joystick)
    if req.scenario and script[0]:  # two button scripts for one run: which one wins is a guess
        raise UsageError("--scenario and --buttons cannot be used together: the scenario's "
                         "[[step]] tables are its button script (controller = \"x\" says "
                         "whose)")
    programs = {name: c.program for name, c in accepted.programs.items()}
    until = _until(req.until, None)
    options = Options(servo_on=not req.servo_off, reference_at=req.reference_at)
    if req.interactive:
        return _interactive(req, rig, programs, script, options)
    result = _simulate(req, rig, programs, script, until, options)
    if not req.scenario:  # a scenario's run showed itself, passed or failed
        _render(req, result)
    if result.interrupted:
        raise interrupt(result.interrupted)
    return _hazards_ok(req, result.hazards)


def _refuse_single_only(req) -> None:
    """Options of one controller's run that a rig does not take (yet): said, not ignored."""
    for given, option in ((req.target, "--target"), (req.hard_limits, "--hard-limits")):
        if given:
            raise UsageError(f"{option} is not available for a rig file; each controller's "
                             "model comes from the rig file")


def checked_rig(path: str):
    """The rig and its programs (rig.accept.Accepted) when `check` finds no errors in it;
    else None after showing what `check` finds (exit 1, as `sim FILE` with errors); a
    program that cannot be read is shown alike, then raised (exit 2, as for any file)."""
    from mercmac.render.report import write_findings
    from mercmac.rig.accept import ProgramsUnread, RigRefused, accept

    try:
        return accept(path)
    except RigRefused as e:
        write_findings(e.findings)
        if isinstance(e, ProgramsUnread):
            raise
        return None


def buttons(rig: Rig, spec: str) -> dict:
    """`--buttons` on a rig: 'x:1@0-300ms,y:5@1s' by controller; a press without a name
    goes to the box's controller. Only what a person can press (rig.presses): the box's
    connected buttons on its controller, on inputs no wire drives, and the joystick's inputs
    on a controller a branch goes to."""
    found: dict[str, list] = {}
    for item in filter(None, (p.strip() for p in spec.split(","))):
        named = _NAMED.fullmatch(item)
        name, press = (named.group(1), named.group(2)) if named else (_box(rig, item), item)
        _known(rig, name, "--buttons", item)
        try:
            pressed = parse_buttons(press)
        except TimeSpecError as e:
            raise UsageError(f"--buttons: {e}") from None
        inputs = {n for p in pressed for n in p.inputs}
        _refuse_unpressable(rig, name, inputs, f"--buttons '{item}'")
        found.setdefault(name, []).extend(pressed)
    return {name: merge(presses) for name, presses in found.items()}


def _refuse_unpressable(rig: Rig, name: str, inputs, said: str) -> None:
    """UsageError, naming the box's controller or the wire, for an input no one can press."""
    from mercmac.rig.presses import refusal

    for number in sorted(inputs):
        why = refusal(rig, name, number)
        if why:
            raise UsageError(f"{said}: {why}")


def _box(rig: Rig, item: str) -> str:
    """The controller a press without a name goes to: the box's."""
    from mercmac.rig.presses import refusal

    if rig.box is None:
        raise UsageError(f"--buttons '{item}': {refusal(rig, '', 1)}",
                         hint="the joystick's inputs 5 and 6 take their controller's name: "
                              "NAME:5@T1-T2")
    return rig.box


def _known(rig: Rig, name: str, option: str, item: str) -> None:
    if not any(c.name == name for c in rig.controllers):
        names = ", ".join(c.name for c in rig.controllers)
        raise UsageError(f"{option} '{item}': the rig has no controller '{name}' ({names})")


def joystick(rig: Rig, spec: str) -> list[Hold]:
    """`--joystick x=+0.5@1s-3s,Y=-1@4s`: a controller (or a branch X/Y/Z of the rig's
    [joystick]) held at a deflection -1..1 from T1 to T2 (or on from T1)."""
    return [_deflection(rig, item) for item in filter(None, (p.strip() for p in spec.split(",")))]


def _deflection(rig: Rig, item: str) -> Hold:
    m = _HOLD.fullmatch(item)
    if m is None:
        raise UsageError(f"--joystick '{item}': write NAME=D@T1-T2 or NAME=D@T1, "
                         "e.g. x=+0.5@1s-3s (D from -1 to 1)")
    who, value, start, end = m.groups()
    name = rig.joystick.get(who, who)  # a branch names its controller
    _known(rig, name, "--joystick", item)
    if name not in rig.joystick.values():
        raise UsageError(f"--joystick '{item}': no joystick branch goes to {name}; the rig's "
                         "[joystick] table says which branch (X, Y, Z) goes where")
    deflection = float(value)
    if not -1 <= deflection <= 1:
        raise UsageError(f"--joystick '{item}': the deflection is from -1 to 1")
    try:
        t0, t1 = parse_duration(start), parse_duration(end) if end else None
    except TimeSpecError as e:
        raise UsageError(f"--joystick '{item}': {e}") from None
    if t1 is not None and t1 < t0:
        raise UsageError(f"--joystick '{item}': the end is before the start")
    return Hold(name, deflection, t0, t1)


def _simulate(req, rig: Rig, programs: dict, script: tuple, until: int,
              options: Options) -> RigRun:
    """Run the rig with the plot's and the VCD's listeners when asked for; the plot and the
    dump are written once the run is over (a failed scenario's too, up to where it failed)."""
    watched = _watches(req, rig)
    if req.vcd:
        return _with_vcd(req, rig, programs, script, until, options, watched)
    sim = _rig_sim(req, rig, programs, script, options, _joined(watched))
    try:
        return _play(req, sim, until)
    finally:
        _plot(req, rig, watched, sim)


def _interactive(req, rig: Rig, programs: dict, script: tuple, options: Options) -> bool:
    """The live box (cli/interactive.py) on the rig's box controller, every controller on
    the clock; --hold holds its inputs at power-on."""
    from mercmac.cli import interactive

    if rig.box is None:
        raise UsageError("--interactive needs the rig's box: say which controller holds the "
                         "C-170.PB with box = \"NAME\" in the rig file")
    held = _held_at_power_on(req)
    _refuse_unpressable(rig, rig.box, held, f"--hold '{req.hold}'")
    sim = _rig_sim(req, rig, programs, script, options, {})
    hazards = interactive.run(_Box(sim, rig), speed=req.speed, hold=held)
    return _hazards_ok(req, hazards)


class _Box:
    """The rig as the live box drives one machine (cli/interactive.py): the box's
    controller, whose inputs the keys press and whose events the screen shows, with power-on
    and the clock those of the whole rig. A key of an input the box cannot press (a wired
    one, a button not connected, rig.presses) does nothing: the wire keeps its line."""

    def __init__(self, sim: RigSim, rig: Rig):
        from mercmac.rig.presses import refusal

        self._sim, self._machine = sim, sim.machines[rig.box]
        self._pressable = {n for n in range(1, 7) if refusal(rig, rig.box, n) is None}

    def __getattr__(self, name: str):
        return getattr(self._machine, name)

    def set_input(self, n: int, on: bool) -> None:
        if n in self._pressable:
            self._machine.set_input(n, on)

    def power_on(self) -> None:
        self._sim.power_on()

    def run_until(self, t_ms: float) -> None:
        self._sim.run_until(t_ms)


def _rig_sim(req, rig: Rig, programs: dict, script: tuple, options: Options,
             listeners: dict) -> RigSim:
    presses, holds = script
    sim = RigSim(rig, programs, cycle_ms=req.cycle_ms, options=options, trace=req.trace,
                 listeners=listeners)
    for name, pressed in presses.items():
        sim.press(name, pressed)
    for hold in holds:
        sim.hold(hold)
    return sim


def _play(req, sim: RigSim, until: int) -> RigRun:
    """The plain run to --until, or the scenario's (its steps and expectations)."""
    if not req.scenario:
        return sim.run(until)
    from mercmac.sim import rig_scenario, scenario

    plan = scenario.load(req.scenario)
    until = _until(req.until, plan.until_ms)
    try:
        checked = rig_scenario.run(sim, plan, until)
    except scenario.ScenarioFailed:
        _render(req, sim.result(round(sim.now_ms())))
        raise
    result = sim.result(until)
    _render(req, result)
    if req.fmt == "text":
        from mercmac.render import sim as render

        render.write_scenario_passed(req.scenario, checked, sys.stdout)
    return result


def _plot(req, rig: Rig, watched: dict, sim: RigSim) -> None:
    if watched:
        from mercmac.sim import rig_plot

        trace = rig_plot.trace_of(rig, watched, round(sim.now_ms() * 1000))
        rig_plot.write(req.plot, trace, f"mercmac sim {os.path.basename(req.file)}")


def _watches(req, rig: Rig) -> dict:
    """The plot's listeners (sim/rig_plot.py) when --plot asks for one, checked first."""
    if not req.plot:
        return {}
    from mercmac.sim import plot, rig_plot

    try:
        rig_plot.check_target(req.plot)
    except plot.PlotError as e:  # its message reads on from the option's name
        raise UsageError(f"--plot {e.message}", hint=e.hint) from None
    return rig_plot.watches(rig)


def _joined(watched: dict, *more: dict) -> dict[str, list]:
    """Every controller's listeners, the plot's first."""
    joined: dict[str, list] = {name: [w.on_event] for name, w in watched.items()}
    for extra in more:
        for name, listeners in extra.items():
            joined.setdefault(name, []).extend(listeners)
    return joined


def _with_vcd(req, rig: Rig, programs: dict, script: tuple, until: int, options: Options,
              watched: dict) -> RigRun:
    from mercmac.render import sim as render
    from mercmac.sim.rig_vcd import RigVcd

    writable_target(req.vcd)
    limit = round(req.vcd_limit_mb * 1_000_000) if req.vcd_limit_mb else None
    with drafting(req.vcd, encoding="ascii") as vcd:
        dump = RigVcd(vcd.file, [c.name for c in rig.controllers], limit)
        sim = _rig_sim(req, rig, programs, script, options, _joined(watched, dump.listeners()))
        try:
            result = _play(req, sim, until)
        finally:
            dump.close(round(sim.now_ms() * 1000))
            _plot(req, rig, watched, sim)
        vcd.keep = not result.interrupted  # a dump cut by Ctrl-C does not replace the old one
    if dump.cut_at is not None and not result.interrupted:
        render.write_vcd_cut(req.vcd, req.vcd_limit_mb, dump.cut_at, sys.stderr)
    return result


def _render(req, result: RigRun) -> None:
    from mercmac.render import rig as render

    if req.fmt == "json":
        sys.stdout.write(render.to_json(result) + "\n")
    else:
        render.write_text(result, sys.stdout, verbose=req.verbose, with_trace=req.trace)
