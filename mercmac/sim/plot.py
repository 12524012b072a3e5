"""A picture of a run (issue 11, `--plot`): position and target over time, lanes below.

The lanes are the buttons held, the LEDs lit and the running macro by name. A
long fast-forwarded stretch (a day of polling) is drawn compressed to a short
hatched band labelled with its real length, a broken time axis, so that the
seconds of action around it stay readable. PNG, SVG and PDF come from
matplotlib (the extra `plot`, imported only here and only when drawing); HTML is
the SVG in a page that zooms and pans (render/plot_html.py).
"""
from __future__ import annotations

import io
import math
import os
from bisect import bisect_left, bisect_right
from dataclasses import dataclass, field

from mercmac.errors import UsageError
from mercmac.outfile import replacing, writable_target
from mercmac.vm import events as ev
from mercmac.vm import fastforward as ff

FORMATS = (".png", ".svg", ".pdf", ".html")
MISSING = "--plot needs the plot extra: pip install 'mercmac[plot]'"
COMPRESS_US = 10_000_000  # skipped stretches longer than this (10 s) are drawn compressed
BAND = 0.06  # a compressed stretch's width, as a share of the time drawn to scale
CURVE = 16  # points per accelerating profile segment
CAP = 200_000  # recorded changes; past this the plot stops (a marked cut) and the run goes on
LANES = ("position", "buttons", "LEDs", "macro")
# A lane of more bars than this is drawn at 1/3000 of the time axis, a quarter of a point
# on the page: every bar has a 1-pt edge of its colour, which covers finer gaps at any
# zoom (an SVG zooms its edges too); 36,000 macro changes cost a few thousand bars.
LANE_STEPS = 3000
LABEL_WIDTH = 0.03  # a band's label (two lines of 7 pt, turned, boxed): 3% of the time axis


def check_target(path: str) -> None:
    """Refuse before any simulating: an unknown kind of file, a bad path, no matplotlib."""
    if os.path.splitext(path)[1].lower() not in FORMATS:
        raise UsageError(f"--plot {path}: the file must end in .png, .svg, .pdf or .html")
    writable_target(path)
    _pyplot()


def _pyplot():
    try:
        import matplotlib
    except ImportError:
        raise UsageError(MISSING) from None
    matplotlib.use("Agg")  # files only, never a window
    import matplotlib.pyplot as plt

    return plt


@dataclass
class Trace:
    """What a plot needs of a run, in microseconds; filled by PlotObserver."""

    position: list = field(default_factory=lambda: [(0.0, 0.0)])  # (t, x)
    target: list = field(default_factory=lambda: [(0, 0)])  # (t, target) steps
    inputs: dict = field(default_factory=dict)  # input -> [(t_on, t_off)]
    outputs: dict = field(default_factory=dict)  # output 1-4 -> [(t_on, t_off)]
    macros: list = field(default_factory=list)  # (t0, t1, label)
    skips: list = field(default_factory=list)  # (t, t_to, passes, loop label)
    actions: list = field(default_factory=list)  # times of input changes, moves, hazards
    hazards: list = field(default_factory=list)  # (t, rule)
    end: int = 0
    cut_at: int | None = None  # where recording stopped at CAP


