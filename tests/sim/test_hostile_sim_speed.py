"""Nothing lost, nothing hangs: long and busy simulations, many presses, big VCDs.

Loops whose passes repeat except for what they emit are fast-forwarded, and
the skipped passes' reports and LED changes are listed and counted exactly as
plain stepping would (docs/simulator.md, "Fast-forward"). Each run here has a budget
of executed instructions, so the slow code fails fast instead of hanging the suite.
"""
from __future__ import annotations

import glob
import json
import os
import time
from unittest import mock

import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from helpers.budgets import budget
from helpers.compiling import program_of
from helpers.simulation import observed
from mercmac.cli import main
from mercmac.compiler.program import Macro, Op, Program
from mercmac.outfile import OutputError
from mercmac.timespec import Press
from mercmac.vm import events as ev
from mercmac.sim import record as record_module
from mercmac.cli import run as sim_run
from mercmac.vm.machine import Machine
from mercmac.sim.simulate import machine_for, schedule, simulate_program

DAY_MS = 86_400_000
PING_PONG = "macro a { goto b }\nmacro b { goto a }\nautostart { goto a }\n"
BLINK = "autostart {\n  every 500ms { CN 1, WA 500, CF 1 }\n}\n"  # CN1,WA500,CF1,WA500,RP,RP
TT_20MS = "autostart {\n  every 20ms { TT }\n}\n"  # TT,WA20,RP,RP
SHUTTLE = "autostart {\n  every 1s { MA 100000, WS 0, MA 0, WS 0 }\n}\n"


class OverBudget(Exception):
    """More instructions executed than the test allows: the loop was not skipped."""


def run(text: str, until_ms: int, budget: int = 10_000, fast_forward: str = "all",
        presses=()):
    """Simulate with a budget of executed instructions; (machine, recorder, executed)."""
    machine, record = machine_for(program_of(text), trace=True, fast_forward=fast_forward)
    executed = 0

    def listen(event) -> None:
        nonlocal executed
        if isinstance(event, ev.Executed):
            executed += 1
            if executed > budget:
                raise OverBudget(f"{executed} instructions by {event.t} us")
        record.on_event(event)

    machine.on_event = listen
    schedule(machine, presses)
    machine.power_on()
    machine.run_until(until_ms)
    return machine, record, executed


