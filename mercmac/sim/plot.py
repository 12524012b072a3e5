"""A picture of a run (`--plot`): position and target over time, lanes below.

The lanes are the buttons held, the LEDs lit and the running macro by name. A
long fast-forwarded stretch (a day of polling), and the idle time after the
program ended, is drawn compressed to a short hatched band labelled with its
real length, a broken time axis, so that the seconds of action around it stay
readable. The position axis spans where the stage goes; a target far outside
it (a jog's 9999999, stopped after a moment) is an arrow on the edge with its
value. A label is drawn only where it fits. PNG, SVG and PDF come from
matplotlib (the extra `plot`, imported only here and only when drawing); HTML is
the SVG in a page that zooms and pans (plot_html.py). A rig's plot (rig_plot.py) is
made of the same lanes: `position`, `bars`, `macros`, `time_lanes` and `save`.
Skipped passes that move are drawn as copies of the pass before them.
"""
from __future__ import annotations

import io
import math
import os
import re
from bisect import bisect_left, bisect_right
from dataclasses import dataclass, field

from mercmac.errors import InputError
from mercmac.outfile import replacing, writable_target
from mercmac.timespec import format_clock, format_span
from mercmac.vm import events as ev
from mercmac.vm import shapes

FORMATS = (".png", ".svg", ".pdf", ".html")
MISSING = "needs the plot extra: pip install 'mercmac[plot]'"
COMPRESS_US = 10_000_000  # skipped stretches longer than this (10 s) are drawn compressed
BAND = 0.06  # a compressed stretch's width, as a share of the time drawn to scale
CURVE = 16  # points per accelerating profile segment
COPIED = 20_000  # position samples of skipped passes drawn as copies of the pass before
SKIP_OUTPUTS = 1000  # output changes of one skip drawn one by one; more: its last pattern
CAP = 200_000  # recorded changes; past this the plot stops (a marked cut) and the run goes on
LANES = ("position", "buttons", "LEDs", "macro")
# A lane of more bars than this is drawn at 1/3000 of the time axis, a quarter of a point
# on the page: every bar has a 1-pt edge of its colour, which covers finer gaps at any
# zoom (an SVG zooms its edges too); 36,000 macro changes cost a few thousand bars.
LANE_STEPS = 3000
BAND_STEPS = 1000  # the hatching of thousands of bands, about a pixel fine (it costs by the part)
TICK_ROOM = 0.05  # a piece drawn to scale narrower than this share gets no round ticks inside
LABEL_WIDTH = 0.03  # a band's label (two lines of 7 pt, turned, boxed): 3% of the time axis
LABEL_ROOM = 0.015  # a lane label is tried only where this share of the time axis is free
LABEL_PAD = 4  # pixels: a label fits when it is this much narrower than its room


class PlotError(InputError):
    """A picture that cannot be drawn (a kind of file not made here, no matplotlib); the
    message reads on from the option that asked for it (`--plot`)."""


def check_target(path: str) -> None:
    """Refuse before any simulating: an unknown kind of file, a bad path, no matplotlib."""
    if os.path.splitext(path)[1].lower() not in FORMATS:
        raise PlotError(f"{path}: the file must end in .png, .svg, .pdf or .html")
    writable_target(path)
    _pyplot()


def _pyplot():
    try:
        import matplotlib
    except ImportError:
        raise PlotError(MISSING) from None
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
    # long skips that move: (t, t_to, (low, high) at t, (low, high) at t_to), the band the
    # position sweeps (its min and max in every pixel column, one pass wide)
    envelopes: list = field(default_factory=list)
    actions: list = field(default_factory=list)  # times of input changes, moves, hazards
    hazards: list = field(default_factory=list)  # (t, rule)
    end: int = 0
    cut_at: int | None = None  # where recording stopped at CAP
    ended: int | None = None  # when the program ended (back in direct mode), if it stayed so
    idle_from: int | None = None  # from here to the end: program ended, stage at rest, no input
    unit: str = "counts"  # what positions count in (commands.unit: steps on a C-663)