class PlotObserver:
    """An event listener that keeps a Trace; chain the recorder as `then`, call `close`."""

    def __init__(self, then=None):
        self.then = then
        self.trace = Trace()
        self.segments: tuple = ()
        self.sampled_to = 0.0
        self.held: dict[int, int] = {}  # input -> since
        self.lit: dict[int, int] = {}  # output -> since
        self.macro: tuple[int, str] | None = None  # (since, label)
        self.changes = 0

    def on_event(self, event) -> None:
        if self.trace.cut_at is None:
            self._take(event)
        if self.then:
            self.then(event)

    def _take(self, event) -> None:
        t = getattr(event, "t", None)
        if t is None:
            return
        self.changes += 1
        if self.changes > CAP or len(self.trace.position) > CAP:
            self.close(t)
            self.trace.cut_at = t
            return
        self._follow(t)
        if isinstance(event, (ev.InputChanged, ev.MoveStarted, ev.MoveEnded, ev.HomeDefined,
                              ev.HazardFound)):
            self.trace.actions.append(t)
        match event:
            case ev.InputChanged(_, n, on):
                self._switch(self.held, self.trace.inputs, n, on, t)
            case ev.OutputsChanged(_, pattern):
                self._pattern(pattern, t)
            case ev.MacroEntered(_, _, label):
                self._enter(label, t)
            case ev.MacroLeft(back_to=back):
                self._enter(back, t)
            case ev.MoveStarted(_, _, target, _, segments):
                self.trace.target.append((t, target))
                self._mark(t)
                self.segments, self.sampled_to = segments, t
            case ev.MoveEnded(_, _, position):
                self.segments = ()
                self.trace.position.append((t, float(position)))
            case ev.HomeDefined(_, position):
                self._mark(t)
                self.segments = ()
                self.trace.position.append((t, float(position)))
                self.trace.target.append((t, position))
            case ev.HazardFound(_, rule):
                self.trace.hazards.append((t, rule))
            case ev.FastForwarded(_, t_to, passes, _, loop, shape):
                self.trace.skips.append((t, t_to, passes, loop.label))
                last = _last_pattern(shape)
                if last is not None:
                    self._pattern(last, t_to)

    def _follow(self, t: float) -> None:
        """Position samples of the running profile up to t: CURVE points along each
        accelerating segment, the ends of a straight one, however many events fall in it
        (a 1-ms polling loop during a move would otherwise sample it every millisecond)."""
        for seg in self.segments:
            n = CURVE if seg.a else 1
            step = seg.dt / n
            if step > 0 and seg.t0 <= t and seg.t1 > self.sampled_to:
                first = max(math.floor((self.sampled_to - seg.t0) / step) + 1, 0)
                last = min(math.floor((t - seg.t0) / step), n)
                self.trace.position += [(seg.t0 + k * step, seg.x(seg.t0 + k * step))
                                        for k in range(first, last + 1)]
        self.sampled_to = max(self.sampled_to, t)

    def _mark(self, t: float) -> None:
        """The position at t itself, where the profile changes (a new move, a new home, the end)."""
        x = next((seg.x(t) for seg in reversed(self.segments) if seg.t0 <= t),
                 self.trace.position[-1][1])
        if self.trace.position[-1] != (t, x):
            self.trace.position.append((t, x))

    def _switch(self, since: dict, into: dict, n: int, on: bool, t: int) -> None:
        if on and n not in since:
            since[n] = t
        elif not on and n in since:
            into.setdefault(n, []).append((since.pop(n), t))

    def _pattern(self, pattern: int, t: int) -> None:
        for bit in range(4):
            self._switch(self.lit, self.trace.outputs, bit + 1, bool(pattern >> bit & 1), t)

    def _enter(self, label: str | None, t: int) -> None:
        if self.macro is not None and self.macro[1] == label:
            return
        if self.macro is not None and t > self.macro[0]:
            self.trace.macros.append((self.macro[0], t, self.macro[1]))
        self.macro = (t, label) if label else None

    def close(self, t_us: int) -> Trace:
        """End every open lane at t_us; the Trace to draw."""
        if self.trace.cut_at is not None:
            return self.trace
        self._follow(t_us)
        self._mark(t_us)
        self.trace.target.append((t_us, self.trace.target[-1][1]))
        for since, into in ((self.held, self.trace.inputs), (self.lit, self.trace.outputs)):
            for n in list(since):
                self._switch(since, into, n, False, t_us)
        self._enter(None, t_us)
        self.trace.end = t_us
        return self.trace


def _last_pattern(shape: tuple) -> int | None:
    """The output pattern a skipped pass leaves behind, if it changes any."""
    last = None
    for item in shape:
        if item[0] == ff.OUTPUTS:
            last = item[2]  # (OUTPUTS, offset, pattern)
        elif item[0] in (ff.SKIP, ff.SHIFTED):  # an inner skip, shifted or not
            inner = _last_pattern(item[4])
            last = last if inner is None else inner
    return last


