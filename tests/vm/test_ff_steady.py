"""A move in flight that a pass commands again to where it goes keeps the running profile
(Axis.keeps), and passes that leave the profile as it is, and show nothing of where the stage
is on it, repeat: they are skipped up to the profile's next event (its arrival, a limit
switch, a trigger pulse), exactly as stepping gives (docs/simulator.md, "Fast-forward")."""
from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from helpers.budgets import budget
from helpers.compiling import program_of
from mercmac.compiler.program import Macro, Op, Program
from mercmac.vm import events as ev
from mercmac.vm.models import DEFAULTS, Options
from mercmac.vm.motion import Axis
from mercmac.vm.trapezoid import PER_S

MODELS = ("c-863", "c-663")
from helpers.simulation import same_as_stepping

# the stage chases a target that runs ahead to the soft limit, then cruises to it
CHASE = ("macro chase {\n  MR 500, TT, MR 25000, CN 1, WA 5, CF 1, goto chase\n}\n"
         "autostart { goto chase }\n")


def test_a_move_commanded_again_to_its_target_keeps_the_profile():
    axis = Axis(DEFAULTS["C-863"], Options())
    assert not axis.move(0, 50_000)
    segs, plan = axis.segs, axis.plan
    for t in (1_000, 250_000, 1_150_000):  # accelerating, cruising, slowing down
        assert axis.move(t, 50_000)
        assert axis.segs is segs and axis.plan is plan
    # a target further on while it cruises: planned from the same start, the same path
    assert axis.move(800_000, 60_000)
    assert axis.plan == plan._replace(target=60_000) and axis.segs[:1] == segs[:1]
    assert axis.segs[1][:4] == segs[1][:4] and axis.segs[1].dt > segs[1].dt
    assert not axis.move(900_000, 40_000)  # one behind it: planned anew from here
    assert axis.segs[0].t0 == 900_000


def test_a_target_further_on_once_it_slows_down_is_planned_anew():
    axis = Axis(DEFAULTS["C-863"], Options())
    axis.move(0, 50_000)
    slowing = axis.segs[-1].t0 + 1_000
    assert not axis.move(slowing, 60_000)
    assert axis.segs[0].t0 == slowing


def test_a_move_at_another_velocity_is_planned_anew():
    axis = Axis(DEFAULTS["C-863"], Options())
    axis.move(0, 50_000)
    assert not axis.move(100_000, 50_000, vmax=axis.sv / 2)  # (the joystick's velocity)
    assert not axis.move(150_000, 50_000)  # back to SV: planned anew again


@pytest.mark.parametrize("model", MODELS)
def test_a_chase_loop_skips_to_the_arrival_exactly(model):
    program = program_of(CHASE, model)
    skips = same_as_stepping(program, [20_000, 600_000, 3_000_000], model)
    # it skips while the stage cruises to the soft limit: once the target is clamped
    assert sum(s.passes for s in skips) > 10_000


def test_a_polling_loop_during_a_long_move_is_skipped_to_the_arrival():
    source = "autostart {\n  MA 2000000\n  every 20ms { TT, CN 2, WA 3, CF 2 }\n}\n"
    skips = same_as_stepping(program_of(source, "c-863"), [60_000, 120_000], "c-863")
    assert skips and sum(s.passes for s in skips) > 2000


# -- the property: passes that command a running move again change nothing but the speed --
body = st.lists(st.sampled_from([
    ("MA", 40_000), ("MA", -30_000), ("MR", 0), ("MR", 1), ("MR", 25_000), ("TT", None),
    ("TP", None), ("TV", None), ("TS", None), ("TE", None), ("CN", 1), ("CF", 1), ("WA", 1),
    ("WA", 5), ("SV", 3000), ("WS", 0), ("AB", None)]), min_size=1, max_size=6)
tail = st.sampled_from([[("RP", 65535)], [("WA", 2), ("RP", 30), ("RP", 65535)],
                        [("EM", 4)]])
limits = st.sampled_from([None, (-90_000, 35_000)])
trigger = st.sampled_from([[], [("ZM", 2), ("ZP", 5), ("ZI", 1000)], [("ZM", 1), ("ZP", 300)]])


@pytest.mark.slow
@settings(max_examples=budget(100), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(body, tail, limits, trigger, st.sampled_from(MODELS),
       st.lists(st.integers(10, 40_000), min_size=1, max_size=3))
def test_passes_that_command_a_running_move_again_give_what_stepping_gives(
        ops, loop, hard, pulses, model, times):
    slots = {0: [*pulses, ("EM", 4)], 4: ops + loop}
    program = Program({s: Macro(s, f"MC{s:02d}", [Op(m, a) for m, a in code])
                       for s, code in slots.items()})
    same_as_stepping(program, sorted(set(times)), model, Options(hard_limits=hard))


def test_kept_moves_are_told_as_moves_from_where_the_stage_is():
    # the timeline's "from" is where the stage is when the command runs, not where the
    # profile began
    from mercmac.render.sim import event_line

    axis = Axis(DEFAULTS["C-863"], Options())
    axis.move(0, 50_000)
    t = 500_000
    event = ev.MoveStarted(t, ev.Motion.MOVE, 50_000, axis.arrival(), axis.segs, None, True)
    text = "".join(part for part, _ in event_line(event))
    assert f"from {round(axis.position(t))} " in text and round(axis.position(t)) > 0
    assert axis.velocity(t) * PER_S > 0


@pytest.mark.parametrize("model", MODELS)
def test_a_chase_loop_dumps_and_plots_as_stepping_does(model):
    # the VCD samples the stage along its profile through the skips, the plot draws it
    import io

    from helpers.simulation import same_samples, vcd_values
    from mercmac.rig.model import Rig
    from mercmac.sim.plot import PlotObserver
    from mercmac.sim.simulate import simulate
    from mercmac.sim.vcd import Dump

    program = program_of(CHASE, model)
    rig = Rig.of_program("chase.mcm", model)
    name = rig.controllers[0].name
    seen = []
    for mode in ("all", "off"):
        out, plot = io.StringIO(), PlotObserver()
        dump = Dump(out, [name])
        listeners = {name: [*dump.listeners()[name], plot.on_event]}
        simulate(rig, {name: program}, until_ms=20_000, listeners=listeners, fast_forward=mode)
        dump.close(20_000_000)
        plot.close(20_000_000)
        seen.append((vcd_values(out.getvalue()), plot.trace))
    (fast, fast_trace), (plain, plain_trace) = seen
    assert same_samples(fast, plain) > 1000
    assert fast_trace.target[-1] == plain_trace.target[-1]
    assert abs(fast_trace.position[-1][1] - plain_trace.position[-1][1]) < 1


def test_a_target_running_ahead_toward_a_limit_switch_is_stepped_into_it():
    # each pass moves the target 25,000 on while the stage cruises: the skip stops before a
    # target past the switch, whose profile would run into it
    source = "macro chase {\n  MR 25000, CN 1, WA 5, CF 1, goto chase\n}\nautostart { goto chase }\n"
    options = Options(hard_limits=(-90_000, 3_000_000))
    same_as_stepping(program_of(source, "c-663"), [5_000, 200_000], "c-663", options)