class PlotObserver:
    """An event listener that keeps a Trace (the machine's listeners); call `close`."""

    def __init__(self, unit: str = "counts"):
        self.trace = Trace(unit=unit)
        self.segments: tuple = ()
        self.planned = None  # what a kept profile was planned from (MoveStarted.plan)
        self.sampled_to = 0.0
        self.held: dict[int, int] = {}  # input -> since
        self.lit: dict[int, int] = {}  # output -> since
        self.macro: tuple[int, str] | None = None  # (since, label)
        self.changes = 0

    def on_event(self, event) -> None:
        if self.trace.cut_at is None:
            self._take(event)

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
                self.trace.ended = None
                self._enter(label, t)
            case ev.ProgramEnded():
                self.trace.ended = t
            case ev.MacroLeft(back_to=back):
                self._enter(back, t)
            case ev.MoveStarted(_, _, target, _, segments):
                self.trace.target.append((t, target))
                self._mark(t)
                self.segments, self.sampled_to = segments, t
                self.planned = event.plan
            case ev.MoveEnded(_, _, position):
                self.segments = ()
                self.trace.position.append((t, float(position)))
            case ev.HomeDefined(_, position):
                self._mark(t)
                self.segments = ()
                self.trace.position.append((t, float(position)))
                self.trace.target.append((t, position))
            case ev.HazardFound(_, rule, _, _, False):  # an accepted one is no warning
                self.trace.hazards.append((t, rule))
            case ev.FastForwarded(_, t_to, passes, _, loop, shape):
                self.trace.skips.append((t, t_to, passes, loop.label))
                self._skipped_outputs(event)
                if event.steady:
                    self._steady(event)
                elif not shapes.plain(shape) or event.shift:
                    self._moved(event)

    def _skipped_outputs(self, skip: ev.FastForwarded) -> None:
        """The output changes of skipped passes, each where a few (a rig's wire lanes show
        every handshake); of many, the pattern the last pass leaves (a hatched band)."""
        if shapes.count(skip.shape, shapes.OUTPUTS) * skip.passes > SKIP_OUTPUTS:
            last = _last_pattern(skip.shape)
            if last is not None:
                self._pattern(last, skip.t_to)
            return
        for change in shapes.expand(skip.shape, skip.t, skip.period, skip.passes, shapes.OUTPUTS,
                                    skip.position, skip.shift):
            self._pattern(change.pattern, change.t)

    def _steady(self, skip: ev.FastForwarded) -> None:
        """Skipped passes that leave the profile going on: the stage follows it through them,
        to the target they moved it on to (Axis.retarget), sampled as it goes."""
        if skip.shift:
            final = skip.position + skip.passes * skip.shift
            self.segments = self.planned._replace(target=final).segments()
            self.trace.target.append((skip.t_to, final))

    def _moved(self, skip: ev.FastForwarded) -> None:
        """Skipped passes that move: copies of the pass before them while they are few,
        else the position where they start and where the last one ends, nothing between."""
        self._follow(skip.t)
        span, moved = skip.t_to - skip.t, skip.passes * skip.shift
        if not self._copied(skip):
            self._envelope(skip)
            self.trace.position += [(skip.t, float(skip.position)),
                                    (skip.t_to, float(skip.position + moved))]
            self.trace.target.append((skip.t_to, self.trace.target[-1][1] + moved))
        # a move running across the skip's end runs on as the copy of the one before it
        self.segments = tuple(seg.moved(span, moved) for seg in self.segments)
        self.sampled_to = skip.t_to

    def _copied(self, skip: ev.FastForwarded) -> bool:
        """The positions and targets of skipped passes drawn as those of the pass before
        them, each `shift` further (the passes are copies: vm/skips.py); False
        when that pass has no samples or the copies would be more than COPIED."""
        before = skip.t - skip.period
        last = _since(self.trace.position, before, skip.t)
        if not last or len(last) * skip.passes > COPIED:
            return False
        for into, pass_ in ((self.trace.position, last),
                            (self.trace.target, _since(self.trace.target, before, skip.t))):
            into += [(t + k * skip.period, x + k * skip.shift)
                     for k in range(1, skip.passes + 1) for t, x in pass_]
        return True

    def _envelope(self, skip: ev.FastForwarded) -> None:
        """The band a long skip's passes sweep: the pass before it spans low..high about its
        start, and each pass starts `shift` further, so in a pixel column of many passes the
        position's min and max lie on two straight lines (the passes are copies)."""
        start = skip.position - skip.shift  # where the pass before began
        seen = [x for _, x in _since(self.trace.position, skip.t - skip.period, skip.t)]
        low, high = min(seen, default=start) - start, max(seen, default=start) - start
        last = skip.position + (skip.passes - 1) * skip.shift
        self.trace.envelopes.append((skip.t, skip.t_to, (skip.position + low, skip.position + high),
                                     (last + low, last + high)))

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
        if self.trace.ended is not None and not self.segments:  # a move still running is no idle
            self.trace.idle_from = max([self.trace.ended, *self.trace.actions[-1:]])
        return self.trace


