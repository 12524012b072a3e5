"""What a rig is: controllers by name, each at its address with its model and program, the
C-170.PB box, the joystick's branches, and wires from output lines to input lines.

A data module: it imports only the foundation, so the simulator, the emulator, the
uploader and the language server all read the same Rig.
"""
from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from typing import Mapping

from mercmac.commands import C863
from mercmac.ops import TextEnum
from mercmac.source import Span

# The longest name of a controller or a rig: names become parts of file names (backups,
# pulled programs), and a file name of 255 bytes or more is refused by the file system.
NAME_MAX = 64
PATH_BRANCHES = ("X", "Y", "Z")  # the joystick's branches name the path's axes (§3.6)


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
    """A rig as its file states it; `joystick` maps a branch ("X", "Y", "Z") to a controller.
    `lone`: the rig of one that a lone program stands for (Rig.of_program), not a rig file."""

    path: str
    name: str
    controllers: tuple[Controller, ...]
    box: str | None = None
    box_buttons: tuple[int, ...] = (1, 2, 3, 4)
    joystick: Mapping[str, str] = field(default_factory=dict)
    wires: tuple[Wire, ...] = ()
    lone: bool = False

    @classmethod
    def of_program(cls, program: str, model: str | None = None, address: int = 0) -> Rig:
        """The rig a lone program stands for where a rig may go (docs/rigs.md, "A program
        is a rig of one"): one controller running it at `address`, of `model` (default the
        C-863, as the simulator's), with the C-170.PB box and the joystick on it, no wires."""
        name = name_from(os.path.splitext(os.path.basename(program))[0])
        controller = Controller(name, address, (model or C863).upper(), program)
        return cls(program, name, (controller,), box=name, joystick={"X": name}, lone=True)

    @property
    def several(self) -> bool:
        """Whether the rig has more than one controller: only then are they named in what
        mercmac shows of it (a rig of one shows as its program does)."""
        return len(self.controllers) > 1

    def path_axes(self) -> tuple[str, ...]:
        """The controllers whose positions draw the stage's path (X, Y and maybe Z): the
        joystick's branches when it names two or more, else the controllers in the rig's
        order when there are two or three; none otherwise."""
        named = tuple(self.joystick[b] for b in PATH_BRANCHES if b in self.joystick)
        if len(named) >= 2:
            return named
        names = tuple(c.name for c in self.controllers)
        return names if 2 <= len(names) <= 3 else ()

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

    def by_hand(self, controller: str) -> tuple[int, ...]:
        """The inputs of `controller` a person drives: the box's buttons, and the joystick's
        input and button (5, 6) where a joystick branch goes (MS176E §6.4 XN)."""
        stick = (5, 6) if controller in self.joystick.values() else ()
        return self.box_inputs(controller) + stick


def name_from(text: str) -> str:
    """A name (rig.load.is_name: a word of ASCII letters, digits and '_' that does not start
    with a digit) made from TEXT, a file's or folder's name: 'my rig' -> 'my_rig',
    '2026' -> '_2026', '' -> 'rig'."""
    name = re.sub(r"[^A-Za-z0-9_]+", "_", text).strip("_")[:NAME_MAX] or "rig"
    return f"_{name[:NAME_MAX - 1]}" if name[0].isdigit() else name
