"""The rules of docs/simulator.md, one at a time: the VM runs lowered macros as the
firmware does."""
from __future__ import annotations

import pytest

from mercmac.compiler import compile_source
from mercmac.compiler.program import Macro, Op, Program
from mercmac.source import Source
from mercmac.timespec import parse_buttons, parse_duration
from mercmac.vm import Machine
from mercmac.vm.events import MacroEntered
from mercmac.sim.record import Folded
from mercmac.sim.simulate import simulate_program


def run(text: str, until: str = "10s", buttons: str = "", **kw):
    compiled = compile_source(Source("t.mcm", text))
    assert not compiled.report.has_errors, [d.message for d in compiled.report.items]
    return simulate_program(compiled.program, presses=parse_buttons(buttons),
                    until_ms=parse_duration(until), **kw)


def texts(result) -> list[str]:
    return [r.text for r in result.record.reports]


def times(result) -> list[float]:
    return [r.t / 1000 for r in result.record.reports]


def patterns(result) -> list[int]:
    return [o.pattern for o in result.record.outputs]


# -- Lines -----------------------------------------------------------------
def test_rp_repeats_from_the_start_of_the_current_macro_only():
    result = run("[MC00] TT,EM1,TP\n[MC01] TB,TC,RP2\n")
    # MC01 runs 3 times; MC00's TT before the call is not repeated
    assert texts(result) == ["T:+0000000000", "B:0", "H00:0", "B:0", "H00:0", "B:0", "H00:0",
                             "P:+0000000000"]


# -- Calls -------------------------------------------------------------------
def test_one_return_point_manual_3_8_4():
    # "MC1 could call MC2, but MC2 could not then call MC3 and still return to MC1"
    result = run("[MC00] EM1,CN4\n[MC01] EM2,CN1\n[MC02] EM3,CN2\n[MC03] CN3\n")
    # MC03 returns into MC02 (CN2); MC02's end finds no return point: MC01 and MC00 never resume
    assert result.machine.outputs_pattern() == 0b0110
    assert result.halted


def test_example3_mc18_resumes_after_em19_but_not_its_caller():
    program = """
[MC10] EM18,CN3
[MC18] XN4,CF1,CF2,MA-50000,EM19,CN1,EM20
[MC19] XF1,MR10,WS0,RP10000
[MC20] XF1,CN2
[MC00] EM10
"""
    # input 4 held: the move to -50000 starts; input 1 at 3 s interrupts the step moves
    result = run(program, until="10s", buttons="4@0,1@3s")
    m = result.machine
    assert m.outputs_pattern() & 1, "MC18 resumed after EM19 and ran CN1"
    assert not m.outputs_pattern() & 2, "MC20 exits on XF1 while input 1 is ON"
    assert not m.outputs_pattern() & 4, "MC10's CN3 never runs: EM19 replaced its return point"
    assert result.halted


def test_example3_runs_to_the_end_sets_output_2():
    program = """
[MC18] XN4,CF1,CF2,MA-50000,EM19,CN1,EM20
[MC19] XF1,MR10,WS0,RP3
[MC20] XF1,CN2
[MC00] EM18
"""
    result = run(program, until="10s", buttons="4@0")
    assert result.machine.outputs_pattern() == 0b0011
    # MA-50000 was overridden by MR10 from the last target: -50000 + 4 * 10
    assert result.machine.target == -49960


def test_em_to_an_empty_slot_does_nothing():
    result = run("[MC00] TT,EM7,TP\n")
    assert texts(result) == ["T:+0000000000", "P:+0000000000"]
    entered = [f.event.slot for f in result.record.timeline
               if isinstance(f, Folded) and isinstance(f.event, MacroEntered)]
    assert entered == [0]


def test_xn_exit_returns_to_the_caller():
    result = run("[MC00] EM1,TP\n[MC01] XN1,TT\n")
    assert texts(result) == ["P:+0000000000"]
    pressed = run("[MC00] EM1,TP\n[MC01] XN1,TT\n", buttons="1@0")
    assert texts(pressed) == ["T:+0000000000", "P:+0000000000"]


def test_xf_and_joystick_inputs_5_and_6():
    program = "[MC00] XF5,TB,XN6,TT\n"
    assert texts(run(program)) == ["B:0"]
    assert texts(run(program, buttons="6@0")) == ["B:0", "T:+0000000000"]
    assert texts(run(program, buttons="5@0")) == []


# -- Repeat counters -----------------------------------------------------------
def test_rp9_runs_the_line_ten_times():
    result = run("[MC00] TB,RP9\n")
    assert texts(result) == ["B:0"] * 10


def test_ti_example_of_manual_6_4():
    # MR100,WS100,WA250,TI,RP99: "X:+0000000000" first, then the remaining count
    result = run("[MC00] MR100,WS100,WA250,TI,RP99\n", until="5min")
    assert texts(result)[:4] == ["X:+0000000000", "X:+0000000099", "X:+0000000098",
                                 "X:+0000000097"]
    assert len(texts(result)) == 100
    assert texts(result)[-1] == "X:+0000000001"
    assert result.machine.target == 10_000


