"""The machine tells a list of listeners: a plot, a VCD and the recorder each hear
every event from the machine itself, in order, none of them passing events on to the next."""
from __future__ import annotations

import inspect
import io

from mercmac.sim import plot, vcd
from mercmac.rig.model import Rig
from mercmac.sim.simulate import machine_for, simulate, simulate_program
from mercmac.vm import Machine
from mercmac.vm import events as ev
from helpers.compiling import program_of

BLINK = "[MC00] CN1,WA10,CF1,TP,WA10,RP3\n"


def test_every_listener_hears_every_event_in_the_order_given():
    heard = []
    m = Machine(program_of(BLINK), listeners=[lambda e: heard.append(("a", e)),
                                              lambda e: heard.append(("b", e))])
    m.power_on()
    m.run_until(200)
    assert len(heard) > 10
    assert [who for who, _ in heard] == ["a", "b"] * (len(heard) // 2)
    assert [e for who, e in heard if who == "a"] == [e for who, e in heard if who == "b"]


def test_a_listener_added_later_hears_what_happens_from_then_on():
    early, late = [], []
    m = Machine(program_of(BLINK), listeners=[early.append])
    m.power_on()
    m.run_until(15)
    m.listeners.append(late.append)
    m.run_until(200)
    assert late and early[-len(late):] == late and len(early) > len(late)


def test_setting_on_event_makes_it_the_only_listener():
    first, second = [], []
    m = Machine(program_of(BLINK), listeners=[first.append])
    m.on_event = second.append
    m.power_on()
    m.run_until(100)
    assert first == [] and second


def test_the_recorder_hears_after_the_listeners_given_before_it():
    seen_before = []
    machine, record = machine_for(program_of(BLINK), listeners=[
        lambda e: seen_before.append(record.events[-1:] != [e])])
    machine.power_on()
    machine.run_until(100)
    assert seen_before and all(seen_before)  # the recorder had not heard it yet


def test_a_plot_and_a_vcd_hear_each_event_from_the_machine_not_from_each_other():
    class Watch:
        def __init__(self):
            self.heard = []

        def on_event(self, event):
            self.heard.append(event)

    watch = Watch()
    dump = vcd.Dump(io.StringIO(), ["program"])
    run = simulate(Rig.of_program("program.mcm"), {"program": program_of(BLINK)}, until_ms=200,
                   listeners={"program": [watch.on_event, *dump.listeners()["program"]]}).only
    assert watch.heard == run.record.events and run.record.events
    assert not hasattr(watch, "then")  # nobody chained the next listener to it
    for listener in (plot.PlotObserver, vcd.VcdObserver):
        assert "then" not in inspect.signature(listener).parameters
    assert isinstance(watch.heard[0], ev.MacroEntered)
