"""Reports read a snapshot of the machine, not the machine: vm/reports.py formats
from `Machine.snapshot()`, a record of values at one instant, and from nothing else."""
from __future__ import annotations

import ast

import pytest

from mercmac.commands import C663, C863, COMMANDS, Kind
from mercmac.vm import Machine, Options, reports
from mercmac.vm.motion import Side
from mercmac.vm.reports import Snapshot
from helpers.compiling import program_of
from helpers.paths import PACKAGE

REPORTS = sorted(m for m, c in COMMANDS.items() if c.kind is Kind.REPORT)


def snapshot(**changes) -> Snapshot:
    """A machine at rest at 5555 with buttons 1 and 3 held, running a macro."""
    values = dict(
        model=C863, address=3, firmware="2.30", position=5555.0, velocity=0.0, target=5555,
        moving=False, sv=45000, sa=400000, iteration=7,
        settings={"JH": 250000, "ZM": 2, "DP": 12}, inputs=(False, True, False, True, False,
                                                            False, False),
        buttons=0b0101, macros={0: "EM1", 1: "MR100,TP"}, macro_running=True, error=0x07,
        referenced=True, servo=True, negative=False, homing=False, joystick=False, brake=True,
        limits_on=True, limits_high=True, reference_high=False, limit=Side.POSITIVE)
    return Snapshot(**values | changes)


class Held:
    """Anything that can give a snapshot: all that reports ask of a machine."""

    def __init__(self, taken: Snapshot):
        self.taken = taken

    def snapshot(self) -> Snapshot:
        return self.taken


@pytest.mark.parametrize("mnemonic, arg, text", [
    ("TP", None, "P:+0000005555"), ("TE", None, "E:+0000000000"), ("TI", None, "X:+0000000007"),
    ("TC", 0, "H00:5"), ("TC", 2, "H02:0"), ("TA", 3, "A3:255"), ("TB", None, "B:3"),
    ("JH?", None, "JH:+250000"), ("ZM?", None, "ZM:2"), ("GP", None, "G:+0000000012"),
    ("TM", None, "MC001 MR100,TP"), ("TZ", None, "MC000 EM1"),
    ("TS", None, "S:0C 12 00 0B 54 07")])
def test_a_report_is_formatted_from_the_snapshot_alone(mnemonic, arg, text):
    assert reports.report(mnemonic, arg, Held(snapshot())) == text


def test_ts_of_the_c663_reads_the_same_snapshot():
    assert reports.status(Held(snapshot(model=C663))) == "S:52 54 07"


def test_a_snapshot_keeps_its_values_while_the_machine_goes_on():
    m = Machine(program_of("[MC00] MR5000,WS0,DP3,CN1\n"))
    m.power_on()
    m.run_until(2)
    taken = m.snapshot()
    before = reports.report("TP", None, Held(taken)), reports.report("GP", None, Held(taken))
    m.run_until(5000)
    m.define(5, program_of("[MC05] TP\n").macros[5].ops)
    assert (reports.report("TP", None, Held(taken)), reports.report("GP", None, Held(taken))) \
        == before != (reports.report("TP", None, m), reports.report("GP", None, m))
    assert 5 not in taken.macros and taken.moving and not m.moving()


@pytest.mark.parametrize("model", [C663, C863])
def test_every_report_of_a_machine_is_that_of_its_snapshot(model):
    m = Machine(program_of("[MC00] MR5000,WS0,JH90000,ZM1,CN2,WA5\n[MC03] TP\n"), model=model,
                options=Options(hard_limits=(-1000, 4000), address=2))
    m.schedule_input(10, 2, True)
    m.power_on()
    m.run_until(30)
    for mnemonic in REPORTS:
        if model in COMMANDS[mnemonic].models:
            assert reports.report(mnemonic, 1, m) == reports.report(mnemonic, 1, Held(m.snapshot()))


def test_reports_know_no_machine():
    tree = ast.parse((PACKAGE / "vm" / "reports.py").read_text(encoding="utf-8"))
    imported = {node.module for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)}
    assert "mercmac.vm.machine" not in imported
    assert not {node.attr for node in ast.walk(tree) if isinstance(node, ast.Attribute)} & \
        {"axis", "clock", "trigger", "chunks", "params", "stored_macros", "setting"}
