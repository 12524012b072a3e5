"""Closed sets are types: what started a move, how it ended, how a macro was entered
and left, what a timeline fold is and how the emulator misbehaves are enums declared beside
the code that produces them; their text is what the JSON and the command line say."""
from __future__ import annotations

import ast
import json

import pytest

from mercmac.emulator.faults import EmptySlot, Faults, Framing
from mercmac.sim.record import Fold, Folded
from mercmac.sim.simulate import simulate_program
from mercmac.vm import Machine, Options
from mercmac.vm import events as ev
from mercmac.vm.motion import Ended, Side
from helpers.cli import cli
from helpers.compiling import program_of
from helpers.paths import PACKAGE

# every kind of move, both endings, and a condition of each sort failing
EVERYTHING = """[MC00] MR1000,WS0,FE1,WS0,MR30000,WS0,MR-5000,AB1,WS0,MR-5000,AB,WA10,EM1
[MC01] JN20000,WA3000,JF,EM2
[MC02] XN2,XF3,EM3
[MC03] WA100
"""
FIELDS = ((ev.MoveStarted, "kind", ev.Motion), (ev.MoveEnded, "how", Ended),
          (ev.MacroEntered, "via", ev.Via), (ev.MacroLeft, "why", ev.Exit))


def everything() -> list:
    """The events of a run that starts every kind of move and leaves macros every way."""
    heard = []
    m = Machine(program_of(EVERYTHING), options=Options(hard_limits=(-20_000, 20_000)),
                listeners=[heard.append])
    m.schedule_input(3000, 5, True)  # the joystick tilted: JN drives the axis
    m.schedule_input(3030, 5, False)
    m.power_on()
    m.run_until(10_000)
    m.start_macro(2)  # from the host; input 2 is OFF: XN2 fails
    m.run_until(10_100)
    m.set_input(2, True)
    m.set_input(3, True)
    m.start_macro(2)  # XN2 passes, XF3 fails
    m.run_until(10_200)
    m.start_macro(3)
    m.run_until(10_250)
    m.stop()  # a character from the host (§3.8.3)
    return heard


@pytest.mark.parametrize("event, field, closed", FIELDS, ids=[f[1] for f in FIELDS])
def test_each_closed_field_of_an_event_holds_a_member_of_its_enum(event, field, closed):
    values = [getattr(e, field) for e in everything() if isinstance(e, event)]
    assert values and all(type(v) is closed for v in values), values
    if closed is ev.Exit:
        assert {ev.Exit.END, ev.Exit.STOPPED, ev.Exit.XN2, ev.Exit.XF3} <= set(values)
    else:
        assert set(values) == set(closed)  # and the run made every one of them


def test_a_failed_condition_is_told_from_an_end_or_a_stop_without_reading_its_text():
    assert [e for e in ev.Exit if e.failed] == [*ev.FAILED_XN[1:], *ev.FAILED_XF[1:]]
    assert ev.FAILED_XN[4] is ev.Exit.XN4 and ev.FAILED_XF[6] is ev.Exit.XF6


def test_the_limit_hit_names_its_switch_as_a_side():
    heard = []
    m = Machine(program_of("[MC00] MR50000,WS0\n"), listeners=[heard.append],
                options=Options(hard_limits=(-1000, 5000)))
    m.power_on()
    m.run_until(5000)
    assert m.axis.limit_switch(m.now_us) is Side.POSITIVE
    [ended] = [e for e in heard if isinstance(e, ev.MoveEnded)]
    assert ended.how is Ended.LIMIT


@pytest.mark.parametrize("member", [*ev.Motion, *Ended, *ev.Via, *ev.Exit, *Fold, *Framing,
                                    *EmptySlot], ids=str)
def test_a_member_reads_prints_and_dumps_as_its_text(member):
    assert member == member.value and str(member) == f"{member}" == member.value
    assert json.dumps({"k": member}) == json.dumps({"k": member.value})


def test_timeline_folds_are_of_a_fold_kind():
    run = simulate_program(program_of("[MC00] EM1,WA10,RP\n[MC01] XN1\n"), until_ms=200)
    folds = [f for f in run.record.timeline if isinstance(f, Folded)]
    assert {f.kind for f in folds} >= {Fold.START, Fold.POLL}
    assert all(type(f.kind) is Fold for f in folds)
    assert all(type(k) is Fold for k in run.record.unlisted)


def test_faults_given_by_their_text_become_members_and_unknown_ones_fail():
    faults = Faults(tm_framing="one-etx", empty_slot="bare")
    assert faults.tm_framing is Framing.ONE_ETX and faults.empty_slot is EmptySlot.BARE
    with pytest.raises(ValueError):
        Faults(tm_framing="two-etx")


def test_emulate_offers_exactly_the_faults_the_enums_name():
    shown = cli("emulate", "--help").output
    assert f"[{'|'.join(Framing)}]" in shown and f"[{'|'.join(EmptySlot)}]" in shown


# -- no reader compares a closed field with text ------------------------------------------

CLOSED = {"kind", "how", "why", "via", "tm_framing", "empty_slot"}
READERS = sorted([*(PACKAGE / "vm").glob("*.py"), *(PACKAGE / "sim").glob("*.py"),
                  *(PACKAGE / "emulator").glob("*.py"), PACKAGE / "render" / "sim.py"])


def _text_reads(tree: ast.AST) -> list[int]:
    """Lines that compare a closed field with a string or slice it (`why[:2]`)."""
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Compare):
            sides = [node.left, *node.comparators]
            closed = any(isinstance(s, ast.Attribute) and s.attr in CLOSED for s in sides)
            texts = [s for s in sides if isinstance(s, ast.Constant) and isinstance(s.value, str)]
            texts += [e for s in sides if isinstance(s, (ast.Tuple, ast.List, ast.Set))
                      for e in s.elts if isinstance(e, ast.Constant) and isinstance(e.value, str)]
            if closed and texts:
                found.append(node.lineno)
        elif isinstance(node, ast.Subscript) and isinstance(node.value, ast.Attribute) \
                and node.value.attr in CLOSED and isinstance(node.slice, ast.Slice):
            found.append(node.lineno)
    return found


@pytest.mark.parametrize("path", READERS, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_closed_fields_are_matched_as_members_not_read_as_text(path):
    assert _text_reads(ast.parse(path.read_text(encoding="utf-8"))) == []


def test_the_scan_sees_a_text_comparison_and_a_slice():
    tree = ast.parse("if e.how == 'arrived' or e.why[:2] in ('XN', 'XF'): pass\n")
    assert len(_text_reads(tree)) == 2
