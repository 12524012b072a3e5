"""`check`'s sure dead-lock on an input nothing drives (MR011, mercmac/rig/checks.py) against
the rig simulator (MH008, sim/rig_deadlock.py): on random programs of two wired
controllers, whenever `check` says the rig dead-locks for sure, `sim` finds the dead-lock."""
from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, assume, event, given, settings
from hypothesis import strategies as st

from helpers.budgets import budget
from helpers.rigs import rig_of
from mercmac.compiler import checking, compile_file
from mercmac.rig.open import open_rig
from mercmac.rig.load import read_rig
from mercmac.sim.simulate import simulate

WIRES = '"x.out1 -> y.in1", "y.out2 -> x.in2"'
OPS = ["WN1", "WN2", "WN3", "WN4", "WF2", "WF3", "CN1", "CN2", "CF1", "CF2", "WA3", "XN3",
       "XN1", "EM1", "RP2", "TP", "MR5", "WS0"]
macros = st.lists(st.sampled_from(OPS), min_size=1, max_size=5).map(",".join)
boxes = st.sampled_from(["", 'box = "x"\nbox_buttons = [3]\n', 'box = "y"\n'])


def sure_dead_lock(path: Path) -> bool | None:
    """Whether `check` reports a sure dead-lock on an undriven input; None: check errors."""
    found = [d for f in open_rig(str(path), checking.options()).findings for d in f.diagnostics]
    if any(d.severity.name == "ERROR" for d in found):
        return None
    return any(d.rule.code == "MR011" and d.message.startswith("dead-lock:") for d in found)


def simulated_dead_lock(path: Path) -> bool:
    rig = read_rig(str(path)).rig
    programs = {c.name: compile_file(c.program, target=c.model).program for c in rig.controllers}
    result = simulate(rig, programs, until_ms=60_000)
    return any(h.rule == "rig-deadlock" for r in result.runs.values() for h in r.record.hazards)


@pytest.mark.slow
@settings(max_examples=budget(150), deadline=None,
          suppress_health_check=[HealthCheck.too_slow])
@given(macros, macros, macros, macros, boxes)
def test_a_sure_dead_lock_that_check_reports_is_one_the_simulator_finds(x0, x1, y0, y1, box):
    folder = Path(tempfile.mkdtemp())
    try:
        path = rig_of(folder, f"[MC00] {x0}\n[MC01] {x1}\n", f"[MC00] {y0}\n[MC01] {y1}\n",
                      WIRES, box)
        sure = sure_dead_lock(path)
        assume(sure is not None)
        event(f"sure dead-lock: {sure}")
        if sure:
            assert simulated_dead_lock(path)
    finally:
        shutil.rmtree(folder)


def test_the_issues_rig_is_a_sure_dead_lock_for_both(tmp_path):
    path = rig_of(tmp_path, "autostart { WN 3, CN 1 }\n", "autostart { WN 1, CN 2 }\n", WIRES)
    assert sure_dead_lock(path) and simulated_dead_lock(path)
