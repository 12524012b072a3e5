"""A rig in plain words: which controller does what, each program described
as `describe` describes one (mercmac.decompile.prose) under its controller's name and
address, what each wire carries (the macros that set its output and those that wait on or
read its input, MS176E §4.5.1 "interaxis communication"), and one call graph with a
cluster per controller and the wires as edges between the clusters. A rig of one (a lone
program) is its program described, as the controllers are named only where there are
several."""
from __future__ import annotations

import json
import os
from typing import Mapping, NamedTuple

from mercmac.commands import Mnemonic
from mercmac.mdtext import slot_name
from mercmac.decompile.prose import (Reader, call_graph_dot, describe, described, dot_body,
                                      mermaid_body)
from mercmac.names import dot, markdown, mermaid, printable
from mercmac.render.sim import plural

# What a command does to the line it names (§6.4: CN/CF/CP set outputs 1-4; WN/WF wait on
# an input, XN/XF run the rest of the line only while it is on/off).
_SETS = {Mnemonic.CN: "turns it on", Mnemonic.CF: "turns it off"}
_READS = {Mnemonic.WN: "waits until it is on", Mnemonic.WF: "waits until it is off",
          Mnemonic.XN: "goes on only while it is on", Mnemonic.XF: "goes on only while it is off"}


class Stored(NamedTuple):
    """One controller's program as it would be stored: macros by slot, model, the source's
    names; and words for its wired lines (filled in from the rig, `_wired`)."""

    macros: dict[int, str]
    model: str | None
    names: dict[int, str]
    inputs: dict[int, str] = {}
    outputs: dict[int, str] = {}
    box: bool = True  # the C-170.PB box is on its I/O socket: inputs are buttons, outputs LEDs


class Touch(NamedTuple):
    """A macro that sets or reads a wired line, and how."""

    controller: str
    slot: int
    label: str  # 'sweep (MC01)'
    how: str  # 'turns it on'


def describe_rig(rig, programs: Mapping[str, Stored], fmt: str = "text") -> str:
    """The rig in words; `programs`: each controller's Stored program by controller name."""
    if not rig.several:
        return _described_as(programs[rig.controllers[0].name], fmt)
    programs = _wired(rig, programs)
    readers = {c.name: Reader(*programs[c.name]) for c in rig.controllers}
    if fmt == "json":
        return json.dumps(_data(rig, programs, readers), indent=2, ensure_ascii=False) + "\n"
    if fmt == "markdown":
        return _markdown(rig, programs, readers)
    if fmt != "text":
        raise ValueError(f"unknown format {fmt!r}: text, markdown or json")
    return _text(rig, programs, readers)


def _wired(rig, programs: Mapping[str, Stored]) -> dict[str, Stored]:
    """`programs` with words for each wired line: a program waits on 'input 2 (from
    y.out2)' and sets 'output 1 (to y.in1)', not a button or LED of a box not there."""
    out = {}
    for c in rig.controllers:
        inputs = {w.target.number: f"input {w.target.number} (from {w.source})"
                  for w in rig.wires if w.target.controller == c.name}
        outputs: dict[int, str] = {}
        for w in rig.wires:
            if w.source.controller == c.name:
                outputs.setdefault(w.source.number, f"output {w.source.number} (to")
                outputs[w.source.number] += f" {w.target}"
        out[c.name] = programs[c.name]._replace(
            inputs=inputs, outputs={n: f"{text})" for n, text in outputs.items()},
            box=rig.box == c.name)
    return out


def _title(rig) -> str:
    return (f"rig {rig.name}: {plural(len(rig.controllers), 'controller')} on one link "
            f"({os.path.basename(rig.path)})")


def _heading(controller) -> str:
    """'x, address 0, C-663: x.mcm'"""
    return (f"{controller.name}, address {controller.address}, {controller.model}: "
            f"{os.path.basename(controller.program)}")


