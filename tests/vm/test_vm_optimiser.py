"""The interpreter and its fast-forward optimiser are two things; the
state key comes from field marks; shapes are typed records walked by vm/shapes.py; the
modes, the wait, the return point and a hazard's place are types."""
from __future__ import annotations

import ast
import dataclasses

import pytest

from helpers.compiling import program_of
from helpers.paths import PACKAGE
from mercmac.vm import Machine
from mercmac.vm import events as ev
from mercmac.vm import shapes
from mercmac.vm.machine import Blocked, Return, Wait
from mercmac.vm.motion import Axis
from mercmac.vm.trigger import Trigger
from mercmac.vm.optimiser import FastForward, Optimiser
from mercmac.vm.statekey import key, keyed, part, unkeyed

ITEMS = (shapes.Report, shapes.Outputs, shapes.Skip, shapes.Shifted, shapes.Placed,
         shapes.Absolute, shapes.Move, shapes.Arrive)
# every 50ms a report and 20 blinks; scans of 50 steps, each showing its position and
# blinking; a step there and back that shows the target and the switches
LOOPS = ("autostart {\n  every 50ms { TT, repeat 20 { CN 1, WA 1, CF 1 } }\n}\n",
         "[MC00] EM1,WA100,RP,RP\n[MC01] MR3,WS0,TP,CN2,WA2,CF2,RP50\n",
         "autostart {\n  every 10ms { MR 1, WS 0, MR -1, WS 0, TT, TS }\n}\n")


def skips(text: str, until_ms: int = 60_000) -> list[ev.FastForwarded]:
    seen = []
    m = Machine(program_of(text), fast_forward="all", on_event=seen.append)
    m.power_on()
    m.run_until(until_ms)
    return [e for e in seen if isinstance(e, ev.FastForwarded)]


# -- the optimiser is the machine's collaborator, not its handlers' bookkeeping ----------

def test_the_instruction_handlers_keep_no_fast_forward_record():
    tree = ast.parse((PACKAGE / "vm" / "machine.py").read_text(encoding="utf-8"))
    names = {n.attr for n in ast.walk(tree) if isinstance(n, ast.Attribute)}
    names |= {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}
    assert not names & {"_log", "_log_base", "_horizon", "Mark", "Visit", "waits"}
    m = Machine(program_of("[MC00] TP,WA10,RP5\n"))
    assert isinstance(m.optimiser, Optimiser) and not {"_log", "waits"} & set(vars(m))


def test_the_optimiser_hears_the_hooks_and_keeps_the_log():
    m = Machine(program_of("[MC00] CN1,WA10,CF1,WA10,RP\n"), fast_forward="quiet")
    m.power_on()
    m.run_until(25)
    assert m.optimiser.waits == 3 and m.optimiser.horizon == 25_000
    assert [type(e) for e in m.optimiser.log] == [ev.OutputsChanged] * 3
    m.set_input(2, True)
    assert m.optimiser.inputs == 1


# -- the state key comes from the fields' marks -------------------------------------------

def test_the_machine_and_its_parts_are_marked_dataclasses():
    for cls in (Machine, type(Machine().axis), type(Machine().trigger),
                type(Machine().outputs), type(Machine().clock)):
        marked = {f.name: f.metadata["key"] for f in dataclasses.fields(cls)}
        assert cls.STATE_KEY == tuple(name for name, keyed_ in marked.items() if keyed_)
        assert set(cls.NOT_KEYED) == {name for name, keyed_ in marked.items() if not keyed_}


def test_a_field_without_a_mark_is_refused_when_the_class_is_made():
    with pytest.raises(TypeError, match=r"mark \['backlash'\]"):
        @keyed()
        @dataclasses.dataclass
        class Part:
            steps: int = key(default=0)
            backlash: int = 0
    with pytest.raises(ValueError, match="reason"):
        unkeyed(" ")