class TimeAxis:
    """Real time (us) -> drawn seconds: long skipped stretches squeezed to short bands."""

    def __init__(self, skips: list, end: int, actions: list = ()):
        stretches = [(a, b) for a, b in _merged(skips, sorted(actions)) if b - a >= COMPRESS_US]
        self.stretches = [(a, min(b, end)) for a, b in stretches if a < end]
        scaled = max(end - sum(b - a for a, b in self.stretches), 1000)
        width = scaled * BAND
        self.real, self.drawn, at = [0.0], [0.0], 0.0
        for a, b in self.stretches:
            at += a - self.real[-1]
            self.real += [a, b]
            self.drawn += [at, at + width]
            at += width
        self.real.append(max(float(end), self.real[-1]))
        self.drawn.append(at + self.real[-1] - self.real[-2])
        self.real = [r / 1e6 for r in self.real]
        self.drawn = [d / 1e6 for d in self.drawn]
        import numpy as np  # the plot extra's; a TimeAxis is made only to draw

        self._xp, self._fp = np.array(self.real), np.array(self.drawn)  # once, not per call

    def __call__(self, t_us):
        import numpy as np

        return np.interp(np.asarray(t_us, dtype=float) / 1e6, self._xp, self._fp)

    def pieces(self) -> list[tuple[float, float, float, float]]:
        """(real from, real to, drawn from, drawn to) in seconds of the parts drawn to scale."""
        return [(self.real[i], self.real[i + 1], self.drawn[i], self.drawn[i + 1])
                for i in range(0, len(self.real) - 1, 2)]

    def ticks(self) -> tuple[list[float], list[str]]:
        """Tick places (drawn) and labels (real time): where each piece after a band
        starts, then round times inside the pieces, as many as fit without overlapping."""
        from matplotlib.ticker import MaxNLocator

        total = self.drawn[-1] or 1.0
        wanted = [(d0, r0) for r0, r1, d0, d1 in self.pieces()[1:]]
        for r0, r1, d0, d1 in self.pieces():
            bins = max(1, round(8 * (d1 - d0) / total))
            wanted += [(self._at(r), r) for r in MaxNLocator(bins + 1).tick_values(r0, r1)
                       if r0 - 1e-9 <= r <= r1 + 1e-9]
        placed: list[tuple[float, str]] = []
        for d, r in wanted:
            text = duration(r)
            if all(abs(d - pd) > total * ((len(text) + len(pt)) / 2 + 2) / 110 for pd, pt in placed):
                placed.append((d, text))
        placed.sort()
        return [d for d, _ in placed], [t for _, t in placed]

    def _at(self, seconds: float) -> float:
        import numpy as np

        return float(np.interp(seconds, self._xp, self._fp))


def _merged(skips: list, actions: list) -> list:
    """Skipped stretches joined across short gaps in which nothing but the loop happens
    (the odd pass that was stepped: an RP counter running out between two skips)."""
    out: list = []
    for a, b, *_ in sorted(skips):
        if out and (a <= out[-1][1] or (a - out[-1][1] < COMPRESS_US
                                        and not _any_in(actions, out[-1][1], a))):
            out[-1] = (out[-1][0], max(out[-1][1], b))
        else:
            out.append((a, b))
    return out


def _any_in(times: list, a: float, b: float) -> bool:
    """Is some time in `times` (sorted) within [a, b]?"""
    return bisect_left(times, a) < bisect_right(times, b)


def duration(seconds: float) -> str:
    """1.5 -> '1.5 s'; 90061.5 -> '1 d 1:01:01.5'."""
    if seconds < 60:
        return f"{round(seconds, 6):g} s"
    whole, frac = divmod(round(seconds, 3), 1)
    d, rest = divmod(int(whole), 86400)
    h, rest = divmod(rest, 3600)
    m, s = divmod(rest, 60)
    tail = f"{frac:.3f}".lstrip("0").rstrip("0").rstrip(".") if frac else ""
    return (f"{d} d " if d else "") + f"{h}:{m:02d}:{s:02d}{tail}"


