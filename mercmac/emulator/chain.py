"""A daisy chain of virtual controllers on one link (MS176E §3.2), and the wires between them.

Every byte the host writes reaches every controller; each one decides by its own selection
state (§3.1.1, §3.1.3: `\\x01` then its address as one hex digit) whether to take it, so only
the selected controller answers, and a deselected one "ignores any subsequent transmissions
except address selection codes" while its macros keep running (§3.2). Every controller's
machine runs on wall time whether it is selected or not.

Wires join an output line of one controller to an input line of another ("interaxis
communication", §4.5.1): the wired machines advance together by the instant rule of
vm/wiring.py, the one `sim RIG` follows, so a level change is seen by the other controller
at the microsecond it happens, as the simulator shows it, not a server tick later.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Mapping, Sequence

from mercmac import outfile
from mercmac.emulator.faults import Faults
from mercmac.emulator.virtual import StateError, VirtualController
from mercmac.rig.model import Rig
from mercmac.vm.wiring import Wired

US_PER_S = 1_000_000  # the server's clock is in seconds, the VM's in whole us


@dataclass(frozen=True, slots=True)
class End:
    """One end of a wire as the wired clock keys it: a controller's address, a line."""

    controller: int
    number: int


@dataclass(frozen=True, slots=True)
class Link:
    source: End
    target: End


@dataclass(frozen=True, slots=True)
class Wiring:
    """Output `output` (1-4) of `source` drives input `input` (1-4) of `target`."""

    source: VirtualController
    output: int
    target: VirtualController
    input: int

    def link(self) -> Link:
        """This wire as the wired clock keys it: by address (vm/wiring.py)."""
        return Link(End(self.source.address, self.output), End(self.target.address, self.input))


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
        self._wired = Wired({c.address: c.machine for c in controllers},
                            [w.link() for w in self.wires], guard=self._guarded)
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
        """Run the wired machines together, instant by instant, up to `now`."""
        if self.wires:  # else nothing joins them: each runs alone in its own `tick`
            self._wired.run_until(round(now * US_PER_S))

    def _carry(self) -> None:
        """Every wired input takes its outputs' level where the machines stand."""
        if self.wires:
            self._wired.carry(min(c.machine.now_us for c in self.controllers))

    def _guarded(self, address: int, work) -> None:
        """A failure of one controller's firmware stops its macro, not the chain."""
        self.by_address(address).run_safely(work)


def of_one(model: str, address: int, **kw) -> Chain:
    """`emulate --address N`: one controller, a chain of one (its `state` a file)."""
    return Chain([VirtualController(model, address, **kw)])


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
