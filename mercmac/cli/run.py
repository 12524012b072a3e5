"""The work of `mercmac sim`: options to a request, open the program or the rig (a lone
program is a rig of one), simulate one way or another (scripted, a scenario, the live box of
cli/interactive.py), render; the library's errors worded as the options' (exit 2).

On a rig (docs/rigs.md), `--buttons NAME:B@T1-T2` presses button B of the box, which must be
plugged into controller NAME (without NAME: the rig's box controller), or the joystick's
input 5 or 6 of a controller a branch goes to, never an input a wire drives (rig.presses);
`--joystick NAME=D@T1-T2` holds the joystick branch of controller NAME (or of branch X, Y,
Z) at deflection D (-1..1) from T1 to T2, then back to the middle.
"""
from __future__ import annotations

import os
import re
import sys
import threading
from contextlib import contextmanager
from dataclasses import dataclass, replace

from mercmac.commands import MAX_INT32
from mercmac.cli.common import UsageError, opened, say
from mercmac.errors import interrupt
from mercmac.outfile import drafting, writable_target
from mercmac.rig.model import Rig
from mercmac.timespec import TimeSpecError, merge, parse_buttons, parse_duration
from mercmac.vm.models import Options

_HOLD = re.compile(r"\s*(\w+)\s*=\s*([+-]?(?:\d+\.?\d*|\.\d+))\s*@\s*([^-]+?)\s*(?:-\s*(.+?))?\s*")
_NAMED = re.compile(r"\s*(\w+)\s*:(.*)", re.DOTALL)


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
    web: bool = False  # the box in the browser (mercmac.web)
    port: int = 0  # --web: 0, a free one
    open_page: bool = True  # --web: open the default browser on the page
    stdin_stops: bool = False  # --web: stop when standard input ends (an editor's pipe)
    joystick: str = ""  # a rig: NAME=D@T1-T2,...
    allow_hazard: tuple[str, ...] = ()  # hazard rules accepted for the run


@dataclass(frozen=True, slots=True)
class Script:
    """What a person does in a scripted run: presses by controller (a lone program's, which
    has no names, in `lone`), joystick holds, inputs held at power-on (--interactive)."""

    presses: dict
    holds: list
    held: tuple[int, ...]
    lone: list

    def by_name(self, rig: Rig) -> dict:
        """The presses by controller of `rig` (a lone program's are its one controller's)."""
        return {rig.controllers[0].name: self.lone} if rig.lone else self.presses


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
    from mercmac.rig.open import open_rig

    rig_file = None
    if is_rig_path(req.file):  # its controllers' names are needed to read the script
        _refuse_single_only(req)
        rig_file = open_rig(req.file)
        if rig_file.rig is None:  # the rig file itself has errors: shown as `check` does
            opened(rig_file.accepted)
            return False
    script = _script(req, rig_file.rig if rig_file else None)
    if req.vcd:  # a path that cannot be written is refused before any work (exit 2)
        writable_target(req.vcd)
    if req.plot:  # and so is a plot that cannot be drawn: a bad path, no matplotlib
        if req.interactive:
            raise UsageError("--plot does not go with --interactive (a live session has no end to draw)")
        _check_plot(req.plot)
    options = Options(servo_on=not req.servo_off, reference_at=req.reference_at,
                      hard_limits=_limits(req.hard_limits), accepted=_allowed(req.allow_hazard))
    accepted = opened(rig_file.accepted if rig_file else _lone(req))
    if accepted is None:
        return False
    rig = accepted.rig
    programs = {name: c.program for name, c in accepted.programs.items()}
    if req.web:  # first: it refuses the options of the other ways to run
        return _web(req, rig, programs, script, options, _read_from(accepted.findings, req))
    for given, option in ((req.port, "--port"), (not req.open_page, "--no-open"),
                          (req.stdin_stops, "--stop-when-stdin-closes")):
        if given:
            raise UsageError(f"{option} is for --web")
    if req.interactive:
        return _interactive(req, rig, programs, script, options)
    if req.scenario:
        return _scenario(req, rig, programs, script, options)
    until = _until(req.until, None)
    result = _simulate(req, rig, programs, script, options, until)
    _render(req, result)
    if result.interrupted:  # Ctrl-C: the timeline so far and the summary, then exit 128+N
        raise interrupt(result.interrupted)
    return _hazards_ok(req, result.hazards)


