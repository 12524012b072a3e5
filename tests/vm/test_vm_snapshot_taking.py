"""How a snapshot is taken: `Machine.snapshot()` runs once per report, so it builds
the Snapshot by position and shares the stored macros' lines until the code changes. These
hold each field to what the machine says by name, and the shared lines to every change of
code (load, define, RM, RZ, RMALL)."""
from __future__ import annotations

import pytest

from helpers.compiling import program_of
from mercmac.ops import Op
from mercmac.vm import Machine, Options, reports
from mercmac.vm.motion import Side
from mercmac.vm.reports import Snapshot


def test_each_field_is_the_one_the_machine_names():
    # fields of one type hold different values here, so two swapped ones would show
    m = Machine(program_of("[MC00] JH90000,ZM1,ZP20,ZI7,DP3,SV9000,MR-6000,WA20,LF,WA100\n"
                           "[MC04] TP\n"),
                options=Options(hard_limits=(-5000, 4000), address=2, firmware="2.31"))
    m.schedule_input(1, 2, True)
    m.schedule_input(2, 5, True)
    m.power_on()
    m.run_until(30)
    m.set_error(0x07)
    t, axis = m.now_us, m.axis
    assert axis.moving(t) and axis.negative and not axis.referenced and not m.limits_on
    assert m.snapshot() == Snapshot(
        model=m.model, address=2, firmware="2.31", position=axis.position(t),
        velocity=axis.velocity(t), target=-6000, moving=True, sv=9000, sa=axis.sa,
        iteration=m.iteration(),
        settings={**m.params, "JH": 90000, "JL": axis.jl, "JN": 0, "ZM": 1, "ZP": 20, "ZI": 7},
        inputs=(False, False, True, False, False, True, False), buttons=0b0010,
        macros={0: "JH90000,ZM1,ZP20,ZI7,DP3,SV9000,MR-6000,WA20,LF,WA100", 4: "TP"},
        macro_running=True, error=0x07, referenced=False, servo=True, negative=True,
        homing=False, joystick=False, brake=True, limits_on=False, limits_high=m.limits_high,
        reference_high=True, limit=None)


def test_a_hard_limit_is_the_snapshots_limit():
    m = Machine(program_of("[MC00] MR-6000\n"), options=Options(hard_limits=(-5000, 4000)))
    m.power_on()
    m.run_until(5000)
    assert m.snapshot().limit is Side.NEGATIVE and not m.snapshot().moving


def _typed(m: Machine, *ops: Op) -> None:
    """A line the host types, run to its end."""
    m.execute_line(list(ops))
    m.run_until(m.now_ms + 10)


def test_the_lines_follow_every_change_of_code():
    m = Machine(program_of("[MC00] TP\n[MC02] TT\n[MC03] TV\n"))

    def listed() -> str:
        return reports.report("TM", None, m) + " | " + reports.report("TZ", None, m)

    first = m.snapshot()
    assert listed() == "MC002 TT\r\nMC003 TV | MC000 TP"
    m.define(4, [Op("TE")])
    assert listed() == "MC002 TT\r\nMC003 TV\r\nMC004 TE | MC000 TP"
    _typed(m, Op("RM", 2))
    assert listed() == "MC003 TV\r\nMC004 TE | MC000 TP"
    _typed(m, Op("RZ"))
    assert listed() == "MC003 TV\r\nMC004 TE | "
    m.load(program_of("[MC00] TT\n[MC05] TE\n"))
    assert listed() == "MC005 TE | MC000 TT"
    _typed(m, Op("RM"))
    assert listed() == " | MC000 TT"
    _typed(m, Op("RMALL"))
    assert listed() == " | "
    assert first.macros == {0: "TP", 2: "TT", 3: "TV"}


def test_shared_lines_cannot_be_changed_through_a_snapshot_or_stored_macros():
    m = Machine(program_of("[MC00] TP\n[MC02] TT\n"))
    with pytest.raises(TypeError):
        m.snapshot().macros[2] = "TV"
    m.stored_macros()[2] = "TV"  # the caller's own copy
    assert reports.report("TM", 2, m) == "MC002 TT" and m.snapshot().macros[2] == "TT"