def every_pass(cycle_passes: int, pass_ms: int, outer_ms: int, offsets: list[int],
               until_ms: int) -> list[int]:
    """Times (ms) of events at `offsets` in each pass of an `X,RP,RP` loop, by arithmetic:
    65536 passes, then the outer RP takes `outer_ms` before the inner loop starts again."""
    cycle = cycle_passes * pass_ms + outer_ms
    times = []
    for start in range(0, until_ms, cycle):
        for offset in offsets:
            last = min(cycle_passes, -(-(until_ms - start - offset) // pass_ms))
            times.extend(start + j * pass_ms + offset for j in range(max(last, 0)))
    return sorted(times)


def total(record, what: str) -> int:
    return len(getattr(record, what)) + record.dropped[what]


# -- busy and long loops fast-forward, counting what they emit ------------------
def test_a_goto_ping_pong_without_a_wait_runs_a_day_in_few_instructions():
    machine, record, executed = run(PING_PONG, DAY_MS)
    assert machine.clock.now == DAY_MS * 1000 and machine.running
    assert executed < 100
    assert [h.rule for h in record.hazards] == ["busy-loop", "busy-loop"]  # as plain stepping
    assert any(isinstance(e, ev.FastForwarded) for e in record.timeline)


def test_a_blinking_led_for_a_day_counts_every_change_exactly():
    machine, record, executed = run(BLINK, DAY_MS)
    assert executed < 1000
    # CN1 at 0, CF1 at 501 ms in each 1003 ms pass; the outer RP takes 1 ms per 65536
    want = every_pass(65536, 1003, 1, [0, 501], DAY_MS)
    assert total(record, "outputs") == len(want) == 172_284
    assert [o.t for o in record.outputs] == [t * 1000 for t in want[:10_000]]
    assert [o.pattern for o in record.outputs[:4]] == [1, 0, 1, 0]
    assert record.dropped["outputs"] == len(want) - 10_000


def test_a_report_every_20ms_for_a_day_counts_every_report_exactly():
    machine, record, executed = run(TT_20MS, DAY_MS)
    assert executed < 1000
    want = every_pass(65536, 22, 1, [0], DAY_MS)
    assert total(record, "reports") == len(want) == 3_927_271
    assert [r.t for r in record.reports] == [t * 1000 for t in want[:10_000]]
    assert {r.text for r in record.reports} == {"T:+0000000000"}


def test_a_ti_loop_is_not_skipped_as_if_its_reports_were_the_same():
    # TI reports the jumping RP's own counter: every pass differs, none may be skipped
    machine, record, _ = run("[MC00] TI,WA5,RP50\n", 1000)
    assert [r.text for r in record.reports][:3] == ["X:+0000000000", "X:+0000000050",
                                                    "X:+0000000049"]
    assert len(record.reports) == 51 and record.reports[-1].text == "X:+0000000001"


def test_skipped_reports_reach_on_report_too():
    program = program_of(TT_20MS)
    heard = {mode: [] for mode in ("all", "off")}
    for mode, into in heard.items():
        m = Machine(program, fast_forward=mode, on_report=lambda t, text, into=into:
                    into.append((t, text)))
        m.power_on()
        m.run_until(5_000)
    assert heard["all"] == heard["off"] and len(heard["off"]) == 5000 // 22 + 1


def test_json_counts_the_skipped_passes():
    result = CliRunner().invoke(main, ["sim", "-", "--until", "1d", "--format", "json"],
                                input="[MC00] TT,CN1,CF1,WA17,RP,RP\n")
    assert result.exit_code == 0, result.output
    out = json.loads(result.output)
    passes = len(every_pass(65536, 21, 1, [0], DAY_MS))
    events = out["truncated"].pop("events")
    assert out["truncated"] == {"reports": passes - 10_000, "outputs": 2 * passes - 10_000}
    # the events of skipped passes are counted too (a report and two output
    # changes a pass, the power-on entry), and the fast-forward markers past the cap
    assert 0 <= events - (3 * passes + 1 - 10_000) < 10
    assert len(out["reports"]) == len(out["outputs"]) == 10_000


# -- the property: fast-forward changes nothing but the speed ------------------
command = st.one_of(
    st.tuples(st.sampled_from(["CN", "CF"]), st.integers(1, 2)),
    st.tuples(st.just("CP"), st.integers(0, 3)),
    st.tuples(st.sampled_from(["TB", "TI", "TT", "TC"]), st.none()),
    st.tuples(st.just("WA"), st.sampled_from([0, 1, 3, 10, 40])),
    st.tuples(st.sampled_from(["XN", "XF"]), st.integers(1, 2)),
    st.tuples(st.just("EM"), st.integers(0, 3)),
    st.tuples(st.just("RP"), st.sampled_from([0, 1, 2, 7, 300, 65535])),
    st.tuples(st.just("MA"), st.sampled_from([0, 50])),
)
# macro 0 mostly ends in a loop, often two nested ones, so that passes repeat
loop_tail = st.sampled_from([[], [("RP", 65535)], [("RP", 7), ("RP", 65535)],
                             [("WA", 2), ("RP", 40), ("RP", 65535)], [("EM", 0)]])
repeating = st.one_of(  # commands whose passes repeat (no motion, TI or conditions)
    st.tuples(st.sampled_from(["CN", "CF"]), st.integers(1, 2)),
    st.tuples(st.sampled_from(["TB", "TT"]), st.none()),
    st.tuples(st.just("WA"), st.sampled_from([0, 1, 3, 10])),
    st.tuples(st.just("EM"), st.integers(1, 3)),
)
macros = st.tuples(
    st.lists(command, min_size=1, max_size=5) | st.lists(repeating, min_size=1, max_size=5),
    loop_tail,
    st.dictionaries(st.integers(1, 3), st.lists(command, min_size=1, max_size=6), max_size=3),
).map(lambda parts: {0: parts[0] + parts[1], **parts[2]})
presses = st.lists(st.tuples(st.integers(1, 2), st.integers(0, 3000), st.integers(0, 500)),
                   max_size=3)


def outcome(program: Program, buttons: list, until_ms: int, mode: str):
    machine, record = machine_for(program, fast_forward=mode)
    schedule(machine, buttons)
    machine.power_on()
    machine.run_until(until_ms)
    m = machine
    return {
        **observed(record),
        "final": (m.clock.now, m.macro, m.ip, m.ret and (m.ret[0].slot, m.ret[1]), m.counters,
                  m.last_rp, m.outputs_pattern(), m.position(), m.block, m.wake, m.error),
    }


@pytest.mark.slow
@settings(max_examples=budget(250), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(macros, presses, st.integers(50, 6000))
def test_fast_forward_gives_what_plain_stepping_gives(slots, buttons, until_ms):
    program = Program({s: Macro(s, f"MC{s:02d}", [Op(m, a) for m, a in ops])
                       for s, ops in slots.items()})
    pressed = [Press((n,), t, t + held) for n, t, held in buttons]
    with mock.patch.object(record_module, "CAP", 25):  # lists fill up and counts start
        fast = outcome(program, pressed, until_ms, "all")
        plain = outcome(program, pressed, until_ms, "off")
    assert fast == plain


# -- presses ---------------------------------------------------------------------
def test_a_hundred_thousand_presses_at_one_instant_finish_promptly():
    program = program_of("autostart {\n  every 20ms { TC 1 }\n}\n")
    presses = [Press((1, 2, 3, 4), 1000, 1001 + i % 2) for i in range(100_000)]
    start = time.perf_counter()
    result = simulate_program(program, presses=presses, until_ms=3000)
    assert time.perf_counter() - start < 20  # a hang guard: it was 53 s, now well under 1 s
    changes = [(e.input, e.on) for e in result.record.timeline if isinstance(e, ev.InputChanged)]
    assert changes == [(n, True) for n in (1, 2, 3, 4)] + [(n, False) for n in (1, 2, 3, 4)]


def test_changes_at_one_instant_apply_in_the_order_scheduled():
    m = Machine(program_of("[MC00] WA1\n"))
    for i in range(1001):
        m.schedule_input(5, 1, i % 2 == 0)  # on, off, on, ... on: the last one wins
    m.schedule_input(3, 2, True)
    m.power_on()
    m.run_until(10)
    assert m.inputs[1] and m.inputs[2]


# -- the VCD -------------------------------------------------------------------
@pytest.fixture
def files(tmp_path):
    program = tmp_path / "p.mcm"
    program.write_text(SHUTTLE)
    old = tmp_path / "out.vcd"
    old.write_text("the old dump\n")
    return program, old


def no_temp_left(folder) -> bool:
    return glob.glob(os.path.join(folder, ".mercmac-*")) == []


@pytest.mark.parametrize("failure", [KeyboardInterrupt(), OSError(28, "No space left on device")])
def test_a_vcd_that_fails_midway_leaves_the_old_file(files, failure):
    program, old = files
    with mock.patch("mercmac.sim.vcd.VcdObserver.close", side_effect=failure):
        req = sim_run.Request(file=str(program), until="20s", vcd=str(old))
        with pytest.raises(KeyboardInterrupt if isinstance(failure, KeyboardInterrupt)
                           else OutputError):
            sim_run.run(req)
    assert old.read_text() == "the old dump\n"
    assert no_temp_left(old.parent)


def test_a_vcd_replaces_the_old_file_when_complete(files):
    program, old = files
    result = CliRunner().invoke(main, ["sim", str(program), "--until", "3s", "--vcd", str(old)])
    assert result.exit_code == 0, result.output
    assert old.read_text().startswith("$comment mercmac sim") and no_temp_left(old.parent)


def test_the_vcd_path_is_refused_before_simulating(files):
    program, _ = files
    result = CliRunner().invoke(main, ["sim", str(program), "--vcd", os.devnull])
    assert result.exit_code == 2
    assert "Summary" not in result.output and "character device" in result.output


def test_a_vcd_stops_before_its_size_limit_and_says_so(files):
    program, old = files
    result = CliRunner().invoke(main, ["sim", str(program), "--until", "1h", "--vcd", str(old),
                                       "--vcd-limit", "0.2"])
    assert result.exit_code == 0, result.output
    assert "--vcd-limit" in result.output and "Summary" in result.output
    text = old.read_text()
    assert len(text) <= 200_000
    assert text.rstrip().splitlines()[-1].startswith("#")  # closed at a time: a valid file


def test_a_fast_forwarded_day_makes_a_small_vcd(tmp_path):
    program = tmp_path / "blink.mcm"
    program.write_text(BLINK)
    out = tmp_path / "blink.vcd"
    result = CliRunner().invoke(main, ["sim", str(program), "--until", "1d", "--vcd", str(out)])
    assert result.exit_code == 0, result.output
    text = out.read_text()
    assert len(text) < 10_000  # 172,284 LED changes, dumped in full, would be megabytes
    assert "fast_forward" in text