def _allowed(keys: tuple[str, ...]) -> frozenset[str]:
    """--allow-hazard: the hazard rules named (mercmac/hazards.py); a name that is no hazard rule
    is a usage error with the nearest."""
    from mercmac.hazards import accepted_rules

    try:
        return accepted_rules(keys, "--allow-hazard")
    except ValueError as e:
        raise UsageError(str(e)) from None


def _lone(req: Request):
    """The file as a rig of one, opened when asked (rig.open.open_program)."""
    from mercmac.rig.open import open_program

    return lambda: open_program(req.file, target=req.target)


def _refuse_single_only(req: Request) -> None:
    """Options of one controller's run that a rig does not take (yet): said, not ignored."""
    for given, option in ((req.target, "--target"), (req.hard_limits, "--hard-limits")):
        if given:
            raise UsageError(f"{option} is not available for a rig file; each controller's "
                             "model comes from the rig file")


def _script(req: Request, rig: Rig | None) -> Script:
    """The presses, the joystick and the inputs held at power-on, as the options give them;
    on a rig (`rig`), by controller and only what a person can press there."""
    presses = _presses(req.buttons) if rig is None else buttons(rig, req.buttons)
    # a lone program is a rig of one with the joystick on it (branch X; docs/rigs.md)
    holds = joystick(rig or Rig.of_program(req.file, req.target), req.joystick) \
        if req.joystick else []
    if req.scenario and presses:  # two button scripts for one run: which one wins is a guess
        where = ("; add the presses there (at = \"1s\", press = [1], then release = [1])"
                 if rig is None else " (controller = \"x\" says whose)")
        raise UsageError("--scenario and --buttons cannot be used together: the scenario's "
                         f"[[step]] tables are its button script{where}")
    held = _hold(req)
    if rig is not None and held:
        _refuse_unpressable(rig, _box_of(rig), held, f"--hold '{req.hold}'")
    if rig is None:
        return Script({}, holds, held, presses)
    return Script(presses, holds, held, [])


def _hazards_ok(req: Request, hazards: int) -> bool:
    """False (exit 1) under --fail-on-hazard when the run found any hazard; says so on stderr."""
    if not (req.fail_on_hazard and hazards):
        return True
    say(f"{hazards} hazard{'s' * (hazards != 1)} found (--fail-on-hazard)")
    return False


def _hold(req: Request) -> tuple[int, ...]:
    """--hold: the inputs held at power-on, only for a live box (--interactive, --web)."""
    if not req.hold:
        return ()
    if not (req.interactive or req.web):
        raise UsageError("--hold is for --interactive and --web; in a script, press at 0: "
                         f"--buttons \"{req.hold.strip()}@0-500ms\"")
    try:
        (press,) = parse_buttons(f"{req.hold}@0")
    except (TimeSpecError, ValueError):
        raise UsageError(f"--hold '{req.hold}': inputs are numbers 1-6 joined by '+', "
                         "e.g. --hold 2 or --hold 2+3") from None
    return press.inputs


# -- the simulation, its views and its files -------------------------------------------------

def _simulation(req: Request, rig: Rig, programs: dict, script: Script, options: Options,
                listeners: dict, fast_forward: str = "all"):
    from mercmac.sim.simulate import Simulation

    sim = Simulation(rig, programs, cycle_ms=req.cycle_ms, options=options, trace=req.trace,
                     listeners=listeners, fast_forward=fast_forward)
    for name, pressed in script.by_name(rig).items():
        sim.press(name, pressed)
    for hold in script.holds:
        sim.hold(hold)
    return sim


