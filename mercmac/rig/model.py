"""What a rig is: controllers by name, each at its address with its model and program, the
C-170.PB box, the joystick's branches, and wires from output lines to input lines.

A data module: it imports only the foundation, so the simulator, the emulator, the
uploader and the language server all read the same Rig.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping

from mercmac.ops import TextEnum
from mercmac.source import Span


class LineKind(TextEnum):
    """An I/O line of a controller: 4 inputs and 4 outputs (MS176E §4.5.1)."""

    IN = "in"
    OUT = "out"


@dataclass(frozen=True)
class Line:
    """One I/O line: `x.out1` is output 1 of controller x."""

    controller: str
    kind: LineKind
    number: int
    span: Span = field(default=Span(1, 1), compare=False)

    def __str__(self) -> str:
        return f"{self.controller}.{self.kind}{self.number}"


@dataclass(frozen=True)
class Wire:
    """An output line of one controller joined to an input line of another (§4.5.1)."""

    source: Line
    target: Line
    span: Span = field(default=Span(1, 1), compare=False)

    def __str__(self) -> str:
        return f"{self.source} -> {self.target}"


@dataclass(frozen=True)
class Controller:
    """One controller of the chain; `program` is an absolute path; `span` marks its
    [controllers.NAME] header in the rig file."""

    name: str
    address: int
    model: str
    program: str
    span: Span = field(default=Span(1, 1), compare=False)


@dataclass(frozen=True)
class Rig:
    """A rig as its file states it; `joystick` maps a branch ("X", "Y", "Z") to a controller."""

    path: str
    name: str
    controllers: tuple[Controller, ...]
    box: str | None = None
    box_buttons: tuple[int, ...] = (1, 2, 3, 4)
    joystick: Mapping[str, str] = field(default_factory=dict)
    wires: tuple[Wire, ...] = ()

    def controller(self, name: str) -> Controller:
        """The controller called `name`; KeyError if the rig has none."""
        found = next((c for c in self.controllers if c.name == name), None)
        if found is None:
            raise KeyError(name)
        return found

    def by_address(self, address: int) -> Controller | None:
        return next((c for c in self.controllers if c.address == address), None)

    def drivers(self, controller: str, input_n: int) -> list[Wire]:
        """The wires into input `input_n` of `controller`."""
        return [w for w in self.wires
                if w.target.controller == controller and w.target.number == input_n]

    def box_inputs(self, controller: str) -> tuple[int, ...]:
        """The inputs of `controller` that buttons of the box drive (button n on input n)."""
        return self.box_buttons if controller == self.box else ()