def span(us: float) -> str:
    """A skipped stretch's length in words: '23 h 59 min', '2 min 5 s', '12.5 s'."""
    s = us / 1e6
    for unit, size, sub, subsize in (("d", 86400, "h", 3600), ("h", 3600, "min", 60),
                                     ("min", 60, "s", 1)):
        if s >= size:
            big, rest = divmod(s, size)
            small = int(rest // subsize)
            return f"{int(big)} {unit}" + (f" {small} {sub}" if small else "")
    return f"{round(s, 1):g} s"


def figure(trace: Trace, title: str = ""):
    """A matplotlib figure of the trace: position over the lanes, one shared time axis."""
    plt = _pyplot()
    plt.rcParams["svg.fonttype"] = "none"  # text stays text in an SVG (searchable, testable)
    plt.rcParams["svg.hashsalt"] = "mercmac"  # the same run gives the same file
    axis = TimeAxis(trace.skips, trace.end, trace.actions)
    inputs = sorted(set(trace.inputs) | {1, 2, 3, 4})
    fig, axes = plt.subplots(4, 1, sharex=True, figsize=(11, 6.5), layout="constrained",
                             gridspec_kw={"height_ratios": [5, 0.45 * len(inputs), 1.8, 0.8]})
    _position(axes[0], trace, axis)
    _bars(axes[1], trace.inputs, inputs, axis, "tab:blue", "buttons")
    _bars(axes[2], trace.outputs, [1, 2, 3, 4], axis, "tab:orange", "LEDs")
    _macros(axes[3], trace.macros, axis)
    for ax in axes:
        _skipped(ax, axis, label=ax is axes[0])
    where, text = axis.ticks()
    axes[-1].set_xticks(where, text)
    axes[-1].set_xlim(0, axis.drawn[-1])
    broken = " (hatched: fast-forwarded, drawn compressed)" if axis.stretches else ""
    axes[-1].set_xlabel("time" + broken)
    if title:
        fig.suptitle(title, fontsize=11)
    return fig


def _position(ax, trace: Trace, axis: TimeAxis) -> None:
    t, x = zip(*trace.position)
    ax.plot(axis(t), x, color="tab:blue", lw=1.6, label="position")
    t, x = zip(*trace.target)
    ax.step(axis(t), x, where="post", color="tab:red", lw=1, ls="--", label="target")
    for t, rule in trace.hazards:
        ax.axvline(float(axis(t)), color="crimson", lw=0.8, ls=":")
        ax.annotate(rule, (float(axis(t)), 0.97), xycoords=("data", "axes fraction"),
                    fontsize=7, color="crimson", rotation=90, va="top", ha="right")
    if trace.cut_at is not None:
        ax.axvline(float(axis(trace.cut_at)), color="black", lw=1)
        ax.annotate(" plot cut here (too many changes)", (float(axis(trace.cut_at)), 0.5),
                    xycoords=("data", "axes fraction"), fontsize=8)
    ax.set_ylabel("position")
    low, high = min(x for _, x in trace.position), max(x for _, x in trace.position)
    if high - low < 2:  # standing still: a sensible scale around it, whole steps
        ax.set_ylim(low - 10, high + 10)
    ax.yaxis.get_major_locator().set_params(integer=True)
    ax.ticklabel_format(axis="y", style="plain", useOffset=False)
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left", fontsize=8, framealpha=0.8)


def _bars(ax, lanes: dict, rows: list, axis: TimeAxis, color: str, name: str) -> None:
    for y, n in enumerate(rows):
        spans = _spans(axis, lanes.get(n, ()))
        _lane(ax, spans, [color] * len(spans), (y + 0.15, 0.7), axis)
    ax.set_yticks([y + 0.5 for y in range(len(rows))], [str(n) for n in rows], fontsize=8)
    ax.set_ylim(len(rows), 0)
    ax.set_ylabel(name)
    ax.grid(axis="x", alpha=0.3)


def _spans(axis: TimeAxis, pairs) -> list[tuple[float, float]]:
    """(drawn start, drawn width) of (t0, t1, ...) in us, all mapped in one call."""
    if not pairs:
        return []
    x = axis([pair[:2] for pair in pairs])
    return list(zip(x[:, 0].tolist(), (x[:, 1] - x[:, 0]).tolist()))


def _lane(ax, spans: list, colors: list, height: tuple, axis: TimeAxis) -> None:
    """Bars in one collection (one per bar makes matplotlib rescale the axes each
    time: quadratic)."""
    spans, colors = _drawable(spans, colors, axis)
    ax.broken_barh(spans, height, color=colors)


def _drawable(spans: list, keys: list, axis: TimeAxis) -> tuple[list, list]:
    """A lane of more than LANE_STEPS bars drawn no finer than that; others as they are."""
    if len(spans) <= LANE_STEPS:
        return spans, keys
    return _coarse(spans, keys, (axis.drawn[-1] or 1.0) / LANE_STEPS)


def _coarse(spans: list, keys: list, step: float) -> tuple[list, list]:
    """The spans and keys of a lane drawn `step` fine: bars of one key less than `step`
    apart joined, and a run of bars narrower than `step` joined into a block about `step`
    wide, split between its keys in proportion (two macros taking turns stay two colours)."""
    blocks: list[list] = []  # [x0, x1, {key: width covered}]
    for (x, w), key in zip(spans, keys):
        last = blocks[-1] if blocks else None
        if last and x - last[1] < step and (
                last[2].keys() == {key} or (w < step and last[1] - last[0] < step)):
            last[1] = max(last[1], x + w)
            last[2][key] = last[2].get(key, 0.0) + w
        else:
            blocks.append([x, x + w, {key: w}])
    out_spans, out_keys = [], []
    for x0, x1, widths in blocks:
        total, at = sum(widths.values()) or 1.0, x0
        for key, w in widths.items():
            out_spans.append((at, (x1 - x0) * w / total))
            out_keys.append(key)
            at += (x1 - x0) * w / total
    return out_spans, out_keys


def _macros(ax, macros: list, axis: TimeAxis) -> None:
    import matplotlib

    tab20 = matplotlib.colormaps["tab20"]
    names = sorted({label for *_, label in macros})
    color = {label: tab20(i % 20) for i, label in enumerate(names)}
    spans = _spans(axis, macros)
    _lane(ax, spans, [color[label] for *_, label in macros], (0.1, 0.8), axis)
    total = axis.drawn[-1] or 1.0
    for (x0, width), (*_, label) in zip(spans, macros):
        if width > total * 0.035:
            ax.text(x0 + width / 2, 0.5, label, ha="center", va="center", fontsize=7, clip_on=True)
    ax.set_yticks([])
    ax.set_ylim(0, 1)
    ax.set_ylabel("macro", rotation=0, ha="right", va="center")
    ax.grid(axis="x", alpha=0.3)


def _skipped(ax, axis: TimeAxis, label: bool) -> None:
    """The compressed stretches hatched across the axes: one path of many parts, hatched
    once (hatching each band on its own costs milliseconds a band)."""
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path

    bands = _spans(axis, axis.stretches)
    if bands:
        drawn, _ = _drawable(bands, [None] * len(bands), axis)
        parts = [Path([(x, 0), (x, 1), (x + w, 1), (x + w, 0), (x, 0)], closed=True)
                 for x, w in drawn]
        # an artist, not a patch: the time axis is set, and its limits would walk every part
        ax.add_artist(PathPatch(Path.make_compound_path(*parts), transform=ax.get_xaxis_transform(),
                                facecolor="white", edgecolor="gray", hatch="///", lw=0, zorder=3))
    if label:
        _band_labels(ax, axis, bands)


def _band_labels(ax, axis: TimeAxis, bands: list) -> None:
    """Each band's real length, where the label does not cover the one before it."""
    total, placed = axis.drawn[-1] or 1.0, -math.inf
    for (x, w), (a, b) in zip(bands, axis.stretches):
        if x + w / 2 - placed < total * LABEL_WIDTH:
            continue
        placed = x + w / 2
        ax.text(placed, 0.5, f"{span(b - a)}\nfast-forwarded",
                transform=ax.get_xaxis_transform(), ha="center", va="center", fontsize=7,
                rotation=90, zorder=4, bbox={"facecolor": "white", "edgecolor": "gray"})


def write(path: str, trace: Trace, title: str = "") -> None:
    """The plot into PATH (whole or not at all), its kind from the ending."""
    plt = _pyplot()
    fig = figure(trace, title)
    kind = os.path.splitext(path)[1].lower().lstrip(".")
    try:
        if kind == "html":
            from mercmac.render import plot_html

            svg = io.StringIO()
            fig.savefig(svg, format="svg", metadata={"Date": None})
            page = plot_html.page(svg.getvalue(), data(trace), title)
            with replacing(path) as f:
                f.write(page)
        else:
            meta = {"pdf": {"CreationDate": None, "ModDate": None},
                    "svg": {"Date": None}}.get(kind, {})
            with replacing(path, binary=True) as f:
                fig.savefig(f, format=kind, dpi=110, metadata=meta)
    finally:
        plt.close(fig)


def data(trace: Trace) -> dict:
    """The lanes as plain numbers (ms), for the HTML page's readers and tests."""
    ms = 1e-3
    return {
        "lanes": list(LANES),
        "end_ms": trace.end * ms,
        "position": [[round(t * ms, 3), round(x, 1)] for t, x in trace.position],
        "target": [[t * ms, x] for t, x in trace.target],
        "buttons": {str(n): [[a * ms, b * ms] for a, b in v] for n, v in sorted(trace.inputs.items())},
        "LEDs": {str(n): [[a * ms, b * ms] for a, b in v] for n, v in sorted(trace.outputs.items())},
        "macro": [[a * ms, b * ms, label] for a, b, label in trace.macros],
        "fast_forwarded": [[a * ms, b * ms, passes, loop] for a, b, passes, loop in trace.skips],
        "hazards": [[t * ms, rule] for t, rule in trace.hazards],
    }