def _since(samples: list, a: float, b: float) -> list:
    """The (t, value) samples with a <= t < b (samples in time order)."""
    return samples[bisect_left(samples, a, key=_time):bisect_left(samples, b, key=_time)]


def _time(sample: tuple) -> float:
    return sample[0]


def _last_pattern(shape: tuple) -> int | None:
    """The output pattern a skipped pass leaves behind, if it changes any."""
    last = None
    for step in shapes.compact(shape, 0, 0, 1):  # one pass: only the patterns matter here
        match step:
            case ev.OutputsChanged(_, pattern):
                last = pattern
    return last


class TimeAxis:
    """Real time (us) -> drawn seconds: long skipped stretches, and a long idle tail after
    the program's end (`idle_from`), squeezed to short bands."""

    def __init__(self, skips: list, end: int, actions: list = (), idle_from: int | None = None):
        stretches = [(a, b) for a, b in _merged(skips, sorted(actions)) if b - a >= COMPRESS_US]
        self.stretches = [(a, min(b, end)) for a, b in stretches if a < end]
        self.idle = None  # the idle tail's stretch, when it is drawn compressed
        if idle_from is not None and end - idle_from >= COMPRESS_US:
            self.idle = (max([idle_from, *(b for _, b in self.stretches[-1:])]), end)
            self.stretches.append(self.idle)
        scaled = max(end - sum(b - a for a, b in self.stretches), 1000)
        # all bands together no wider than the parts drawn to scale (thousands of skips)
        width = scaled * min(BAND, 1 / max(len(self.stretches), 1))
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

        total, pieces = self.drawn[-1] or 1.0, self.pieces()
        # the run's start (0 s) first, then its end (--until: '60 s', never the start of the
        # last stepped millisecond), then where each piece after a band starts
        real = self.real[-1] - self.real[0]
        wanted = [(self.drawn[0], self.real[0]), (self.drawn[-1], self.real[-1])]
        wanted += [(d0, _round(r0, real)) for r0, r1, d0, d1 in pieces[1:]]
        for r0, r1, d0, d1 in pieces:
            if d1 - d0 < total * TICK_ROOM:  # its start is all the ticks it has room for
                continue
            bins = max(1, round(8 * (d1 - d0) / total))
            wanted += [(self._at(r), r) for r in MaxNLocator(bins + 1).tick_values(r0, r1)
                       if r0 - 1e-9 <= r <= r1 + 1e-9]
        placed: list[tuple[float, str]] = []
        for d, r in wanted:
            # too close to a placed label even for an empty one: not worth wording
            if any(abs(d - pd) <= total * (len(pt) / 2 + 2) / 110 for pd, pt in placed):
                continue
            text = duration(r)
            if all(abs(d - pd) > total * ((len(text) + len(pt)) / 2 + 2) / 110 for pd, pt in placed):
                placed.append((d, text))
        placed.sort()
        return [d for d, _ in placed], [t for _, t in placed]

    def _at(self, seconds: float) -> float:
        import numpy as np

        return float(np.interp(seconds, self._xp, self._fp))