def _simulate(req: Request, rig: Rig, programs: dict, script: Script, options: Options,
              until: int):
    """The plain run to --until, with the plot's and the VCD's listeners when asked for,
    and a progress line on a terminal; the plot and the dump are written once it is over."""
    with _views(req, rig) as views:
        sim = _simulation(req, rig, programs, script, options, views.listeners())
        result = sim.run(until, _progress(until))
        views.close(result)
    return result


def _scenario(req: Request, rig: Rig, programs: dict, script: Script,
              options: Options) -> bool:
    from mercmac.sim import scenario

    plan = scenario.load(req.scenario)
    options = replace(options, accepted=options.accepted | plan.accepted)
    until = _until(req.until, plan.until_ms)
    with _views(req, rig) as views:
        sim = _simulation(req, rig, programs, script, options, views.listeners())
        try:
            checked = scenario.run(sim, plan, until)
        except scenario.ScenarioFailed:
            failed = sim.result(round(sim.now_ms()))
            views.close(failed)
            _render(req, failed)
            raise
        result = sim.result(until)
        views.close(result)
    _render(req, result)
    if req.fmt == "text":
        from mercmac.render import sim as render

        render.write_scenario_passed(req.scenario, checked, sys.stdout)
    return _hazards_ok(req, result.hazards)


class _Views:
    """The plot's and the VCD's listeners of a run, as the options ask for them."""

    def __init__(self, req: Request, rig: Rig):
        self.req, self.rig = req, rig
        self.watched = {}
        self.dump = self.draft = None
        if req.plot:
            from mercmac.sim import plot

            self.watched = plot.watches(rig)

    def listeners(self) -> dict[str, list]:
        """Every controller's listeners: the plot's first, then the dump's."""
        joined: dict[str, list] = {name: [w.on_event] for name, w in self.watched.items()}
        for name, listeners in (self.dump.listeners() if self.dump else {}).items():
            joined.setdefault(name, []).extend(listeners)
        return joined

    def close(self, result) -> None:
        """The run is over, or stopped at `result.until_ms`: the dump and the plot end there."""
        end = round(result.until_ms * 1000)
        if self.dump is not None:
            self.dump.close(end)
            result.vcd_cut_at = self.dump.cut_at
            self.draft.keep = not result.interrupted  # a dump cut short keeps the old file
        if self.watched:
            from mercmac.sim import plot

            plot.write_run(self.req.plot, self.rig, self.watched, end,
                           f"mercmac sim {os.path.basename(self.req.file)}")


@contextmanager
def _views(req: Request, rig: Rig):
    """The views of a run; the VCD replaces the old file only when the run went through (an
    error or Ctrl-C leaves the old one and no temp), and says where its size limit cut it."""
    views = _Views(req, rig)
    if not req.vcd:
        yield views
        return
    from mercmac.sim.vcd import Dump

    limit = round(req.vcd_limit_mb * 1_000_000) if req.vcd_limit_mb else None
    with drafting(req.vcd, encoding="ascii") as draft:
        views.draft = draft
        views.dump = Dump(draft.file, [c.name for c in rig.controllers], limit)
        yield views
    if views.dump.cut_at is not None and draft.keep:
        from mercmac.render import sim as render

        render.write_vcd_cut(req.vcd, req.vcd_limit_mb, views.dump.cut_at, sys.stderr)


def _progress(until_ms: int):
    """A progress line on stderr for a long run, when stderr is a terminal."""
    if not sys.stderr.isatty():
        return None
    from mercmac.render.progress import ProgressLine

    return ProgressLine(sys.stderr, until_ms)


def _interactive(req: Request, rig: Rig, programs: dict, script: Script,
                 options: Options) -> bool:
    """The live box (cli/interactive.py) on the box's controller, every controller on the
    clock; --hold holds its inputs at power-on. Passes that emit something are stepped, so
    that the screen shows every LED change (fast_forward "quiet")."""
    from mercmac.cli import interactive

    box = _box_of(rig)
    sim = _simulation(req, rig, programs, script, options, {}, fast_forward="quiet")
    hazards = interactive.run(sim, box, speed=req.speed, hold=script.held)
    return _hazards_ok(req, hazards)