def _text(rig, programs, readers) -> str:
    out = [printable(_title(rig))]
    for c in rig.controllers:
        program = _described_as(programs[c.name], "text")
        out += ["", f"{printable(_heading(c))}:"] + [f"  {line}" if line else "" for line in
                                                     program.rstrip("\n").split("\n")]
    for head, items in _rig_sections(rig, readers):
        if items:
            out += ["", f"{head}:"] + [f"  {'    ' * depth}{printable(text)}"
                                       for depth, text in items]
    return "\n".join(out) + "\n"


def _markdown(rig, programs, readers) -> str:
    out = [f"# {markdown(_title(rig))}"]
    for c in rig.controllers:
        out += ["", f"## {markdown(_heading(c))}", "",
                _described_as(programs[c.name], "markdown", level=3).rstrip("\n")]
    for head, items in _rig_sections(rig, readers):
        if items:
            out += ["", f"## {head}", ""] + [f"{'  ' * depth}- {markdown(text)}"
                                             for depth, text in items]
    out += ["", "## Call graph", "", "```mermaid", _mermaid(rig, readers), "```"]
    return "\n".join(out) + "\n"


def _described_as(stored: Stored, fmt: str, level: int = 1) -> str:
    return describe(stored.macros, model=stored.model, names=stored.names, fmt=fmt, level=level,
                    inputs=stored.inputs, outputs=stored.outputs, box=stored.box)


def _rig_sections(rig, readers) -> list[tuple[str, list[tuple[int, str]]]]:
    """The wires (each with the macros on both ends), the box and the joystick."""
    wires = []
    for wire in rig.wires:
        wires.append((0, f"{wire.source} -> {wire.target}"))
        wires += [(1, f"set by {t.controller}'s {t.label}: {t.how}")
                  for t in touches(readers, wire.source, _SETS)] or [
            (1, f"set by no macro of {wire.source.controller}: it stays off")]
        wires += [(1, f"read by {t.controller}'s {t.label}: {t.how}")
                  for t in touches(readers, wire.target, _READS)] or [
            (1, f"read by no macro of {wire.target.controller}")]
    box = [(0, f"on {rig.box}, buttons {', '.join(map(str, rig.box_buttons))}")] \
        if rig.box else []
    stick = [(0, f"branch {branch} drives {name}") for branch, name in rig.joystick.items()]
    return [("Wires", wires), ("C-170.PB pushbutton box", box), ("Joystick", stick)]


def touches(readers: Mapping[str, Reader], line, verbs: Mapping[str, str]) -> list[Touch]:
    """The macros of `line`'s controller whose commands in `verbs` name the line's number,
    each once with what it does to the line; CP sets outputs as a bit pattern (bit 0 =
    output 1)."""
    reader = readers.get(line.controller)
    if reader is None:
        return []
    out = []
    for slot, stored in reader.lines.items():
        hows = [_how(op, line.number, verbs) for op in stored.ops or ()]
        hows = list(dict.fromkeys(how for how in hows if how is not None))
        if hows:  # in the order the macro does them: 'turns it on, then turns it off'
            out.append(Touch(line.controller, slot, reader.label(slot), ", then ".join(hows)))
    return out


def _how(op, number: int, verbs: Mapping[str, str]) -> str | None:
    if op.mnemonic == Mnemonic.CP and verbs is _SETS:
        return "turns it on" if (op.arg or 0) >> (number - 1) & 1 else "turns it off"
    return verbs.get(op.mnemonic) if op.arg == number else None


def _data(rig, programs, readers) -> dict:
    return {
        "rig": rig.name, "file": rig.path,
        "controllers": [{"name": c.name, "address": c.address, "model": c.model,
                         "program": c.program, "description": described(
                             programs[c.name].macros, model=programs[c.name].model,
                             names=programs[c.name].names, inputs=programs[c.name].inputs,
                             outputs=programs[c.name].outputs, box=programs[c.name].box)}
                        for c in rig.controllers],
        "wires": [{"from": str(w.source), "to": str(w.target),
                   "set_by": [_touch(t) for t in touches(readers, w.source, _SETS)],
                   "read_by": [_touch(t) for t in touches(readers, w.target, _READS)]}
                  for w in rig.wires],
        "box": None if not rig.box else {"controller": rig.box,
                                         "buttons": list(rig.box_buttons)},
        "joystick": dict(rig.joystick),
    }