def test_a_key_is_generated_from_the_marks_with_parts_and_shifts():
    @keyed()
    @dataclasses.dataclass
    class Inner:
        a: int = key(default=1)
        b: int = key(default=2, shifts=True)

    @keyed()
    @dataclasses.dataclass
    class Outer:
        x: dict = key(lambda d: tuple(d), default_factory=dict)
        inner: Inner = part(shifts=Inner.unshifted, default_factory=Inner)
        note: str = unkeyed("not state", default="")

    outer = Outer({"k": 0})
    assert outer.state_key() == (("k",), (1, 2)) and Outer.unshifted(outer.state_key()) == (("k",), 1)


def test_the_machines_shift_key_leaves_out_positions_targets_and_profiles_only():
    # the profile (segs and the plan it came from) is keyed relative to the time and the
    # target while the axis moves (Axis.relative), and is () and None at rest
    m = Machine(program_of("[MC00] MR5,WS0,WA10,RP\n"))
    m.power_on()
    m.run_until(50)
    whole, shifted = m._state_key(None), m.unshifted(m._state_key(None))
    at = Machine.STATE_KEY.index("axis")
    shifting = {"segs", "plan", "final", "target"}
    axis = [v for name, v in zip(Axis.STATE_KEY, whole[at]) if name not in shifting]
    expected = list(whole[:at] + (tuple(axis),) + whole[at + 1:])
    # and the trigger's next position, keyed relative to the target (Trigger.relative)
    trigger = Machine.STATE_KEY.index("trigger")
    expected[trigger] = tuple(v for name, v in zip(Trigger.STATE_KEY, whole[trigger])
                              if name != "next_at")
    assert shifted == tuple(expected)


# -- shapes are typed records, walked by vm/shapes.py --------------------------------------

def flatten(shape: tuple):
    for item in shape:
        yield item
        if isinstance(item, (shapes.Skip, shapes.Shifted)):
            yield from flatten(item.shape)


def test_every_shape_item_is_a_named_record_with_its_tag():
    items = [item for text in LOOPS for skip in skips(text) for item in flatten(skip.shape)]
    assert {type(item) for item in items} == set(ITEMS)
    assert all(item.tag.name == type(item).__name__.upper() for item in items)


def test_items_of_two_kinds_never_compare_equal():
    assert shapes.Outputs(shapes.Tag.OUTPUTS, 5, 3) != shapes.Arrive(shapes.Tag.ARRIVE, 5, 3)


def test_compact_gives_the_stretches_and_the_last_passes_output_changes():
    blink = (shapes.Outputs(shapes.Tag.OUTPUTS, 0, 1), shapes.Outputs(shapes.Tag.OUTPUTS, 5, 0))
    shape = (shapes.Skip(shapes.Tag.SKIP, 10, 3, 20, blink, None),)
    assert list(shapes.compact(shape, 1000, 100, 4)) == [
        shapes.Stretch(1000, 1300, 4), shapes.Stretch(1310, 1350, 3),
        ev.OutputsChanged(1350, 1), ev.OutputsChanged(1355, 0)]
    assert [e.t for e in shapes.expand(shape, 1000, 100, 2, shapes.OUTPUTS)] == [
        1010, 1015, 1030, 1035, 1050, 1055, 1110, 1115, 1130, 1135, 1150, 1155]


# -- closed sets are types ------------------------------------------------------------

def test_fast_forward_modes_are_an_enum_that_reads_as_its_text():
    assert [m.value for m in FastForward] == ["off", "quiet", "all"]
    assert Machine(fast_forward="all").optimiser.mode is FastForward.ALL
    assert Machine(fast_forward=FastForward.OFF).optimiser.mode is FastForward.OFF
    with pytest.raises(ValueError, match="'sometimes'"):
        Machine(fast_forward="sometimes")


def test_a_blocked_wait_and_the_return_point_are_records():
    m = Machine(program_of("[MC00] EM1\n[MC01] WN3\n"))
    m.power_on()
    m.run_until(5)
    assert m.block == Blocked(Wait.WN, 3, 1000) and m.ret == Return(m.chunks[0], 1)
    assert not m.block.ended_by(3, False) and m.block.ended_by(3, True)
    m.set_input(3, True)
    assert m.block is None
