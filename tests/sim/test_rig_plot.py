"""`sim RIG --plot`: a lane per axis, the wires' levels, the path picture.

A two-axis raster runs on the rig simulator (sim/simulate.py): X sweeps a line and raises
out1, Y steps one row on in1 and raises out2, X sweeps back on in2. The figure is read
back as drawn: one position lane per controller, a lane per wire equal to the wire's
edges, and a path whose points are the simulated positions, with a start and an end.
The PNG was looked at by eye: rows swept, stepped, arrows along them.
"""
from __future__ import annotations

import re

import pytest

from helpers.compiling import program_of
from helpers.plots import inline_svg, page_data, svg_texts

pytest.importorskip("matplotlib")

import numpy as np  # noqa: E402  (the plot extra's)
from matplotlib.quiver import Quiver  # noqa: E402

from mercmac.rig.model import Controller, Line, LineKind, Rig, Wire  # noqa: E402
from mercmac.sim import plot, rig_plot  # noqa: E402
from mercmac.sim.simulate import simulate  # noqa: E402

SWEEP = ("target C-663\nautostart { SV 20000, SA 200000\n goto sweep }\n"
         "macro sweep {\n  MR 20000, WS 10, CN 1, WN 2, CF 1, WF 2\n"
         "  MR -20000, WS 10, CN 1, WN 2, CF 1, WF 2\n  goto sweep\n}\n")
STEP = ("target C-663\nautostart { SV 10000, SA 200000\n goto step }\n"
        "macro step {\n  WN 1, MR 2000, WS 10, CN 2, WF 1, CF 2\n  goto step\n}\n")
LIFT = "target C-663\nautostart { WA 3000, MR 500, WS 10 }\n"  # a third axis: Z lifts once
UNTIL_MS = 12_000
ROWS = 8  # Y's steps in 12 s (one line of X: 1.1 s out, a row of Y: 0.3 s)


def _wire(a: str, b: str) -> Wire:
    (sc, so), (tc, ti) = a.split("."), b.split(".")
    return Wire(Line(sc, LineKind.OUT, int(so[3:])), Line(tc, LineKind.IN, int(ti[2:])))


def _rig(*names: str, box: str | None = None) -> Rig:
    controllers = tuple(Controller(n, i, "C-663", f"/rig/{n}.mcm") for i, n in enumerate(names))
    return Rig("/rig/raster.rig.toml", "raster", controllers, box=box, box_buttons=(1, 3),
               wires=(_wire("x.out1", "y.in1"), _wire("y.out2", "x.in2")))


def _listeners(watches: dict) -> dict:
    return {name: [w.on_event] for name, w in watches.items()}


def _run(rig: Rig, until_ms: int = UNTIL_MS, **kw):
    """The rig simulated with a plot listener on every controller: (Result, RigTrace)."""
    programs = {"x": program_of(SWEEP), "y": program_of(STEP), "z": program_of(LIFT)}
    watches = plot.watches(rig)
    run = simulate(rig, {c.name: programs[c.name] for c in rig.controllers},
                       until_ms=until_ms, listeners=_listeners(watches), **kw)
    return run, rig_plot.trace_of(rig, watches, until_ms * 1000)


@pytest.fixture(scope="module")
def raster():
    return _run(_rig("x", "y"))


def _figure(rt):
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    fig = rig_plot.figure(rt, "raster")
    FigureCanvasAgg(fig).draw()
    return fig


def _axes(fig) -> dict[str, object]:
    """The lanes (left) by their y labels."""
    return {ax.get_ylabel(): ax for ax in fig.subfigs[0].axes}


def test_one_position_lane_per_controller_on_one_time_axis(raster):
    fig = _figure(raster[1])
    axes = _axes(fig)
    assert {"x: position (steps)", "y: position (steps)", "x: macro", "y: macro",
            "wires"} <= set(axes)
    lanes = [axes[k] for k in ("x: position (steps)", "y: position (steps)", "wires")]
    assert len({ax.get_xlim() for ax in lanes}) == 1  # aligned in time
    for name in ("x", "y"):  # the lane draws the controller's own positions
        line = axes[f"{name}: position (steps)"].get_lines()[0]
        assert round(line.get_ydata()[-1]) == raster[0].runs[name].machine.position()


