"""Motion timing against the closed-form trapezoid and triangle, and the axis's rules
(docs/simulator.md)."""
from __future__ import annotations

import math

import pytest

from mercmac.compiler.program import Op, Program
from mercmac.vm import Machine, Options


def closed_form_s(distance: float, v: float, a: float) -> float:
    """Rest-to-rest time: triangle if v is never reached (d < v^2/a), else trapezoid."""
    if distance < v * v / a:
        return 2 * math.sqrt(distance / a)
    return distance / v + v / a


def machine(model="C-863", **options) -> Machine:
    m = Machine(Program({}), model=model, options=Options(**options))
    m.power_on()
    return m


def arrival_ms(m: Machine, line: list[Op]) -> float:
    reports = []
    m.on_report = lambda t, s: reports.append(t)
    m.execute_line(line + [Op("WS", 0), Op("TB")])
    m.run_until(m.now_ms + 600_000)
    return reports[-1]  # TB runs at the arrival (WS0 adds nothing)


@pytest.mark.parametrize("model, distance", [
    ("C-863", 100_000),  # trapezoid: 45000 c/s reached after 5625 counts
    ("C-863", 3_000),  # triangle
    ("C-663", 250_000),
    ("C-663", 500),
])
def test_move_time_matches_the_closed_form(model, distance):
    m = machine(model)
    v, a = (45_000, 400_000) if model == "C-863" else (20_000, 250_000)
    expected = closed_form_s(distance, v, a) * 1000
    assert arrival_ms(m, [Op("MR", distance)]) == pytest.approx(expected, abs=0.002)
    assert m.position() == distance


@pytest.mark.parametrize("v, a, distance", [(80_000, 100_000, 1_000_000), (250_000, 950_000, 20_000)])
def test_sv_sa_set_the_profile(v, a, distance):
    m = machine()
    t = arrival_ms(m, [Op("SV", v), Op("SA", a), Op("MR", -distance)])
    # SV and SA take one cycle each before the move starts at 2 ms
    assert t - 2 == pytest.approx(closed_form_s(distance, v, a) * 1000, abs=0.002)
    assert m.position() == -distance


def test_profile_shape_midway_and_cruise_velocity():
    m = machine()
    m.execute_line([Op("MA", 100_000)])
    total = closed_form_s(100_000, 45_000, 400_000) * 1000
    m.run_until(total / 2)
    assert m.position() == pytest.approx(50_000, abs=1)
    assert m.velocity() == 45_000
    m.run_until(45_000 / 400_000 * 1000 / 2)  # in the past: time does not go back
    assert m.position() == pytest.approx(50_000, abs=1)


def test_mr_adds_to_the_last_target_not_the_position():
    m = machine()
    m.execute_line([Op("MR", 10_000), Op("MR", 10_000)])
    m.run_until(1.5)
    assert m.target == 20_000 and m.position() < 100
    m.run_until(5_000)
    assert m.position() == 20_000


def test_soft_limits_clamp_targets_and_report_a_hazard():
    events = []
    m = Machine(Program({}), on_event=events.append)
    m.power_on()
    m.execute_line([Op("JH", 5000), Op("JL", -100), Op("MA", 8000), Op("WS", 0), Op("MR", -9000)])
    m.run_until(5_000)
    assert m.position() == -100 and m.target == -100
    hazards = [e.rule for e in events if type(e).__name__ == "HazardFound"]
    assert hazards == ["soft-limit-clamp", "soft-limit-clamp"]
    m.execute_line([Op("JC"), Op("MA", 8000), Op("WS", 0)])
    m.run_until(10_000)
    assert m.position() == 8000


def test_gh_dh_and_the_shifted_home():
    m = machine()
    m.execute_line([Op("MA", 3000), Op("WS", 0), Op("DH", 100), Op("TP"), Op("GH"), Op("WS", 0)])
    m.run_until(5_000)
    assert m.position() == 0 and m.target == 0  # GH went to the new zero: 2900 counts back