def _round(seconds: float, total: float) -> float:
    """A band's end as its tick says it: to a thousandth of the whole run (a 60 s run's
    piece starts at '59.984 s', not '59.98376 s'); the tick stands where it truly is."""
    import math

    if total <= 0:
        return seconds
    places = max(0, 3 - math.floor(math.log10(total)))
    return round(seconds, places)


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
    """A tick's label (the axis counts seconds): 1.5 -> '1.5 s'; 90061.5 -> '1 d 1:01:01.5'."""
    return format_clock(seconds * 1e6)


def span(us: float) -> str:
    """A skipped stretch's length in whole units: '23 h 59 min' (not '1 d'), '2 min 5 s'."""
    return format_span(us, parts=2)


def figure(trace: Trace, title: str = ""):
    """A matplotlib figure of the trace: position over the lanes, one shared time axis."""
    plt = styled()
    axis = _time_axis(trace)
    inputs = sorted(set(trace.inputs) | {1, 2, 3, 4})
    fig, axes = plt.subplots(4, 1, sharex=True, figsize=(11, 6.5), layout="constrained",
                             gridspec_kw={"height_ratios": [5, 0.45 * len(inputs), 1.8, 0.8]})
    position(axes[0], trace, axis)
    bars(axes[1], trace.inputs, inputs, axis, "tab:blue", "buttons")
    bars(axes[2], trace.outputs, [1, 2, 3, 4], axis, "tab:orange", "LEDs")
    macros(axes[3], trace.macros, axis)
    time_lanes(axes, axis)
    if title:
        fig.suptitle(title, fontsize=11)
    return fig


def styled():
    """pyplot, set to make files that are the same for the same run."""
    plt = _pyplot()
    plt.rcParams["svg.fonttype"] = "none"  # text stays text in an SVG (searchable, testable)
    plt.rcParams["svg.hashsalt"] = "mercmac"  # the same run gives the same file
    return plt


def time_lanes(axes, axis: TimeAxis) -> None:
    """Lanes on one time axis (top first): the compressed stretches hatched across all,
    labelled on the top one, the real times ticked on the bottom one."""
    bands = _spans(axis, axis.stretches)
    hatch = _hatch(bands, axis)
    for ax in axes:
        _skipped(ax, hatch)
    _band_labels(axes[0], axis, bands)
    where, text = axis.ticks()
    axes[-1].set_xticks(where, text)
    axes[-1].set_xlim(0, axis.drawn[-1])
    axes[-1].set_xlabel("time" + _broken(axis))


def _time_axis(trace: Trace) -> TimeAxis:
    return TimeAxis(trace.skips, trace.end, trace.actions, trace.idle_from)


def _broken(axis: TimeAxis) -> str:
    """What the time axis label says about its hatched bands."""
    kinds = [kind for kind, there in (("fast-forwarded", len(axis.stretches) > bool(axis.idle)),
                                      ("idle after the program ended", axis.idle)) if there]
    return f" (hatched: {' or '.join(kinds)}, drawn compressed)" if kinds else ""


