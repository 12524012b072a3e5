"""A picture of a rig's run (`sim RIG --plot`): every axis on one clock.

On the left, one position lane (with its macro lane) per controller, the wires' levels
and the box's buttons, all on one time axis; on the right, for a rig of two or three
axes, the path the stage draws (X against Y, and X against Z for a third axis) with its
start, its end and arrows along it: the picture a person draws of a raster scan. The
lanes are the single-controller plot's (plot.py): the same time axis, compressed
stretches, clipped targets and labels that fit; a stretch is compressed only where every
controller skipped it. Skipped passes are drawn as the copies they are (plot.py); past
its budget of copies the path breaks across them, with a dashed jump.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import reduce

from mercmac.rig.model import Rig
from mercmac.sim import plot
from mercmac.sim.plot import PlotObserver, TimeAxis, Trace

# Direction arrows: one on each straight leg, ALONG of the way from its start (so that
# a raster's rightward and leftward arrows stand in two columns, apart), none on a leg
# shorter than SHORT_LEG of the picture (the arrow itself is ~5% long), and none nearer
# than GAP of the picture to one already drawn (hundreds of rows stay readable).
ALONG = 0.4
GAP = 0.05
TURN = 0.35  # radians: a change of direction this large starts a new leg
SHORT_LEG = 0.05
LANES = "position and macro per controller, wires, box buttons; path: start, end, direction"


@dataclass
class RigTrace:
    """What a rig's plot needs: each controller's Trace (us), the wires' high spans, the
    box's button presses, and the controllers that are the path's axes (X, Y, Z order)."""

    rig: Rig
    traces: dict[str, Trace]
    wires: dict[str, list]  # str(wire) -> [(t_on, t_off)] in us
    buttons: dict[int, list]  # box input -> [(t_on, t_off)] in us
    axes: tuple[str, ...]
    end: int


def trace_of(rig: Rig, watched: dict[str, PlotObserver], end_us: int) -> RigTrace:
    """Close every listener at end_us. A wire carries its driving output's level
    (vm/wiring.py), so its lane is that output's lane: kept whole where the run's list of
    edges stops at its cap, and skipped passes leave it as they leave the output."""
    traces = {name: w.close(end_us) for name, w in watched.items()}
    wires = {str(w): traces[w.source.controller].outputs.get(w.source.number, [])
             for w in rig.wires}
    return RigTrace(rig, traces, wires, _buttons(rig, traces), rig.path_axes(), end_us)


def _buttons(rig: Rig, traces: dict[str, Trace]) -> dict[int, list]:
    """The presses of the box's buttons: its controller's inputs that no wire drives."""
    if rig.box is None or rig.box not in traces:
        return {}
    pressed = traces[rig.box].inputs
    buttons = [n for n in rig.box_inputs(rig.box) if not rig.drivers(rig.box, n)]
    if not any(n in pressed for n in buttons):  # a lane of nothing pressed says nothing
        return {}
    return {n: pressed.get(n, []) for n in buttons}


def joint_axis(traces: list[Trace]) -> TimeAxis:
    """One time axis for all lanes: a stretch is drawn compressed only where every
    controller skipped it (or sat idle after its program ended)."""
    end = max(t.end for t in traces)
    each = [TimeAxis(t.skips, end, t.actions, t.idle_from).stretches for t in traces]
    idle = [t.idle_from for t in traces]
    idle_from = None if None in idle else max(idle)
    shared = [s for s in reduce(_intersect, each) if idle_from is None or s[0] < idle_from]
    return TimeAxis(shared, end, sorted(a for t in traces for a in t.actions), idle_from)


def _intersect(a: list, b: list) -> list:
    """The common parts of two sorted lists of (start, end)."""
    out, i, j = [], 0, 0
    while i < len(a) and j < len(b):
        lo, hi = max(a[i][0], b[j][0]), min(a[i][1], b[j][1])
        if lo < hi:
            out.append((lo, hi))
        if a[i][1] < b[j][1]:
            i += 1
        else:
            j += 1
    return out


# --- the path -------------------------------------------------------------------------

def path(rt: RigTrace):
    """The path's points: times (us, every sample of any axis) and one column per axis,
    each axis's position at those times as its lane draws it (between its samples,
    a straight line); a row of NaN where a skipped pass breaks it."""
    import numpy as np

    traces = [rt.traces[name] for name in rt.axes]
    times = np.unique(np.concatenate([[t for t, _ in tr.position] for tr in traces]))
    columns = [np.interp(times, *zip(*tr.position)) for tr in traces]
    points = np.column_stack([times, *columns])
    cuts = _gaps(times, [s for tr in traces for s in tr.skips])
    return np.insert(points, cuts, np.nan, axis=0) if cuts else points


def _gaps(times, skips: list) -> list[int]:
    """Where the path breaks: before the first sample after each skipped stretch that
    holds no sample of its own."""
    import numpy as np

    cuts = set()
    for a, b, *_ in skips:
        i = int(np.searchsorted(times, a, side="right"))
        if 0 < i < len(times) and times[i] >= b:
            cuts.add(i)
    return sorted(cuts)


def legs(x, y, scale: tuple[float, float]) -> list[tuple[float, float, float, float]]:
    """(x, y, dx, dy) on each straight leg of the path (ALONG of its way), (dx, dy) its
    unit direction in counts; legs are told apart as the picture shows them (`scale`:
    counts per picture width and height)."""
    import numpy as np

    sx, sy = (s or 1.0 for s in scale)
    u, v = np.diff(x) / sx, np.diff(y) / sy
    length = np.nan_to_num(np.hypot(u, v))  # a break (NaN) is no step
    return [_along(x, y, leg, length) for leg in _legs(u, v, length)
            if length[leg].sum() >= SHORT_LEG]


def _legs(u, v, length) -> list[list[int]]:
    """The path's steps (indices) in runs that go on in one direction, stops left out."""
    import numpy as np

    found: list[tuple[float, list[int]]] = []  # (the leg's first direction, its steps)
    for k in np.flatnonzero(length > 0):
        angle = math.atan2(v[k], u[k])
        if found and found[-1][1][-1] == k - 1 and abs(_turn(angle, found[-1][0])) <= TURN:
            found[-1][1].append(k)
        else:
            found.append((angle, [k]))
    return [steps for _, steps in found]