def test_each_wire_lane_is_high_exactly_between_its_edges(raster):
    run, rt = raster
    for wire in run.rig.wires:
        edges = [e for e in run.edges if e.wire == wire]
        assert [e.level for e in edges] == [True, False] * (len(edges) // 2)
        highs = list(rt.wires[str(wire)])
        assert highs == [(on.t, off.t) for on, off in zip(edges[::2], edges[1::2])]
    assert len(rt.wires["x.out1 -> y.in1"]) == ROWS
    labels = [t.get_text() for t in _axes(_figure(rt))["wires"].get_yticklabels()]
    assert labels == ["x.out1 → y.in1", "y.out2 → x.in2"]


def test_the_path_is_the_simulated_positions_with_start_and_end(raster):
    run, rt = raster
    points = rig_plot.path(rt)
    for column, name in ((1, "x"), (2, "y")):  # at each axis's own samples, its position
        t, x = np.array(rt.traces[name].position).T
        assert np.allclose(np.interp(t, points[:, 0], points[:, column]), x)
    assert points[0, 1:].tolist() == [0, 0]
    final = [run.runs[n].machine.position() for n in ("x", "y")]
    assert [round(v) for v in points[-1, 1:]] == final
    (ax,) = _path_axes(_figure(rt))
    drawn = {line.get_label(): line for line in ax.get_lines()}
    assert np.array_equal(drawn["path"].get_xdata(), points[:, 1], equal_nan=True)
    assert np.array_equal(drawn["path"].get_ydata(), points[:, 2], equal_nan=True)
    assert (drawn["start"].get_xdata()[0], drawn["start"].get_ydata()[0]) == (0, 0)
    assert [round(drawn["end"].get_xdata()[0]), round(drawn["end"].get_ydata()[0])] == final
    assert ax.get_xlabel() == "x: position (steps)"


def _path_axes(fig) -> list:
    return [ax for ax in fig.subfigs[1].axes if ax.get_xlabel().endswith("(steps)")]


def test_the_raster_reads_as_rows_swept_and_stepped(raster):
    """An arrow on every sweep (right, then left, in turn) and on every row step (up)."""
    (ax,) = _path_axes(_figure(raster[1]))
    (arrows,) = [c for c in ax.collections if isinstance(c, Quiver)]
    directions = [(round(u), round(v)) for u, v in zip(arrows.U, arrows.V)]
    sweeps = [d for d in directions if d[1] == 0]
    assert sweeps[:4] == [(1, 0), (-1, 0), (1, 0), (-1, 0)]
    assert directions.count((0, 1)) == ROWS and len(directions) == len(sweeps) + ROWS


def test_fast_forward_draws_the_same_picture(raster):
    """Skipped passes are drawn as the copies they are: the lanes, the wires and the path
    are those of the run stepped pass by pass."""
    _, stepped = _run(_rig("x", "y"), fast_forward="off")
    _, skipped = raster
    assert skipped.traces["y"].skips  # the rig did skip passes
    assert np.allclose(rig_plot.path(skipped), rig_plot.path(stepped))
    assert skipped.wires == stepped.wires


def test_a_long_run_is_compressed_in_time_and_its_path_stays_whole():
    _, rt = _run(_rig("x", "y"), until_ms=600_000)
    axis = rig_plot.joint_axis(list(rt.traces.values()))
    (stretch,) = axis.stretches  # 9 min 50 s of skipped rows: one hatched band
    assert stretch[1] - stretch[0] > 500e6
    points = rig_plot.path(rt)
    assert not np.isnan(points).any()  # every row drawn, copied from the one before
    rows = len(rt.wires["x.out1 -> y.in1"])
    assert points[:, 2].max() == 2000 * rows


def test_past_the_copy_budget_the_path_breaks_with_a_dashed_jump(monkeypatch):
    from mercmac.sim import plot

    monkeypatch.setattr(plot, "COPIED", 10)  # too many skipped samples to copy
    run, rt = _run(_rig("x", "y"), until_ms=600_000)
    points = rig_plot.path(rt)
    (cut,) = np.flatnonzero(np.isnan(points[:, 1]))
    (skip,) = rt.traces["y"].skips
    assert points[cut - 1, 0] == skip[0] and points[cut + 1, 0] == skip[1]
    (ax,) = _path_axes(_figure(rt))
    (jump,) = [line for line in ax.get_lines() if line.get_label() == "fast-forwarded"]
    assert jump.get_ydata()[:2].tolist() == [points[cut - 1, 2], points[cut + 1, 2]]
    assert [round(v) for v in points[-1, 1:]] == [run.runs[n].machine.position() for n in "xy"]


def test_a_deadlock_is_marked_on_both_lanes():
    rig = Rig("/rig/d.rig.toml", "d", (Controller("x", 0, "C-663", "/rig/x.mcm"),
                                       Controller("y", 1, "C-663", "/rig/y.mcm")),
              wires=(_wire("x.out1", "y.in1"), _wire("y.out2", "x.in2")))
    wait = "target C-663\nautostart {{ WN {n}, CN {m} }}\n"  # each waits for the other
    programs = {"x": program_of(wait.format(n=2, m=1)), "y": program_of(wait.format(n=1, m=2))}
    watches = plot.watches(rig)
    simulate(rig, programs, until_ms=1000, listeners=_listeners(watches))
    rt = rig_plot.trace_of(rig, watches, 1_000_000)
    axes = _axes(_figure(rt))
    for name in ("x", "y"):
        texts = [t.get_text() for t in axes[f"{name}: position (steps)"].texts]
        assert "rig-deadlock" in texts


def test_three_axes_give_two_projections():
    rig = _rig("x", "y", "z")
    run, rt = _run(rig, until_ms=4000)
    fig = _figure(rt)
    labels = [(ax.get_xlabel(), ax.get_ylabel()) for ax in _path_axes(fig)]
    assert labels == [("x: position (steps)", "y: position (steps)"),
                      ("x: position (steps)", "z: position (steps)")]
    assert rig_plot.path(rt)[-1, 3] == run.runs["z"].machine.position() == 500


def test_the_joystick_names_the_path_axes():
    rig = _rig("y", "x")
    assert rig.path_axes() == ("y", "x")
    joy = Rig(rig.path, rig.name, rig.controllers, joystick={"Y": "y", "X": "x"})
    assert joy.path_axes() == ("x", "y")
    one = Rig(rig.path, rig.name, rig.controllers[:1])
    assert one.path_axes() == ()


def test_the_box_buttons_have_a_lane_when_pressed():
    from mercmac.timespec import parse_buttons

    rig = _rig("x", "y", box="x")
    _, rt = _run(rig, until_ms=2000, presses={"x": parse_buttons("1@500ms-800ms")})
    assert rt.buttons == {1: [(500_000, 800_000)], 3: []}
    assert "x buttons" in _axes(_figure(rt))


@pytest.mark.parametrize("kind", ["png", "svg", "pdf"])
def test_each_kind_of_file_is_made(raster, tmp_path, kind):
    out = tmp_path / f"rig.{kind}"
    rig_plot.write(str(out), raster[1], "mercmac sim raster.rig.toml")
    assert out.stat().st_size > 1000
    assert not [p for p in tmp_path.iterdir() if p != out]  # written whole: no temporary


def test_the_html_page_holds_the_lanes_and_the_path(raster, tmp_path):
    run, rt = raster
    out = tmp_path / "rig.html"
    rig_plot.write(str(out), rt, "mercmac sim raster.rig.toml")
    page = out.read_text()
    texts = svg_texts(inline_svg(page))
    assert {"x: position (steps)", "y: position (steps)", "wires", "start", "end"} <= set(texts)
    data = page_data(page)
    assert data["controllers"] == ["x", "y"] and set(data["lanes"]) == {"x", "y"}
    assert data["path"]["axes"] == ["x", "y"]
    assert data["path"]["points"][0][1:] == [0, 0]
    final = [run.runs[n].machine.position() for n in "xy"]
    assert [round(v) for v in data["path"]["points"][-1][1:]] == final
    assert len(data["wires"]["x.out1 -> y.in1"]) == ROWS
    assert re.search(r"Lanes: position and macro per controller", page)


# --- through the command line ------------------------------------------------------------

RIG_FILE = """box = "x"
box_buttons = [1, 3]
wires = ["x.out1 -> y.in1", "y.out2 -> x.in2"]

[joystick]
X = "x"
Y = "y"

[controllers.x]
address = 0
model = "C-663"
program = "x.mcm"

[controllers.y]
address = 1
model = "C-663"
program = "y.mcm"
"""


@pytest.fixture
def rig_file(tmp_path):
    (tmp_path / "x.mcm").write_text(SWEEP, encoding="utf-8")
    (tmp_path / "y.mcm").write_text(STEP, encoding="utf-8")
    path = tmp_path / "raster.rig.toml"
    path.write_text(RIG_FILE, encoding="utf-8")
    return path


def _sim(rig_file, out, *more):
    from helpers.cli import cli

    return cli("sim", rig_file, "--until", "12s", "--format", "json", "--plot", out, *more)


@pytest.mark.parametrize("kind", ["png", "svg", "pdf", "html"])
def test_sim_rig_plot_makes_each_kind_of_file(rig_file, tmp_path, kind):
    out = tmp_path / f"run.{kind}"
    result = _sim(rig_file, out)
    assert result.exit_code == 0, result.output
    magic = {"png": b"\x89PNG", "svg": b"<?xml", "pdf": b"%PDF-", "html": b"<!DOCTYPE html>"}
    assert out.read_bytes().startswith(magic[kind])


def test_sim_rig_plot_draws_the_run_it_simulated(rig_file, tmp_path, monkeypatch):
    drawn = []
    make = rig_plot.figure
    monkeypatch.setattr(rig_plot, "figure", lambda *a, **kw: drawn.append(make(*a, **kw)) or drawn[-1])
    result = _sim(rig_file, tmp_path / "run.svg")
    assert result.exit_code == 0, result.output
    (fig,) = drawn
    (ax,) = _path_axes(fig)
    path_line = next(line for line in ax.get_lines() if line.get_label() == "path")
    _, rt = _run(_rig("x", "y"))  # the same rig, run in the library: the same path
    assert np.array_equal(path_line.get_xdata(), rig_plot.path(rt)[:, 1], equal_nan=True)
    assert fig.get_suptitle() == "mercmac sim raster.rig.toml"


def test_sim_rig_plot_without_matplotlib_is_a_clear_message(rig_file, tmp_path, monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "matplotlib", None)  # `import matplotlib` fails
    out = tmp_path / "run.png"
    result = _sim(rig_file, out)
    assert result.exit_code == 2
    assert "--plot needs the plot extra: pip install 'mercmac[plot]'" in result.output
    assert "Traceback" not in result.output and '"until_ms"' not in result.output
    assert not out.exists()


def test_sim_rig_plot_refuses_an_unknown_kind_of_file(rig_file, tmp_path):
    result = _sim(rig_file, tmp_path / "run.gif")
    assert result.exit_code == 2 and ".png, .svg, .pdf or .html" in result.output


def test_the_readme_raster_picture_is_made_by_the_command_it_names(tmp_path):
    from helpers.cli import cli
    from helpers.paths import ROOT

    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    named = re.search(r"`mercmac (sim [^`]*--plot docs/raster\.png)`", readme)
    assert named and "](docs/raster.png)" in readme
    assert (ROOT / "docs" / "raster.png").read_bytes().startswith(b"\x89PNG")
    args = named.group(1).split()[1:-1]  # the command's own words, the picture to tmp_path
    out = tmp_path / "raster.png"
    result = cli("sim", *[ROOT / a if a.startswith("examples/") else a for a in args], out)
    assert result.exit_code == 0, result.output
    assert out.read_bytes().startswith(b"\x89PNG")
