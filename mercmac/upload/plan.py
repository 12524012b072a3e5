"""The upload plan: which slots to write or erase, in an order safe against power cuts.

Write only what differs (docs/uploader.md, "A flash, step by step"); when anything
changes while an autostart macro exists, remove macro 0 first (`RZ`) and write it last, so
a power cut mid-flash never autostarts a half-written program (MS176E §3.8.5).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum

from mercmac import mdtext
from mercmac.compiler.program import Program
from mercmac.upload import protocol


class Action(str, Enum):
    """What one step does to one slot."""

    PARK = "park"  # RZ before anything else; macro 0 comes back last
    WRITE = "write"  # MDn,... then read back
    ERASE = "erase"  # RMn / RZ then read back


@dataclass(frozen=True, slots=True)
class Step:
    """One write or erase, with the line that goes out and the content expected after."""

    action: Action
    slot: int
    name: str
    line: str | None = None  # the macro body for WRITE

    @property
    def wire(self) -> str:
        """The command line sent, without CR."""
        if self.action is Action.WRITE:
            return mdtext.md(self.slot, self.line)
        return mdtext.remove(self.slot)

    @property
    def describe(self) -> str:
        """'write MC05', 'erase MC07', 'remove the autostart macro MC00 first'."""
        if self.action is Action.PARK:
            # the program's label of macro 0 may already say so: 'autostart (MC00)'
            what = self.name if "autostart" in self.name else f"the autostart macro {self.name}"
            return f"remove {what} first"
        return f"{self.action.value} {self.name}"

    @property
    def expected(self) -> str | None:
        """The slot's contents after the step: the line, or None (empty)."""
        return self.line if self.action is Action.WRITE else None

    @property
    def readback(self) -> str:
        """The command that reads the slot back (`TM0` would list all but 0)."""
        return mdtext.tell(self.slot)


class Fate(str, Enum):
    """What happens to a slot, for the summary table."""

    WRITTEN = "written"
    UNCHANGED = "unchanged"
    RESTORED = "re-written last"  # macro 0 unchanged, parked during the flash
    ERASED = "erased"
    KEPT = "kept (not in file)"


@dataclass(slots=True)
class Plan:
    """Steps in order, the fate of every slot involved, and the state they lead to."""

    steps: list[Step]
    fates: dict[int, Fate]
    names: dict[int, str]
    before: dict[int, str]
    after: dict[int, str] = field(default_factory=dict)

    @property
    def changes_nothing(self) -> bool:
        return not self.steps


def make_plan(program: Program, stored: dict[int, str], *, erase_unused: bool = False) -> Plan:
    """Compare the program with what the controller holds and order the steps."""
    wanted = {slot: m.line for slot, m in program.macros.items()}
    names = {slot: m.label for slot, m in program.macros.items()}
    after = {s: t for s, t in stored.items() if not erase_unused} | wanted
    fates = {s: _fate(s, wanted, stored, erase_unused) for s in sorted(wanted.keys() | stored.keys())}
    others = [_step(s, fates[s], after, names) for s in sorted(fates) if s != 0]
    others = [step for step in others if step]
    steps, changes_zero = [], fates.get(0) in (Fate.WRITTEN, Fate.ERASED)
    if 0 in stored and (changes_zero or others):
        steps.append(Step(Action.PARK, 0, names.get(0, mdtext.slot_name(0))))
        if fates[0] in (Fate.UNCHANGED, Fate.KEPT):
            fates[0] = Fate.RESTORED
    steps += others
    if 0 in after and (0 not in stored or steps):
        steps.append(Step(Action.WRITE, 0, names.get(0, mdtext.slot_name(0)), after[0]))
    return Plan(steps, fates, names, dict(stored), after)


def _fate(slot: int, wanted: dict[int, str], stored: dict[int, str], erase_unused: bool) -> Fate:
    if slot not in wanted:
        return Fate.ERASED if erase_unused else Fate.KEPT
    same = protocol.same_macro(wanted[slot], stored.get(slot))
    return Fate.UNCHANGED if same else Fate.WRITTEN


def _step(slot: int, fate: Fate, after: dict[int, str], names: dict[int, str]) -> Step | None:
    name = names.get(slot, mdtext.slot_name(slot))
    if fate is Fate.WRITTEN:
        return Step(Action.WRITE, slot, name, after[slot])
    if fate is Fate.ERASED:
        return Step(Action.ERASE, slot, name)
    return None