def _turn(a: float, b: float) -> float:
    return (a - b + math.pi) % (2 * math.pi) - math.pi


def _along(x, y, seg: list, length) -> tuple[float, float, float, float]:
    """The point ALONG of the way of a leg, and the leg's direction there."""
    at, walked = length[seg].sum() * ALONG, 0.0
    for k in seg:
        if walked + length[k] >= at:
            f = (at - walked) / length[k]
            dx, dy = x[k + 1] - x[k], y[k + 1] - y[k]  # a unit step in counts (quiver's "xy")
            return x[k] + f * dx, y[k] + f * dy, dx / math.hypot(dx, dy), dy / math.hypot(dx, dy)
        walked += length[k]
    raise AssertionError("a leg has a point ALONG of its way")


def spaced(arrows: list, scale: tuple[float, float]) -> list:
    """The arrows in path order, each kept when no kept one is nearer than GAP of the
    picture."""
    import numpy as np

    sx, sy = (s or 1.0 for s in scale)
    kept: list = []
    places = np.empty((0, 2))
    for arrow in arrows:
        place = np.array([arrow[0] / sx, arrow[1] / sy])
        if not len(places) or np.hypot(*(places - place).T).min() >= GAP:
            kept.append(arrow)
            places = np.vstack([places, place])
    return kept


# --- the figure -----------------------------------------------------------------------

