"""`describe RIG`: which controller does what, what each wire carries, and the
call graph of every controller in one picture (a cluster each, wires between clusters)."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from mercmac.compiler import compile_file
from mercmac.decompile.rig import Stored, describe_rig, rig_graph_dot
from mercmac.rig.model import Controller, Line, LineKind, Rig, Wire
from helpers.cli import cli
from helpers.paths import ROOT

X = """\
// X sweeps a line, tells Y, waits for Y
target C-663

macro sweep {
    MR 1000, WS 10
    CN 1, WA 20, CF 1
    WN 2
    goto sweep
}

autostart { goto sweep }
"""
Y = """\
target C-663

macro step {
    WN 1
    MR 100, WS 10
    CP 2, WA 20, CF 2
    goto step
}

autostart { goto step }
"""


def _line(text: str) -> Line:
    name, rest = text.split(".")
    kind = LineKind.OUT if rest.startswith("out") else LineKind.IN
    return Line(name, kind, int(rest[-1]))


def _rig(folder: Path, wires=(("x.out1", "y.in1"), ("y.out2", "x.in2"))) -> Rig:
    (folder / "x.mcm").write_text(X, encoding="utf-8")
    (folder / "y.mcm").write_text(Y, encoding="utf-8")
    return Rig(str(folder / "scan.rig.toml"), "scan",
               (Controller("x", 0, "C-663", str(folder / "x.mcm")),
                Controller("y", 1, "C-663", str(folder / "y.mcm"))),
               box="x", box_buttons=(1, 3), joystick={"X": "x", "Y": "y"},
               wires=tuple(Wire(_line(a), _line(b)) for a, b in wires))


def _stored(rig: Rig) -> dict[str, Stored]:
    out = {}
    for c in rig.controllers:
        program = compile_file(c.program, target=c.model).program
        out[c.name] = Stored({m.slot: m.line for m in program.macros.values()}, c.model,
                             program.names())
    return out


@pytest.fixture
def rig(tmp_path) -> Rig:
    return _rig(tmp_path)


def test_text_names_each_controller_and_what_each_wire_carries(rig):
    text = describe_rig(rig, _stored(rig))
    assert text.startswith("rig scan: 2 controllers on one link (scan.rig.toml)")
    assert "x, address 0, C-663: x.mcm:" in text and "y, address 1, C-663: y.mcm:" in text
    # each program as `describe` says it, under its controller, its wired lines named
    assert ("  step (MC01): wait until input 1 (from x.out1) is on, move +100 steps" in text)
    assert "output 1 (to y.in1) on, wait 20 ms, output 1 (to y.in1) off" in text
    assert "wait until input 2 (from y.out2) is on" in text
    wires = text.split("\nWires:\n")[1]
    assert "x.out1 -> y.in1" in wires
    assert "set by x's sweep (MC01): turns it on, then turns it off" in wires
    assert "read by y's step (MC01): waits until it is on" in wires
    # CP 2 = bit 1 = output 2 on
    assert "y.out2 -> x.in2" in wires and "set by y's step (MC01): turns it on" in wires
    assert "on x, buttons 1, 3" in text and "branch Y drives y" in text


def test_a_wire_no_macro_sets_or_reads_is_said(tmp_path):
    rig = _rig(tmp_path, wires=(("x.out3", "y.in4"),))
    text = describe_rig(rig, _stored(rig))
    assert "set by no macro of x: it stays off" in text and "read by no macro of y" in text


def test_json_has_each_program_and_the_wires_ends(rig):
    data = json.loads(describe_rig(rig, _stored(rig), fmt="json"))
    assert [c["name"] for c in data["controllers"]] == ["x", "y"]
    assert data["controllers"][1]["address"] == 1
    assert data["controllers"][0]["description"]["model"] == "C-663"
    first = data["wires"][0]
    assert (first["from"], first["to"]) == ("x.out1", "y.in1")
    assert [t["how"] for t in first["set_by"]] == ["turns it on, then turns it off"]
    assert first["read_by"] == [{"controller": "y", "slot": 1, "macro": "step (MC01)",
                                 "how": "waits until it is on"}]
    assert data["box"] == {"controller": "x", "buttons": [1, 3]}


def test_markdown_nests_the_programs_and_draws_one_graph(rig):
    text = describe_rig(rig, _stored(rig), fmt="markdown")
    assert text.startswith("# rig scan")
    assert "\n## x, address 0, C-663: x.mcm\n" in text
    assert "\n### 2 macros for a C-663" in text and "\n#### Every macro\n" in text
    assert "\n## Wires\n" in text and "\n  - set by x's sweep (MC01): turns it on, then" in text
    graph = text.split("\n## Call graph\n\n```mermaid\n")[1]
    assert 'subgraph x_rig["x, address 0, C-663: x.mcm"]' in graph
    assert "x_out1 ==>|x.out1 to y.in1| y_in1" in graph
    assert "y_in1 -.->|waits until it is on| y_MC01" in graph


def test_the_graph_has_a_cluster_per_controller_and_wires_between(rig):
    dot = rig_graph_dot(rig, _stored(rig))
    assert dot.count("subgraph cluster_") == 2
    assert "subgraph cluster_x {" in dot and 'label="x, address 0, C-663: x.mcm";' in dot
    assert "x_MC00 -> x_MC01" in dot and "y_MC00 -> y_MC01" in dot
    assert 'x_out1 -> y_in1 [label="x.out1 -> y.in1", style=bold' in dot
    assert 'x_MC01 -> x_out1 [label="turns it on, then turns it off", style=dotted]' in dot
    assert 'y_in1 -> y_MC01 [label="waits until it is on", style=dotted]' in dot


# -- `mercmac describe RIG` ----------------------------------------------------------------------

RASTER = ROOT / "examples" / "rigs" / "raster" / "raster.rig.toml"


@pytest.mark.parametrize("fmt, start", [("text", "rig raster: 2 controllers"),
                                        ("markdown", "# rig raster: 2 controllers"),
                                        ("json", "{")])
def test_describe_takes_a_rig_file(fmt, start):
    result = cli("describe", RASTER, "--format", fmt)
    assert result.exit_code == 0, result.output
    assert result.stdout.startswith(start)
    assert "x.out1" in result.stdout and "y.out2" in result.stdout
    if fmt == "json":
        assert [c["address"] for c in json.loads(result.stdout)["controllers"]] == [0, 1]


def test_describe_rig_graph_is_one_picture(tmp_path):
    out = tmp_path / "raster.dot"
    result = cli("describe", RASTER, "--graph", out)
    assert result.exit_code == 0, result.output
    dot = out.read_text(encoding="utf-8")
    assert dot.startswith("digraph rig {") and dot.count("subgraph cluster_") == 2
    assert "x_out1 -> y_in1" in dot and "y_out2 -> x_in2" in dot


def test_describe_a_rig_whose_program_has_errors_refuses(tmp_path):
    rig_text = RASTER.read_text(encoding="utf-8")
    for name in ("x.mcm", "y.mcm"):
        (tmp_path / name).write_text((RASTER.parent / name).read_text(encoding="utf-8"),
                                     encoding="utf-8")
    (tmp_path / "y.mcm").write_text("target C-663\nmacro row { MR }\n", encoding="utf-8")
    (tmp_path / "r.rig.toml").write_text(rig_text, encoding="utf-8")
    result = cli("describe", tmp_path / "r.rig.toml")
    assert result.exit_code == 1 and "y.mcm" in result.stderr and not result.stdout


def test_describe_a_broken_rig_file_shows_where(tmp_path):
    broken = tmp_path / "b.rig.toml"
    broken.write_text('[controllers.x]\naddress = 0\nmodel = "C-663"\nprogram = "x.mcm"\n'
                      'adress = 3\n', encoding="utf-8")
    result = cli("describe", broken)
    assert result.exit_code == 1 and "b.rig.toml:5:" in result.stderr and "MR001" in result.stderr


def test_describe_a_missing_rig_file_is_a_usage_error(tmp_path):
    result = cli("describe", tmp_path / "none.rig.toml")
    assert result.exit_code == 2 and "cannot read" in result.stderr


def test_a_condition_on_a_wired_input_is_said_as_the_wire():
    from mercmac.decompile import describe

    text = describe({1: "XN2,XF1,MR5"}, model="C-663", inputs={2: "input 2 (from y.out2)"})
    assert "only while button 1 is not pressed and input 2 (from y.out2) is on: move +5" in text
