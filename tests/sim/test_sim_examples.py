"""The manual's Examples 1-4 (MS176E §3.8.6) driven by scripted buttons; the bundled scenarios."""
from __future__ import annotations

import os

import pytest

from helpers.compiling import program_of
from helpers.paths import EXAMPLE4, EXAMPLES, SCENARIOS
from mercmac.compiler import compile_file
from mercmac.timespec import parse_buttons
from mercmac.vm import events as ev
from mercmac.sim import scenario
from mercmac.rig.open import open_program
from mercmac.sim.simulate import Simulation, machine_for, simulate_program


def example4(buttons: str, until_ms: int):
    compiled = compile_file(str(EXAMPLE4))
    assert not compiled.report.has_errors
    return simulate_program(compiled.program, presses=parse_buttons(buttons), until_ms=until_ms)


def test_example1_initialises_then_polls_for_ever():
    program = program_of("[MC00] EM5,EM13\n"
                         "[MC05] BF,DP200,DI,DD200,SV80000,SA400000,FE2,WS100,DH,SV250000\n"
                         "[MC13] EM14,EM15,EM16,EM17,WA20,RP,RP\n")
    run = simulate_program(program, until_ms=3_600_000)
    m = run.machine
    assert m.running and m.macro == 13
    assert m.axis.sv == 250_000 and m.params["DP"] == 200 and m.params["DI"] == 0
    assert not m.brake and m.axis.referenced
    assert any(isinstance(e, ev.FastForwarded) for e in run.record.timeline)


def test_example1_fe2_finds_a_switch_away_from_zero():
    program = program_of("[MC00] EM5\n"
                         "[MC05] BF,DP200,DI,DD200,SV80000,SA400000,FE2,WS100,DH,SV250000\n")
    from mercmac.vm import Options

    run = simulate_program(program, until_ms=5000, options=Options(reference_at=12_000))
    homes = [e for e in run.record.timeline if isinstance(e, ev.HomeDefined)]
    assert run.halted and len(homes) == 1 and homes[0].position == 0
    assert run.machine.position() == 0 and run.machine.axis.shift == -12_000


def test_example2_button_3_steps_through_speeds_and_leds():
    program = program_of("[MC16] XN3,SV70000,CP8,WA200,XN3,SV130000,CP12,WA200,XN3,SV190000,"
                         "CP14,WA200,XN3,SV250000,CP15,WF3\n")
    m, record = machine_for(program)
    m.schedule_input(0, 3, True)
    m.schedule_input(450, 3, False)
    m.power_on()
    m.start_macro(16)
    m.run_until(2000)
    assert [o.pattern for o in record.outputs] == [8, 12, 14]
    assert m.axis.sv == 190_000 and not m.running


def test_example2_buttons_1_and_2_together():
    program = program_of("[MC15] XN1,XN2,SV30000,WF1,WF2\n")
    m, _ = machine_for(program)
    m.schedule_input(0, 1, True)
    m.schedule_input(0, 2, True)
    m.schedule_input(500, 1, False)
    m.schedule_input(800, 2, False)
    m.power_on()
    m.start_macro(15)
    m.run_until(700)
    assert m.axis.sv == 30_000 and m.running
    m.run_until(900)
    assert not m.running


def test_example3_continuous_move_until_released_then_ab1():
    program = program_of("[MC00] EM17\n[MC17] XN1,MR-9999999,WF1,AB1\n")
    run = simulate_program(program, presses=parse_buttons("1@0-1s"), until_ms=3000)
    m = run.machine
    # after 1 s at up to 45000 c/s (reached after 112.5 ms) and AB1's 2531 counts of braking
    expected = -(45_000 * (1.0 - 0.001 - 45_000 / 400_000 / 2) + 45_000**2 / 800_000)
    assert m.position() == pytest.approx(expected, abs=50)
    assert m.target == m.position() and run.halted


@pytest.mark.parametrize("mode, velocity", [(1, 70_000), (2, 250_000), (3, 250_000),
                                            (4, 120_000)])