def test_ab_stops_at_once_ab1_decelerates_to_the_stop_point():
    m = machine()
    m.execute_line([Op("MR", 1_000_000), Op("WA", 500), Op("AB")])
    m.run_until(502)
    stopped = m.position()
    assert m.target == stopped and m.velocity() == 0
    m = machine()
    m.execute_line([Op("MR", 1_000_000), Op("WA", 500), Op("AB", 1)])
    m.run_until(501)
    at_ab1 = m.position()
    m.run_until(2_000)
    # from 45000 c/s at 400000 c/s^2: v^2 / 2a more counts
    assert m.position() - at_ab1 == pytest.approx(45_000**2 / 800_000, abs=2)
    assert m.target == m.position()


def test_st_overshoots_and_moves_back():
    m = machine()
    m.execute_line([Op("MR", 1_000_000), Op("WA", 500), Op("ST"), Op("WS", 0), Op("TP")])
    m.run_until(501)
    captured = m.position()
    m.run_until(560)
    assert m.position() > captured  # still braking past the captured point (112 ms to stop)
    m.run_until(3000)
    assert m.position() == captured == m.target


def test_servo_off_refuses_moves_with_error_0a():
    events = []
    said = []
    m = Machine(Program({}), options=Options(servo_on=False), on_event=events.append,
                on_report=lambda t, text: said.append(text))
    m.power_on()
    m.execute_line([Op("MR", 100), Op("TS")])
    m.run_until(10)
    assert m.target == 0 and said[-1].endswith(" 0A")
    assert m.status().endswith(" 00")  # the TS that read the code cleared it
    assert [e.rule for e in events if type(e).__name__ == "HazardFound"] == ["move-servo-off"]
    m.execute_line([Op("MN"), Op("MR", 100), Op("WS", 0)])
    m.run_until(100)
    assert m.position() == 100


def test_joystick_on_refuses_moves_and_drives_with_input_5():
    events = []
    m = Machine(Program({}), on_event=events.append)
    m.power_on()
    m.execute_line([Op("JN", 20_000), Op("MR", 100)])
    m.run_until(10)
    assert m.target == 0 and m.status().endswith(" 0B")
    m.set_input(5, True)
    m.run_until(1010)
    assert m.velocity() == 20_000
    m.set_input(5, False)
    m.run_until(2000)
    assert m.velocity() == 0 and m.position() == m.target > 0


def test_hard_limit_stops_abruptly_with_error_07():
    events = []
    said = []
    m = Machine(Program({}), options=Options(hard_limits=(-1000, 5000)), on_event=events.append,
                on_report=lambda t, text: said.append(text))
    m.power_on()
    m.execute_line([Op("MR", 20_000), Op("WS", 0), Op("TS")])
    m.run_until(2000)
    assert m.position() == 5000 == m.target
    assert said[-1].endswith(" 07")  # read by the TS, which clears it (Machine.read_status)
    hit = next(e for e in events if type(e).__name__ == "HazardFound")
    assert hit.rule == "hard-limit" and hit.where.ip == 0  # blamed on the MR that ran into it


@pytest.mark.parametrize("mode, switch_at, found, end", [
    (0, 5000, True, 5000), (1, -5000, True, -5000), (2, 5000, True, 5000),
    (2, -5000, True, -5000), (3, 5000, False, -20_000), (0, -5000, False, 20_000)])
def test_fe_finds_the_reference_switch(mode, switch_at, found, end):
    # §6.4 FE2: the reference line is high on the negative side of the switch
    events = []
    m = Machine(Program({}), options=Options(reference_at=switch_at, hard_limits=(-20_000, 20_000)),
                on_event=events.append)
    m.power_on()
    m.execute_line([Op("FE", mode), Op("WS", 0)])
    m.run_until(5_000)
    hazards = [e.rule for e in events if type(e).__name__ == "HazardFound"]
    assert m.position() == end
    referenced = bool(int(m.status().split()[0][2:], 16) & 8)  # TS block 1 bit 3
    assert referenced == found
    assert hazards == ([] if found else ["reference-not-found", "hard-limit"])


def test_ws_that_can_never_finish_is_a_hazard():
    events = []
    m = Machine(Program({}), on_event=events.append)
    m.power_on()
    m.execute_line([Op("SV", 0), Op("MR", 100), Op("WS", 0), Op("TB")])
    m.run_until(60_000)
    assert m.running
    assert [e.rule for e in events if type(e).__name__ == "HazardFound"] == ["ws-never-finishes"]