def figure(rt: RigTrace, title: str = ""):
    """Lanes on one time axis on the left; the path picture on the right (2-3 axes)."""
    plt = plot.styled()
    names = [c.name for c in rt.rig.controllers]
    height = max(6.5, 2.4 * len(names) + 1.5)
    side = _side(rt, height) if rt.axes else 0.0
    fig = plt.figure(figsize=(11 + side, height), layout="constrained")
    lanes_fig, path_fig = fig.subfigures(1, 2, width_ratios=[11, side]) if rt.axes else (fig, None)
    _lanes(lanes_fig, rt, names)
    if path_fig is not None:
        _paths(path_fig, rt)
    if title:
        fig.suptitle(title, fontsize=11)
    return fig


def _lanes(fig, rt: RigTrace, names: list[str]) -> None:
    axis = joint_axis([rt.traces[n] for n in names])
    ratios = [r for _ in names for r in (4, 0.7)]
    extra = [(rt.wires, "tab:green", "wires"), (rt.buttons, "tab:blue", f"{rt.rig.box} buttons")]
    extra = [e for e in extra if e[0]]
    ratios += [0.45 * len(lanes) + 0.3 for lanes, *_ in extra]
    axes = fig.subplots(len(ratios), 1, sharex=True, gridspec_kw={"height_ratios": ratios})
    for i, name in enumerate(names):
        plot.position(axes[2 * i], rt.traces[name], axis)
        axes[2 * i].set_ylabel(f"{name}: position ({rt.traces[name].unit})")
        if i:  # the legend once, above the first lane
            axes[2 * i].get_legend().remove()
        plot.macros(axes[2 * i + 1], rt.traces[name].macros, axis)
        axes[2 * i + 1].set_ylabel(f"{name}: macro", rotation=0, ha="right", va="center")
    for ax, (lanes, color, label) in zip(axes[2 * len(names):], extra):
        plot.bars(ax, lanes, list(lanes), axis, color, label)
        ax.set_yticklabels([str(k).replace(" -> ", " → ") for k in lanes], fontsize=8)
    plot.time_lanes(axes, axis)


def _paths(fig, rt: RigTrace) -> None:
    """X against Y; for a third axis also X against Z, below."""
    points = path(rt)
    views = [(1, 2)] + ([(1, 3)] if len(rt.axes) == 3 else [])
    axes = fig.subplots(len(views), 1, squeeze=False)[:, 0]
    for ax, (i, j) in zip(axes, views):
        named = (rt.axes[i - 1], rt.axes[j - 1])
        _path(ax, points[:, i], points[:, j], named,
              tuple(rt.traces[n].unit for n in named))


def _side(rt: RigTrace, height: float) -> float:
    """Inches for the path picture beside the lanes: as wide as its views, stacked in the
    figure's height, need at one scale (a 20,000 by 12,000 raster is wider than tall), so
    that it fills its column instead of floating small in it; 4-9 in."""
    import numpy as np

    points = path(rt)
    views = 1 + (len(rt.axes) == 3)
    spans = [float(np.nanmax(points[:, k]) - np.nanmin(points[:, k])) if len(points) else 0.0
             for k in range(1, len(rt.axes) + 1)]
    tall = max(max(spans[1:]), 1.0)
    ratio = max(spans[0], 1.0) / tall
    ratio = ratio if 0.1 <= ratio <= 10 else 1.0  # each axis its own scale (_frame)
    return min(max((height / views - 1.2) * ratio + 1.2, 4.0), 9.0)


def _path(ax, x, y, names: tuple[str, str], units: tuple[str, str]) -> None:
    ax.plot(x, y, color="tab:blue", lw=1.3, label="path")
    _jumps(ax, x, y)
    _ends(ax, x, y)
    _arrows(ax, x, y)
    ax.set_xlabel(f"{names[0]}: position ({units[0]})")
    ax.set_ylabel(f"{names[1]}: position ({units[1]})")
    ax.ticklabel_format(style="plain", useOffset=False)
    ax.grid(alpha=0.3)
    ax.legend(loc="lower center", bbox_to_anchor=(0.5, 1), ncols=5, fontsize=8, frameon=False,
              borderaxespad=0.1)