def _web(req: Request, rig: Rig, programs: dict, script: Script, options: Options,
         paths: tuple[str, ...]) -> bool:
    """The box and the stage in the browser (mercmac.web) until Ctrl-C (exit 130), the
    file (`paths`: with a rig's programs) reopened when it changes on disk."""
    from mercmac.web.live import SPEEDS, Live
    from mercmac.web.server import WebServer
    from mercmac.web.watch import Watcher

    # what the page does itself, or what a session without an end has no use for: refused,
    # not ignored (a joystick held by the command line would not be in a saved scenario)
    for given, option in ((req.buttons, "--buttons"), (req.joystick, "--joystick"),
                          (req.scenario, "--scenario"), (req.until, "--until"),
                          (req.plot, "--plot"), (req.vcd, "--vcd"), (req.trace, "--trace"),
                          (req.fmt != "text", "--format"), (req.verbose, "-v"),
                          (req.fail_on_hazard, "--fail-on-hazard"),
                          (req.interactive, "--interactive")):
        if given:
            raise UsageError(f"{option} does not go with --web: the page is the box, and its "
                             "\"save as scenario\" keeps what you pressed")
    if not SPEEDS[0] <= req.speed <= SPEEDS[1]:
        raise UsageError(f"--speed {req.speed:g}: with --web, from {SPEEDS[0]:g} to "
                         f"{SPEEDS[1]:g} (the page also runs as fast as it goes)")
    sim = _simulation(req, rig, programs, script, options, {}, fast_forward="quiet")
    try:
        live = Live(sim, os.path.basename(req.file), speed=req.speed,
                    held={_box_of(rig): script.held} if script.held else {})
        server = WebServer(live, req.port)
    except OSError as e:
        raise UsageError(f"--port {req.port}: cannot listen on 127.0.0.1: "
                         f"{e.strerror or e}") from None
    watcher = Watcher(live, lambda: _reopened(req, options), paths)
    say(f"the box in the browser: {server.url}")
    say("Ctrl-C stops it" + ("" if _opened(server.url, req.open_page) else
                             "; open the address above in a browser"))
    watcher.start()
    if req.stdin_stops:
        threading.Thread(target=_stop_at_end_of_input, args=(server,), name="mercmac-stdin",
                         daemon=True).start()
    try:
        server.serve_forever()  # Ctrl-C: KeyboardInterrupt, exit 130 (cli/common.py)
    finally:
        watcher.stop()
        server.server_close()
    return True


def _stop_at_end_of_input(server) -> None:
    """--stop-when-stdin-closes: the editor that started this process on a pipe is gone
    when the pipe ends, however it went (a crash leaves no `deactivate` to stop us)."""
    # the file descriptor, not sys.stdin: a thread blocked in a buffered read holds its
    # lock, and the interpreter aborts on it when Ctrl-C ends the process meanwhile
    try:
        while os.read(0, 4096):
            pass
    except OSError:
        pass  # no standard input to read: it has ended too
    say("standard input closed: stopped")
    server.shutdown()


def _reopened(req: Request, options: Options):
    """The file opened and checked again after it changed on disk (--web follows saves):
    its new simulation, or its problems as `check` words them."""
    from mercmac.errors import MercmacError
    from mercmac.render.report import finding_texts
    from mercmac.rig import is_rig_path
    from mercmac.rig.open import RigRefused, open_rig
    from mercmac.web.watch import Loaded

    try:
        accepted = open_rig(req.file).accepted() if is_rig_path(req.file) else _lone(req)()
    except RigRefused as e:
        return Loaded(None, finding_texts(e.findings), _read_from(e.findings, req))
    except MercmacError as e:  # a file that cannot be read now (deleted, half written)
        return Loaded(None, [str(e)], ())
    programs = {name: c.program for name, c in accepted.programs.items()}
    sim = _simulation(req, accepted.rig, programs, Script({}, [], (), []), options, {},
                      fast_forward="quiet")
    return Loaded(sim, [], _read_from(accepted.findings, req))