def position(ax, trace: Trace, axis: TimeAxis) -> None:
    """Position and target over time; far targets as arrows on the edge, hazards marked."""
    t, x = zip(*trace.position)
    ax.plot(axis(t), x, color="tab:blue", lw=1.6, label="position")
    for t0, t1, at0, at1 in trace.envelopes:  # above the hatching (zorder 3) of its band
        ax.fill_between(axis([t0, t1]), [at0[0], at1[0]], [at0[1], at1[1]], color="tab:blue",
                        alpha=0.45, lw=0.8, edgecolor="tab:blue", zorder=4)
    t, x = zip(*trace.target)
    ax.step(axis(t), x, where="post", color="tab:red", lw=1, ls="--", label="target")
    low, high = _y_range(trace)
    ax.set_ylim(low, high)
    _clipped_targets(ax, _clipped(trace, (low, high)), axis)
    for t, rule in trace.hazards:
        ax.axvline(float(axis(t)), color="crimson", lw=0.8, ls=":")
        ax.annotate(rule, (float(axis(t)), 0.97), xycoords=("data", "axes fraction"),
                    fontsize=7, color="crimson", rotation=90, va="top", ha="right")
    if trace.cut_at is not None:
        _cut(ax, float(axis(trace.cut_at)), axis.drawn[-1])
    ax.set_ylabel(f"position ({trace.unit})")
    ax.yaxis.get_major_locator().set_params(integer=True)
    ax.ticklabel_format(axis="y", style="plain", useOffset=False)
    ax.grid(alpha=0.3)
    # above the axes: inside, it would cover the start of the run and its target arrows
    ax.legend(loc="lower right", bbox_to_anchor=(1, 1), ncols=2, fontsize=8, frameon=False,
              borderaxespad=0.1)


def _cut(ax, x: float, total: float) -> None:
    """The line where recording stopped, its note on the side with room (never widening
    the figure: the note is left out of the layout)."""
    ax.axvline(x, color="black", lw=1)
    right = x > total / 2
    note = ax.annotate("plot cut here (too many changes)", (x, 0.5), xytext=(-4 if right else 4, 0),
                       xycoords=("data", "axes fraction"), textcoords="offset points",
                       ha="right" if right else "left", fontsize=8)
    note.set_in_layout(False)


def _y_range(trace: Trace) -> tuple[float, float]:
    """The position axis: where the stage goes, with the targets near it; a margin of 5%."""
    xs = [x for _, x in trace.position] + [x for *_, at0, at1 in trace.envelopes
                                            for x in (*at0, *at1)]
    low, high = min(xs), max(xs)
    reach = max(high - low, 10)  # a target further out than the travel itself is clipped
    near = [x for _, x in trace.target if low - reach <= x <= high + reach]
    low, high = min([low, *near]), max([high, *near])
    if high - low < 2:  # standing still: a sensible scale around it, whole steps
        return low - 10, high + 10
    return low - (high - low) * 0.05, high + (high - low) * 0.05


def _clipped(trace: Trace, shown: tuple[float, float]) -> list[tuple[int, int]]:
    """The targets set outside the position axis: (t, target)."""
    low, high = shown
    return [(t, x) for t, x in trace.target[1:-1] if not low <= x <= high]


def _clipped_targets(ax, targets: list, axis: TimeAxis) -> None:
    """Each target beyond the axis as an arrow on its edge, pointing out; its value beside
    it where there is room before the next one."""
    if not targets:
        return
    at = axis([t for t, _ in targets]).tolist()
    up = [target > ax.get_ylim()[0] for _, target in targets]  # outside: above or below
    for edge in (True, False):
        _arrows(ax, [x for x, above in zip(at, up) if above == edge], edge)
    total = axis.drawn[-1] or 1.0
    for x, until, above, (_, target) in zip(at, at[1:] + [total], up, targets):
        if until - x >= total * LABEL_ROOM:
            _fit(_target_label(ax, x, target, above), (x, until), (f"target {target}",))