def _touch(t: Touch) -> dict:
    return {"controller": t.controller, "slot": t.slot, "macro": t.label, "how": t.how}


# -- one picture ---------------------------------------------------------------------------------

def rig_graph_dot(rig, programs: Mapping[str, Stored]) -> str:
    """Graphviz dot: a cluster per controller with its call graph (prose.dot_body), a node
    per wired line in its controller's cluster, the wire as a bold edge between clusters,
    and dotted edges from the macros that set an output and to those that read an input;
    a rig of one: its program's call graph (prose.call_graph_dot)."""
    if not rig.several:
        stored = programs[rig.controllers[0].name]
        return call_graph_dot(stored.macros, model=stored.model, names=stored.names)
    programs = _wired(rig, programs)
    readers = {c.name: Reader(*programs[c.name]) for c in rig.controllers}
    out = ["digraph rig {", "    rankdir=LR;", "    compound=true;", "    node [shape=box];",
           "    edge [fontsize=10];"]
    for c in rig.controllers:
        out += [f"    subgraph cluster_{c.name} {{",
                f'        label="{dot(_heading(c))}";',
                *dot_body(readers[c.name], prefix=f"{c.name}_", indent="        "),
                *[f'        {_line_id(line)} [label="{line.kind}{line.number}", shape=cds];'
                  for line in _wired_lines(rig, c.name)],
                "    }"]
    for start, end, label, wire in _wire_edges(rig, readers):
        style = "style=bold, color=blue" if wire else "style=dotted"
        out.append(f'    {start} -> {end} [label="{dot(label)}", {style}];')
    out.append("}")
    return "\n".join(out) + "\n"


def _mermaid(rig, readers) -> str:
    out = ["graph LR"]
    for c in rig.controllers:
        # `end` and mermaid's other keywords are good controller names but no subgraph ids;
        # `_rig` is no end of a node id (`x_MC01`, `x_out1`)
        out += [f'    subgraph {c.name}_rig["{mermaid(_heading(c))}"]',
                *mermaid_body(readers[c.name], prefix=f"{c.name}_", indent="        "),
                *[f'        {_line_id(line)}>"{line.kind}{line.number}"]'
                  for line in _wired_lines(rig, c.name)],
                "    end"]
    for start, end, label, wire in _wire_edges(rig, readers):
        arrow, label = ("==>", label.replace(" -> ", " to ")) if wire else ("-.->", label)
        out.append(f"    {start} {arrow}|{label}| {end}")  # `->` in a label reads as an arrow
    return "\n".join(out)


def _wire_edges(rig, readers):
    """(from, to, label, is the wire) of each wire between its lines' nodes, and of the
    macros that set its output and read its input (node ids as dot_body makes them)."""
    for wire in rig.wires:
        source, target = _line_id(wire.source), _line_id(wire.target)
        yield source, target, str(wire), True
        for t in touches(readers, wire.source, _SETS):
            yield f"{t.controller}_{slot_name(t.slot)}", source, t.how, False
        for t in touches(readers, wire.target, _READS):
            yield target, f"{t.controller}_{slot_name(t.slot)}", t.how, False


def _wired_lines(rig, controller: str) -> list:
    """The controller's lines that a wire starts or ends at, each once."""
    found = {}
    for wire in rig.wires:
        for line in (wire.source, wire.target):
            if line.controller == controller:
                found.setdefault(str(line), line)
    return list(found.values())


def _line_id(line) -> str:
    return f"{line.controller}_{line.kind}{line.number}"
