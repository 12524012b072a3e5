"""A daisy chain of virtual controllers on one link (MS176E §3.2), and the wires between them.

Every byte the host writes reaches every controller; each one decides by its own selection
state (§3.1.1, §3.1.3: `\\x01` then its address as one hex digit) whether to take it, so only
the selected controller answers, and a deselected one "ignores any subsequent transmissions
except address selection codes" while its macros keep running (§3.2). Every controller's
machine runs on wall time whether it is selected or not.

Wires join an output line of one controller to an input line of another ("interaxis
communication", §4.5.1): the machines advance together from event to event, and after each
step every wired input takes its driving output's level at that instant, so a level change
is seen by the other controller at the time it happens, not a server tick later.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Mapping, Sequence

from mercmac import outfile
from mercmac.emulator.faults import Faults
from mercmac.emulator.virtual import StateError, VirtualController
from mercmac.rig.model import Rig

EPSILON_MS = 0.001  # 1 us, the VM's unit: run *through* an event, not just up to it


@dataclass(frozen=True, slots=True)
class Wiring:
    """Output `output` (1-4) of `source` drives input `input` (1-4) of `target`."""

    source: VirtualController
    output: int
    target: VirtualController
    input: int

    def level(self) -> bool:
        """The driving output's level now (bit 0 = output 1, §6.4 CP)."""
        return bool(self.source.machine.outputs_pattern() >> (self.output - 1) & 1)


class Chain:
    """Controllers on one link: the server feeds bytes to all, each answers only when selected."""

    def __init__(self, controllers: Sequence[VirtualController],
                 wires: Sequence[Wiring] = (), names: Mapping[int, str] | None = None):
        addresses = [c.address for c in controllers]
        if not controllers or len(set(addresses)) != len(addresses):
            raise ValueError(f"a chain needs distinct addresses, not {addresses}")
        self.controllers = tuple(controllers)
        self.wires = tuple(wires)
        self.names = dict(names or {})  # address -> the rig's name, for the log
        self.parts: list[tuple[int, bytes]] = []  # the last `take`, by who sent it
        self._carry()  # outputs are off at power-on: wired inputs start low

    @property
    def vanished(self) -> bool:
        return any(c.vanished for c in self.controllers)

    def by_address(self, address: int) -> VirtualController | None:
        return next((c for c in self.controllers if c.address == address), None)

    def selected(self) -> list[VirtualController]:
        return [c for c in self.controllers if c.selected]

    def label(self, address: int) -> str:
        """How the log names a controller: its address, and its rig name if it has one."""
        name = self.names.get(address)
        return f"{address} ({name})" if name else str(address)

    def receive(self, data: bytes, now: float) -> None:
        """Bytes the host wrote at `now`: every controller hears them (§3.2)."""
        self._advance(now)
        for c in self.controllers:
            c.receive(data, now)
        self._carry()

    def tick(self, now: float) -> None:
        """Let every controller run to wall time `now` (seconds since power-on)."""
        self._advance(now)
        for c in self.controllers:
            c.tick(now)
        self._carry()

    def take(self) -> bytes:
        """What goes to the host; `parts` keeps who said it (two at once is a collision)."""
        self.parts = [(c.address, data) for c in self.controllers if (data := c.take())]
        return b"".join(data for _, data in self.parts)

    def _advance(self, now: float) -> None:
        """Run the wired machines together from event to event up to `now`, carrying the
        output levels across after each, so a wired input changes when its output does."""
        if not self.wires:
            return  # nothing joins them: each runs alone in its own `tick`
        end_ms, done = now * 1000, -1.0
        while (t := min(c.machine.next_event_ms() for c in self.controllers)) < end_ms:
            done = max(t, done) + EPSILON_MS  # always forward, whatever a machine reports
            for c in self.controllers:
                c.advance(done)
            self._carry()

    def _carry(self) -> None:
        """Every wired input takes its outputs' level, set once: an input that two outputs
        drive (`check` refuses such a rig) is ON while either is, never toggled in between."""
        levels: dict[tuple[VirtualController, int], bool] = {}
        for wire in self.wires:
            key = (wire.target, wire.input)
            levels[key] = levels.get(key, False) or wire.level()
        for (target, n), on in levels.items():
            target.machine.set_input(n, on)


def at_addresses(addresses: Sequence[int], model: str, *, firmware: str = "2.30",
                 faults: Faults | None = None, state: Path | None = None) -> Chain:
    """`emulate --addresses 0,1,2`: one controller of `model` at each address; with a
    state folder, each keeps its macros in ADDRESS.json there."""
    folder = state_folder(state) if state else None
    return Chain([VirtualController(model, a, firmware=firmware, faults=replace(faults or Faults()),
                                    state=folder / f"{a}.json" if folder else None)
                  for a in addresses])


def state_folder(path: Path) -> Path:
    """The folder of a chain's state files (one per controller), made if its parent exists;
    a file there is refused before serving, and left as it is."""
    if path.exists() and not path.is_dir():
        raise StateError(f"--state: {path} is a file; a chain keeps one state file per "
                         "controller in a folder", hint="give a folder (it is created if missing)")
    try:
        path.mkdir(exist_ok=True)
    except OSError as e:
        raise StateError(f"--state: cannot make the folder {path}: {outfile.reason(e)}",
                         hint="give a folder in one that exists and can be written") from None
    return path


def for_rig(rig: Rig, *, firmware: str = "2.30", faults: Faults | None = None,
            state: Path | None = None) -> Chain:
    """`emulate --rig RIG`: each controller at its address with its model, empty (or with
    its macros from NAME.json in the state folder), and the rig's wires live between them.
    The box and the joystick stay unplugged: nothing presses them on a pty."""
    folder = state_folder(state) if state else None
    made = {c.name: VirtualController(c.model, c.address, firmware=firmware,
                                      faults=replace(faults or Faults()),
                                      state=outfile.in_folder(folder, f"{c.name}.json")
                                      if folder else None)  # a name, never a path
            for c in rig.controllers}
    wires = [Wiring(made[w.source.controller], w.source.number,
                    made[w.target.controller], w.target.number) for w in rig.wires]
    return Chain(list(made.values()), wires, {c.address: c.name for c in rig.controllers})