def test_rp_rp_runs_two_to_the_32_passes_through_fast_forward():
    result = run("[MC00] CN1,WA20,RP,RP\n", until="1500d")
    assert result.halted
    # 2^32 passes of CN1 (1 ms) + WA20 (20 ms) + RP (1 ms), plus the second RP
    # (1 ms) each of the 65536 times the first one runs out
    assert result.record.ended_at == (2**32 * 22 + 65536) * 1000
    assert any(type(e).__name__ == "FastForwarded" for e in result.record.timeline)


def test_fast_forward_is_exact_against_a_plain_run():
    program = "[MC00] CN1,WA7,TB,RP3,WA5,RP200\n"
    slow = run(program, until="1h")
    # TB makes every pass observable, so nothing is skipped: the reference
    reports = len(texts(slow))
    quiet = run(program.replace("TB,", ""), until="1h")
    assert reports == 4 * 201
    assert quiet.record.ended_at == slow.record.ended_at - reports * 1000


def test_counters_reset_when_a_macro_is_entered():
    result = run("[MC00] EM1,EM1\n[MC01] TB,RP1\n")
    assert texts(result) == ["B:0"] * 4


def test_a_later_arrival_after_running_out_starts_again():
    # the inner RP1 runs out, the outer RP1 jumps back, the inner starts afresh
    result = run("[MC00] TB,RP1,RP1\n")
    assert texts(result) == ["B:0"] * 4


# -- Time ----------------------------------------------------------------------
def test_each_command_takes_one_cycle():
    assert times(run("[MC00] TB,TB,TB\n")) == [0, 1, 2]
    assert times(run("[MC00] TB,TB,TB\n", cycle_ms=0.5)) == [0, 0.5, 1]


def test_wa_waits_from_its_start():
    assert times(run("[MC00] TB,WA20,TB,WA0,TB\n")) == [0, 21, 23]


def test_ws_waits_for_the_stop_then_n_ms_default_1000():
    now = times(run("[MC00] WS,TB\n"))
    assert now == [1000]
    moved = run("[MC00] MR1000,WS10,TB\n")
    arrival = next(e for e in moved.record.timeline if type(e).__name__ == "MoveEnded").t
    assert times(moved) == [arrival / 1000 + 10]


def test_wn_wf_wait_for_inputs():
    result = run("[MC00] WN2,TB,WF2,TB\n", buttons="2@1.5s-4s")
    assert times(result) == [1500, 4000]


# -- Outputs -------------------------------------------------------------------
def test_cn_cf_cp_set_the_leds():
    result = run("[MC00] CN1,CN3,CF1,CP12,CP0\n")
    assert patterns(result) == [0b0001, 0b0101, 0b0100, 0b1100, 0]


def test_output_4_carries_trigger_pulses():
    # §4.5.2 sequence: DH20000, ZP26000, ZI100, SV50000, SA400000, ZM2, MR100000
    result = run("[MC00] DH20000,ZP26000,ZI100,SV50000,SA400000,ZM2,MR100000,WS0\n")
    rises = [o.t for o in result.record.outputs if o.pattern & 8]
    assert len(rises) == (120000 - 26000) // 100 + 1
    first = rises[0] / 1e6
    # the first pulse when the stage crosses 26,000 (6,000 counts from the start)
    accel = 50000 / 400000
    cruise = (6000 - 0.5 * 400000 * accel**2) / 50000
    assert first == pytest.approx(0.006 + accel + cruise, abs=2e-6)


# -- Reports -------------------------------------------------------------------
def test_report_formats():
    result = run("[MC00] MA5555,WS0,TP,TT,TC,TC1,TY,TL,TS\n", buttons="1@0,3@0")
    # TS: on target; busy, macro running; LN, LH, brake on; inputs 1 and 3; no error
    assert texts(result) == ["P:+0000005555", "T:+0000005555", "H00:5", "H01:1",
                             "Y:+0000045000", "L:+0000400000", "S:04 12 00 0B 50 00"]


def test_c663_status_has_three_blocks_and_its_defaults():
    result = run("target C-663\nautostart { TY, TL, TS }\n")
    # block 1: on target, macro running (so not ready), brake on (BN, §3.4.2); block 2: both
    # limit lines high, as active-low switches (LL) that are not hit read (§6.4 TS `s:03 07 00`)
    assert texts(result) == ["Y:+0000020000", "L:+0000250000", "S:52 05 00"]


# -- Power-on ------------------------------------------------------------------
def test_macro_0_runs_at_t0_and_nothing_runs_without_it():
    started = run("[MC00] TB\n")
    assert times(started) == [0]
    idle = run("[MC03] TB\n")
    assert texts(idle) == [] and idle.halted


def test_direct_mode_api_used_by_the_emulator():
    seen = []
    program = Program({3: Macro(3, "MC03", [Op("TP"), Op("MR", 500), Op("WS", 0), Op("TP")])})
    m = Machine(program, model="C-663", on_report=lambda t, s: seen.append((t, s)))
    m.power_on()
    m.execute_line([Op("MA", 1000), Op("TT")])
    m.run_until(5)
    assert seen == [(1.0, "T:+0000001000")]
    m.start_macro(3)
    assert m.running and m.macro == 3
    m.run_until(2000)
    assert not m.running and seen[-1][1] == "P:+0000001500"
    m.start_macro(9)  # empty slot: nothing
    assert not m.running