def _arrows(ax, xs: list, up: bool) -> None:
    """Arrow heads on the top (or bottom) edge at xs, in one artist."""
    if xs:  # on the edge, outside the clip; left out of the layout like the axes' spines
        ax.plot(xs, [1 if up else 0] * len(xs), ls="none", marker="^" if up else "v", ms=8,
                color="tab:red", transform=ax.get_xaxis_transform(), clip_on=False,
                zorder=5)[0].set_in_layout(False)


def _target_label(ax, x: float, target: int, up: bool):
    return ax.annotate(f"target {target}", (x, 1 if up else 0), xytext=(5, -4 if up else 4),
                       xycoords=ax.get_xaxis_transform(), textcoords="offset points",
                       va="top" if up else "bottom", fontsize=7, color="tab:red",
                       bbox={"facecolor": "white", "edgecolor": "none", "pad": 1,
                             "alpha": 0.6})  # readable, and the curve shows through


def _fit(label, room: tuple[float, float], texts: tuple[str, ...]) -> None:
    """Draw `label` with the first of `texts` whose width fits in `room` (time axis
    from, to), or not at all: whether it fits is known only when drawing, after the
    layout, so the label's own draw is wrapped (its text is then what was drawn)."""
    plain = label.draw

    def draw(renderer):
        left, right = label.axes.transData.transform([(room[0], 0), (room[1], 0)])[:, 0]
        for text in texts:
            label.set_text(text)
            if label.get_window_extent(renderer).width + LABEL_PAD <= right - left:
                return plain(renderer)
        label.set_text("")

    label.set_in_layout(False)
    label.draw = draw


def bars(ax, lanes: dict, rows: list, axis: TimeAxis, color: str, name: str) -> None:
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


def macros(ax, macros: list, axis: TimeAxis) -> None:
    import matplotlib

    tab20 = matplotlib.colormaps["tab20"]
    names = sorted({label for *_, label in macros})
    color = {label: tab20(i % 20) for i, label in enumerate(names)}
    spans = _spans(axis, macros)
    _lane(ax, spans, [color[label] for *_, label in macros], (0.1, 0.8), axis)
    total = axis.drawn[-1] or 1.0
    for (x0, width), (*_, label) in zip(spans, macros):
        if width > total * LABEL_ROOM:
            text = ax.text(x0 + width / 2, 0.5, label, ha="center", va="center", fontsize=7)
            _fit(text, (x0, x0 + width), (label, *re.findall(r"\((MC\d+)\)$", label)))
    ax.set_yticks([])
    ax.set_ylim(0, 1)
    ax.set_ylabel("macro", rotation=0, ha="right", va="center")
    ax.grid(axis="x", alpha=0.3)


def _hatch(bands: list, axis: TimeAxis):
    """The compressed stretches as one path of many parts, for every lane (hatching each
    band on its own costs milliseconds a band); None without any."""
    from matplotlib.path import Path

    if not bands:
        return None
    parts = [Path([(x, 0), (x, 1), (x + w, 1), (x + w, 0), (x, 0)], closed=True)
             for x, w in _band_parts(bands, axis)]
    return Path.make_compound_path(*parts)


def _band_parts(bands: list, axis: TimeAxis) -> list:
    """More than BAND_STEPS bands drawn no finer, each block hatched in the share of its
    time that was skipped: what happened between the bands stays visible beside them."""
    if len(bands) <= BAND_STEPS:
        return bands
    gaps = [(x + w, after - x - w) for (x, w), (after, _) in zip(bands, bands[1:])]
    spans = [span for pair in zip(bands, gaps) for span in pair] + bands[-1:]
    spans, skipped = _coarse(spans, [True, False] * len(gaps) + [True],
                             (axis.drawn[-1] or 1.0) / BAND_STEPS)
    return [span for span, band in zip(spans, skipped) if band]


