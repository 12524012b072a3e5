"""Scenarios for a rig: the steps and expectations of sim/scenario.py, each
about one controller (`controller = "y"`); a step without one presses the box's buttons (the
rig's box controller), an expectation without one is about the only controller or the box's.
A step presses only what a person can (rig.presses). All controllers run on one clock
(sim/rig.py) while the expectations are checked in time order; the first that fails ends the
run (ScenarioFailed, exit 1).
"""
from __future__ import annotations

from dataclasses import replace

from mercmac.sim import scenario as one
from mercmac.sim.rig import RigSim
from mercmac.sim.scenario import Expect, Scenario, ScenarioError, ScenarioFailed


def run(sim: RigSim, plan: Scenario, until_ms: int) -> int:
    """Power on, play the steps, check every expectation in time order; the number checked."""
    default = _default(sim, plan)
    parts = {name: _part(plan, name, default) for name in sim.machines}
    _refuse_unknown_names(sim, plan)
    _refuse_unpressable(sim, plan, default)
    for name, part in parts.items():
        one.check_names(sim.machines[name], part)
        one.schedule_steps(sim.machines[name], part)
    sim.power_on()
    expects = sorted((e for part in parts.values() for e in part.expects),
                     key=lambda e: (e.start_ms, e.number))
    for expect in expects:
        _check(sim, expect)
    sim.run_until(max(until_ms, sim.now_ms()))
    return len(expects)


def _default(sim: RigSim, plan: Scenario) -> str | None:
    """Who a step or expectation without `controller` is about: the box's controller, or
    the only one."""
    if sim.rig.box is not None:
        return sim.rig.box
    return next(iter(sim.machines)) if len(sim.machines) == 1 else None


def _part(plan: Scenario, name: str, default: str | None) -> Scenario:
    """The steps and expectations about controller `name`, each naming it."""
    steps = [s for s in plan.steps if (s.controller or default) == name]
    expects = [replace(e, controller=name) for e in plan.expects
               if (e.controller or default) == name]
    return Scenario(f"{plan.name} ({name})", plan.until_ms, steps, expects)


def _refuse_unknown_names(sim: RigSim, plan: Scenario) -> None:
    names = ", ".join(sim.machines)
    for item in [*plan.steps, *plan.expects]:
        name = item.controller
        if name is None and _default(sim, plan) is None:
            raise ScenarioError(f"{plan.name}: the rig has no box: give each step and "
                                f"expectation its controller = \"...\" ({names})")
        if name is not None and name not in sim.machines:
            raise ScenarioError(f"{plan.name}: controller = \"{name}\": the rig has no "
                                f"controller of that name ({names})")


def _refuse_unpressable(sim: RigSim, plan: Scenario, default: str | None) -> None:
    """A step presses or releases only what a person can (rig.presses): the box's connected
    buttons on its controller, on inputs no wire drives; the joystick's on its branches."""
    from mercmac.rig.presses import refusal

    for step in plan.steps:
        name = step.controller or default
        for number in sorted({*step.press, *step.release}):
            why = refusal(sim.rig, name, number)
            if why:
                raise ScenarioError(f"{plan.name}: the step at {step.at_ms} ms on {name}, "
                                    f"input {number}: {why}")


def _check(sim: RigSim, expect: Expect) -> None:
    """Run the rig through the expectation's time; ScenarioFailed if it never holds."""
    m = sim.machines[expect.controller]
    sim.run_until(expect.start_ms)
    while True:
        why = one.mismatch(m, expect.checks)
        if why is None:
            return
        if sim.now_ms() >= expect.end_ms:
            raise ScenarioFailed(f"{expect.describe()} on {expect.controller} failed: {why}")
        sim.run_until(min(expect.end_ms, _next_change_ms(sim)))


def _next_change_ms(sim: RigSim) -> float:
    """When any controller's checked state may change next (a wire joins them)."""
    now = sim.now_ms()
    t = min(sim.next_us() / 1000, *(one.next_change_ms(m) for m in sim.machines.values()))
    return t if t > now else now + min(m.cycle_ms for m in sim.machines.values())