def _read_from(findings, req: Request) -> tuple[str, ...]:
    """The files a rig or a program was read from: the file itself, a rig's programs."""
    return tuple(dict.fromkeys((req.file, *(f.compilation.source.name for f in findings))))


def _opened(url: str, wanted: bool) -> bool:
    """Whether the default browser was asked to open `url`: not where there is no screen to
    show it on (a console browser would take over this terminal)."""
    import webbrowser

    if not wanted or (sys.platform.startswith("linux") and not (
            os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))):
        return False
    try:
        return webbrowser.open(url, new=2)
    except webbrowser.Error:
        return False


def _box_of(rig: Rig) -> str:
    """The controller the box is plugged into, which --interactive and --hold press."""
    if rig.box is None:
        raise UsageError("--interactive and --hold need the rig's box: say which controller "
                         "holds the C-170.PB with box = \"NAME\" in the rig file")
    return rig.box


def _check_plot(path: str) -> None:
    """--plot refused before any simulating: a bad path or kind of file, no matplotlib."""
    from mercmac.sim import plot

    try:
        plot.check_target(path)
    except plot.PlotError as e:  # its message reads on from the option's name
        raise UsageError(f"--plot {e.message}", hint=e.hint) from None


def _render(req: Request, result) -> None:
    from mercmac.render import sim as render

    if req.fmt == "json":
        sys.stdout.write(render.to_json(result) + "\n")
    else:
        render.write_text(result, sys.stdout, with_trace=req.trace, verbose=req.verbose)


# -- the options' texts ----------------------------------------------------------------------

def _presses(spec: str):
    try:
        return parse_buttons(spec)
    except TimeSpecError as e:
        raise UsageError(f"--buttons: {e}") from None


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


def joystick(rig: Rig, spec: str) -> list:
    """`--joystick x=+0.5@1s-3s,Y=-1@4s`: a controller (or a branch X/Y/Z of the rig's
    [joystick]) held at a deflection -1..1 from T1 to T2 (or on from T1)."""
    return [_deflection(rig, item) for item in filter(None, (p.strip() for p in spec.split(",")))]


def _deflection(rig: Rig, item: str):
    from mercmac.sim.simulate import Hold

    m = _HOLD.fullmatch(item)
    if m is None:
        raise UsageError(f"--joystick '{item}': write NAME=D@T1-T2 or NAME=D@T1, "
                         "e.g. x=+0.5@1s-3s (D from -1 to 1)")
    who, value, start, end = m.groups()
    if rig.lone and who not in rig.joystick and who != rig.controllers[0].name:
        _lone_branch(item)
    name = rig.joystick.get(who, who)  # a branch names its controller
    _branch_known(rig, who, item)
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


def _branch_known(rig: Rig, who: str, item: str) -> None:
    """UsageError for a branch (X, Y, Z) the rig's [joystick] table does not connect, unless
    a controller is called so: said as a missing branch, not a missing controller."""
    from mercmac.rig.load import BRANCHES

    if who not in BRANCHES or who in rig.joystick or any(c.name == who for c in rig.controllers):
        return
    has = ", ".join(f"{b} = \"{n}\"" for b, n in rig.joystick.items())
    why = (f"the rig's [joystick] table has no branch {who} (only {has})" if has else
           f"{who} is a joystick branch, and the rig has no [joystick] table to say which "
           "controller it goes to")
    if rig.lone:
        _lone_branch(item)
    raise UsageError(f"--joystick '{item}': {why}",
                     hint=f"add {who} = \"NAME\" under [joystick] in the rig file")


def _lone_branch(item: str) -> None:
    """UsageError: a program alone is a rig of one, its joystick on branch X (docs/rigs.md)."""
    raise UsageError(f"--joystick '{item}': a program alone has one joystick, on branch X",
                     hint="write X=D@T1-T2, e.g. --joystick \"X=+0.5@1s-3s\"")


def _until(text: str | None, fallback: int | None) -> int:
    from mercmac.sim.simulate import DEFAULT_UNTIL_MS

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