def test_example4_mode_selection_at_power_on(mode, velocity):
    run = example4(f"{mode}@0-300ms", 2000)
    entered = {f.event.slot for f in run.record.timeline
               if hasattr(f, "event") and isinstance(f.event, ev.MacroEntered)}
    loop = {1: 15, 2: 20, 3: 26, 4: 20}[mode]
    assert loop in entered and run.machine.macro == loop
    assert run.machine.axis.sv == velocity


def test_example4_no_button_ends_in_direct_mode():
    run = example4("", 2000)
    # MC09 ends at 110 ms (WS100 from 8 ms, DH, SV); EM10, then MC11-MC14 each EM + XN
    assert run.halted and run.record.ended_at == 119_000


def test_example4_mode1_runs_while_held_and_steps():
    # mode 1 at power-on (button 1 held until 300 ms also runs MC16: positive until released)
    run = example4("1@0-300ms,2@2s-2.1s,3@4s-4.1s,4@6s-7s", 9000)
    m = run.machine
    starts = [e for e in run.record.timeline if isinstance(e, ev.MoveStarted)]
    kinds = [(e.kind, e.target) for e in starts if e.kind in ("move", "stop")]
    assert kinds[0] == ("move", 9_999_999) and kinds[1][0] == "stop"
    after_first = kinds[1][1]
    assert ("move", after_first + 10_000) in kinds  # button 2: MR10000
    assert ("move", after_first) in kinds  # button 3: MR-10000 back
    assert kinds[-1][0] == "stop" and m.position() < after_first - 10_000  # button 4 ran negative


def rest_to_rest_us(distance: float, v: float, a: float) -> float:
    """Closed form: a triangle when v is never reached, else a trapezoid."""
    if distance < v * v / a:
        return 2 * (distance / a) ** 0.5 * 1e6
    return (distance / v + v / a) * 1e6


@pytest.mark.parametrize("mode, velocity", [(2, 250_000), (4, 120_000)])
def test_example4_modes_2_and_4_go_to_fixed_positions(mode, velocity):
    run = example4(f"{mode}@0-150ms,1@2.5s-2.7s,3@5s-5.2s,4@7.5s-7.7s,2+3@10s-10.3s", 13_000)
    moves = [e for e in run.record.timeline if isinstance(e, ev.MoveStarted) and e.kind == "move"]
    first = 50_000 if mode == 2 else -100_000
    assert [e.target for e in moves] == [first, 100_000, -50_000, -100_000, 0]
    assert [o.pattern for o in run.record.outputs] == [2 if mode == 2 else 8, 1, 4, 8, 6]
    for before, move in zip(moves, moves[1:]):  # each from rest: the mode's own speed
        expected = rest_to_rest_us(abs(move.target - before.target), velocity, 400_000)
        assert move.arrival - move.t == pytest.approx(expected, abs=2)


def test_example4_mode3_steps_while_held():
    # button 3 still held when MC26 starts: MC29 steps -2000; button 1 held 0.6 s: two
    # steps of +4000 (each 200 ms move + WS50 + WA20 + the pass); button 4: one of -4000
    run = example4("3@0-250ms,1@1s-1.6s,4@3s-3.05s", 5000)
    targets = [e.target for e in run.record.timeline
               if isinstance(e, ev.MoveStarted) and e.kind == "move"]
    assert targets == [-2000, 2000, 6000, 2000]
    assert run.machine.position() == 2000


@pytest.mark.parametrize("path", sorted(map(str, SCENARIOS.glob("*.toml"))))
def test_bundled_scenarios_pass(path):
    """examples/scenarios/NAME.anything.toml belongs to examples/macros/NAME.mcm."""
    name = os.path.basename(path).split(".")[0]
    accepted = open_program(str(EXAMPLES / (name + ".mcm")))
    plan = scenario.load(path)
    sim = Simulation(accepted.rig, {n: c.program for n, c in accepted.programs.items()})
    assert scenario.run(sim, plan, plan.until_ms or 10_000) == len(plan.expects) > 0
