"""One clock for wired machines (vm/wiring.py): `sim RIG` and the virtual chain of
`emulate --rig` step a rig by the same instant rule, so a wired input changes at the same
microsecond in both (once the chain saw x's `WA5,CN1` reach y at 5,001 us, the simulator at
5,000)."""
from __future__ import annotations

from pathlib import Path

import pytest

from helpers.rigs import DEAD_X, X, Y, write_rig
from mercmac.compiler import compile_file
from mercmac.emulator.chain import Chain, Wiring
from mercmac.emulator.virtual import VirtualController
from mercmac.rig.load import read_rig
from mercmac.sim.simulate import simulate
from mercmac.vm import events as ev

UNTIL_MS = 3_000
HANDSHAKE = ("target C-663\nautostart { WA 5, CN 1, WN 2, CF 1 }\n",
             "target C-663\nautostart { WN 1, CN 2, WA 3, CF 2 }\n")
RUNS = {"token passing": (X, Y), "handshake": HANDSHAKE,
        "one waits for good": (DEAD_X, "target C-663\nautostart { WA 2, CN 2, CF 2 }\n")}


def _inputs(events: list) -> list[tuple[int, int, bool]]:
    return [(e.t, e.input, e.on) for e in events if isinstance(e, ev.InputChanged)]


def _simulated(rig, programs) -> dict[str, list]:
    run = simulate(rig, programs, until_ms=UNTIL_MS, fast_forward="off")
    return {name: _inputs(r.record.events) for name, r in run.runs.items()}


def _emulated(rig, programs) -> dict[str, list]:
    made = {c.name: VirtualController(c.model, c.address,
                                      macros={s: m.line for s, m in programs[c.name].macros.items()})
            for c in rig.controllers}
    heard = {name: [] for name in made}
    for name, vc in made.items():
        vc.machine.listeners.append(heard[name].append)
    wires = [Wiring(made[w.source.controller], w.source.number,
                    made[w.target.controller], w.target.number) for w in rig.wires]
    chain = Chain(list(made.values()), wires)
    for now in (0.0015, 0.0049, 0.005, 0.0051, 0.25, UNTIL_MS / 1000):  # ticks, as a server's
        chain.tick(now)
    return {name: _inputs(events) for name, events in heard.items()}


@pytest.mark.parametrize("name", RUNS)
def test_the_simulator_and_the_virtual_chain_change_wired_inputs_at_the_same_instants(
        tmp_path: Path, name: str):
    x, y = RUNS[name]
    rig = read_rig(str(write_rig(tmp_path, x=x, y=y))).rig
    programs = {c.name: compile_file(c.program, target=c.model).program for c in rig.controllers}
    simulated, emulated = _simulated(rig, programs), _emulated(rig, programs)
    assert simulated["y"], "the rig changes no wired input: nothing is compared"
    assert emulated == simulated


def test_an_output_set_at_5_ms_reaches_the_other_controller_at_5_ms(tmp_path: Path):
    rig = read_rig(str(write_rig(tmp_path, x=HANDSHAKE[0], y=HANDSHAKE[1]))).rig
    programs = {c.name: compile_file(c.program, target=c.model).program for c in rig.controllers}
    for seen in (_simulated(rig, programs), _emulated(rig, programs)):
        assert seen["y"][0] == (5_000, 1, True)