def _ends(ax, x, y) -> None:
    """The start and the end marked, the frame around the path."""
    import numpy as np

    keep = ~np.isnan(x)
    # the end drawn smaller, over the start: a path that comes back shows both
    ax.plot(x[keep][:1], y[keep][:1], ls="none", marker="o", ms=12, color="tab:green",
            label="start", zorder=4)
    ax.plot(x[keep][-1:], y[keep][-1:], ls="none", marker="s", ms=7, color="tab:red",
            label="end", zorder=5)
    _frame(ax, x[keep], y[keep])


def _arrows(ax, x, y) -> None:
    """The legs' directions, in one artist (the path's limits are set by now)."""
    arrows = spaced(legs(x, y, _scale(ax)), _scale(ax))
    if arrows:
        px, py, u, v = zip(*arrows)
        ax.quiver(px, py, u, v, angles="xy", pivot="mid", color="tab:blue", zorder=3,
                  scale_units="inches", scale=4.5, width=0.01, headwidth=4, headlength=4.5,
                  label="direction")


def _jumps(ax, x, y) -> None:
    """A dashed line across each break: the stage got there through skipped passes."""
    import numpy as np

    breaks = [k for k in np.flatnonzero(np.isnan(x)) if 0 < k < len(x) - 1]
    if breaks:  # one artist: the jumps apart from each other by NaN
        ends = [(x[k + d], y[k + d]) for k in breaks for d in (-1, 1, 0)]
        ax.plot(*zip(*ends), color="gray", lw=1, ls="--", label="fast-forwarded")


def _frame(ax, x, y) -> None:
    """Limits with a margin; counts at one scale on both axes when their spans are
    alike (a raster's rows keep their spacing), else each axis its own."""
    spans = [max(float(v.max() - v.min()), 1.0) for v in (x, y)]
    ax.margins(0.08)
    for v, set_lim in ((x, ax.set_xlim), (y, ax.set_ylim)):
        if v.max() - v.min() < 2:  # standing still: whole counts around it, as a lane does
            set_lim(float(v.min()) - 10, float(v.max()) + 10)
    for axis in (ax.xaxis, ax.yaxis):
        axis.get_major_locator().set_params(integer=True)
    if max(spans) / min(spans) <= 10:
        ax.set_aspect("equal", adjustable="box")


def _scale(ax) -> tuple[float, float]:
    """Data units per picture width and height (what a direction is measured in)."""
    (a, b), (c, d) = ax.get_xlim(), ax.get_ylim()
    return b - a, d - c


# --- the file -------------------------------------------------------------------------

def write(path_: str, rt: RigTrace, title: str = "") -> None:
    """The rig's plot into PATH (whole or not at all), its kind from the ending."""
    plot.save(path_, figure(rt, title), lambda: data(rt), title, LANES)


def data(rt: RigTrace) -> dict:
    """The lanes and the path as plain numbers (ms, counts), for the HTML page and tests."""
    ms = 1e-3
    points = path(rt) if rt.axes else None
    return {
        "controllers": [c.name for c in rt.rig.controllers],
        "lanes": {name: plot.data(trace) for name, trace in rt.traces.items()},
        "wires": {k: [[a * ms, b * ms] for a, b in v] for k, v in rt.wires.items()},
        "buttons": {str(n): [[a * ms, b * ms] for a, b in v] for n, v in rt.buttons.items()},
        "path": None if points is None else {
            "axes": list(rt.axes),
            "points": [None if math.isnan(p[1]) else
                       [round(p[0] * ms, 3), *(round(v, 1) for v in p[1:])]
                       for p in points.tolist()]},
    }