def _skipped(ax, hatch) -> None:
    """The compressed stretches hatched across the axes, above the lanes."""
    from matplotlib.patches import PathPatch

    if hatch is not None:
        # an artist, not a patch: the time axis is set, and its limits would walk every part
        ax.add_artist(PathPatch(hatch, transform=ax.get_xaxis_transform(), facecolor="white",
                                edgecolor="gray", hatch="///", lw=0, zorder=3))


def _band_labels(ax, axis: TimeAxis, bands: list) -> None:
    """Each band's real length, where the label does not cover the one before it."""
    total, placed = axis.drawn[-1] or 1.0, -math.inf
    for (x, w), (a, b) in zip(bands, axis.stretches):
        if x + w / 2 - placed < total * LABEL_WIDTH:
            continue
        placed = x + w / 2
        what = "idle: program ended" if (a, b) == axis.idle else "fast-forwarded"
        ax.text(placed, 0.5, f"{span(b - a)}\n{what}",
                transform=ax.get_xaxis_transform(), ha="center", va="center", fontsize=7,
                rotation=90, zorder=4, bbox={"facecolor": "white", "edgecolor": "gray"})


def watches(rig) -> dict[str, PlotObserver]:
    """One plot listener per controller of the rig, to hear its machine during the run."""
    from mercmac.commands import unit

    return {c.name: PlotObserver(unit(c.model)) for c in rig.controllers}


def write_run(path: str, rig, watched: dict[str, PlotObserver], end_us: int,
              title: str = "") -> None:
    """The picture of a run into PATH, each listener closed at end_us: a lone controller's
    lanes (`figure`), or a rig's lanes per controller and its path (rig_plot.py)."""
    if rig.several:
        from mercmac.sim import rig_plot

        rig_plot.write(path, rig_plot.trace_of(rig, watched, end_us), title)
        return
    (only,) = watched.values()
    write(path, only.close(end_us), title)


def write(path: str, trace: Trace, title: str = "") -> None:
    """The plot into PATH (whole or not at all), its kind from the ending."""
    save(path, figure(trace, title), lambda: data(trace), title)


def save(path: str, fig, data_of, title: str = "", lanes: str = "") -> None:
    """A figure into PATH (whole or not at all), its kind from the ending, then closed;
    an HTML page also holds `data_of()` and says what `lanes` are drawn."""
    plt = _pyplot()
    kind = os.path.splitext(path)[1].lower().lstrip(".")
    try:
        if kind == "html":
            from mercmac.sim import plot_html

            svg = io.StringIO()
            fig.savefig(svg, format="svg", metadata={"Date": None})
            page = plot_html.page(svg.getvalue(), data_of(), title, lanes)
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
    ms, shown, axis = 1e-3, _y_range(trace), _time_axis(trace)
    return {
        "lanes": list(LANES),
        "unit": trace.unit,  # of the positions (commands.unit)
        "end_ms": trace.end * ms,
        "position": [[round(t * ms, 3), round(x, 1)] for t, x in trace.position],
        "target": [[t * ms, x] for t, x in trace.target],
        "buttons": {str(n): [[a * ms, b * ms] for a, b in v] for n, v in sorted(trace.inputs.items())},
        "LEDs": {str(n): [[a * ms, b * ms] for a, b in v] for n, v in sorted(trace.outputs.items())},
        "macro": [[a * ms, b * ms, label] for a, b, label in trace.macros],
        "fast_forwarded": [[a * ms, b * ms, passes, loop] for a, b, passes, loop in trace.skips],
        "hazards": [[t * ms, rule] for t, rule in trace.hazards],
        "ended_ms": None if trace.ended is None else trace.ended * ms,
        # as drawn: the position axis, the targets beyond it (arrows), the compressed bands
        "position_range": [round(v, 1) for v in shown],
        "clipped_targets": [[t * ms, x] for t, x in _clipped(trace, shown)],
        "compressed": [[a * ms, b * ms, "idle" if (a, b) == axis.idle else "fast-forwarded"]
                       for a, b in axis.stretches],
    }
