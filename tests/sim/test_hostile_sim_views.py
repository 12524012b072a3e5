"""Views of a crowded run, and of empty names: the text
timeline says exactly what it leaves out, `-vv` shows it all, and `--plot` draws
thousands of presses as a few collections, in proportion to the run.
"""
from __future__ import annotations

import re
import subprocess
import sys

import pytest

from helpers.cli import cli
from helpers.compiling import program_of
from helpers.paths import FOUR_MODES

README_ARGS = [str(FOUR_MODES), "--buttons", "3@0-300ms,1@1s-1.2s",
               "--until", "3s"]
POLL = "autostart { every 1ms { when 1 { CN 1, WF 1, CF 1 } } }\n"
MORE = re.compile(r"^ +\.\.\. ([\d,]+) more lines? after ")


def presses(count: int, period_ms: int = 60, held_ms: int = 20) -> str:
    return ",".join(f"1@{i * period_ms}-{i * period_ms + held_ms}" for i in range(count))


def timeline(*args) -> list[str]:
    """The lines between the header and the summary of `mercmac sim ARGS`."""
    result = cli("sim", *args)
    assert result.exit_code == 0, result.output
    return result.output.split("\n\nSummary")[0].splitlines()[1:]


def verbose(level: int) -> list[str]:
    return ["-" + "v" * level] if level else []


def left_out(lines: list[str]) -> int:
    """The count the closing line gives (0 when there is none), checked to be a number."""
    counts = [int(m.group(1).replace(",", "")) for m in map(MORE.match, lines) if m]
    assert len(counts) <= 1 and not any("more event" in line for line in lines), lines[-3:]
    return counts[0] if counts else 0


@pytest.fixture
def crowded(write):
    """6,000 short presses of a polled button over 360 s (once slow to show)."""
    return [write(POLL), "--buttons", presses(6000), "--until", "360s"]


@pytest.mark.slow
def test_vv_shows_the_whole_360_s_run(crowded):
    lines = timeline(*crowded, "-vv")
    assert left_out(lines) == 0
    assert lines[-1].split()[:2] == ["360.000", "s"] and "end of the run" in lines[-1]
    assert float(lines[-2].split()[0]) > 359.9  # the last event, not a stop at 23 s
    assert sum("button 1 pressed" in line for line in lines) == 6000


@pytest.mark.slow
@pytest.mark.parametrize("level", [0, 1])
def test_the_story_stops_with_the_true_count_of_lines_left_out(crowded, level, monkeypatch):
    from mercmac.render import sim as render

    limit = render.TEXT_LIMIT
    shown = timeline(*crowded, *verbose(level))[:-1]  # without "end of the run"
    monkeypatch.setattr(render, "TEXT_LIMIT", 10**9)
    whole = timeline(*crowded, *verbose(level))[:-1]
    assert len(shown) == limit + 1 < len(whole)
    assert left_out(shown) == len(whole) - limit
    assert "-vv shows every line" in shown[-1]


@pytest.mark.parametrize("cap", [*range(1, 41)])  # the run makes 41 entries
def test_entries_past_the_recorders_cap_are_counted_as_the_lines_they_make(cap, monkeypatch):
    """Folds show at some verbosities only, and `-v` sums a stretch's polls in one line:
    the count must be what the whole timeline would show past the cut, at each level."""
    from mercmac.render import sim as render
    from mercmac.sim import record

    whole = {level: timeline(*README_ARGS, *verbose(level))[:-1] for level in (0, 1, 2)}
    monkeypatch.setattr(record, "TIMELINE_CAP", cap)
    cut = False
    for level in (0, 1, 2):
        shown = timeline(*README_ARGS, *verbose(level))[:-1]
        hidden = left_out(shown)
        assert len(shown) - bool(hidden) + hidden == len(whole[level]), (level, shown[-1])
        if hidden:  # none when all that was cut shows only at a higher verbosity
            assert f"the timeline keeps the first {cap:,} entries" in shown[-1]
        cut |= bool(hidden)
    assert cut
    assert render.TEXT_LIMIT > len(whole[2])  # only the recorder's cap cut these


@pytest.mark.parametrize("level", [0, 1])
def test_both_cuts_at_once_count_every_line_and_say_both(level, monkeypatch):
    from mercmac.render import sim as render
    from mercmac.sim import record

    whole = timeline(*README_ARGS, *verbose(level))[:-1]
    monkeypatch.setattr(record, "TIMELINE_CAP", 20)
    monkeypatch.setattr(render, "TEXT_LIMIT", 5)
    shown = timeline(*README_ARGS, *verbose(level))[:-1]
    assert len(shown) == 6 and left_out(shown) == len(whole) - 5
    assert "-vv shows more; the timeline keeps the first 20 entries" in shown[-1]


@pytest.mark.parametrize("option", ["--plot", "--vcd", "--scenario"])
def test_an_empty_file_name_is_refused(write, tmp_path, option, monkeypatch):
    monkeypatch.chdir(tmp_path)
    result = cli("sim", write(POLL), option, "")
    assert result.exit_code == 2, result.output
    assert "an empty file name" in result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p.mcm"]


def test_an_empty_plot_name_is_refused_by_the_command_as_run(write, tmp_path):
    done = subprocess.run([sys.executable, "-m", "mercmac", "sim", write(POLL), "--plot", ""],
                          capture_output=True, text=True, cwd=tmp_path, timeout=60)
    assert done.returncode == 2 and "an empty file name" in done.stderr
    assert "Traceback" not in done.stderr and sorted(p.name for p in tmp_path.iterdir()) == ["p.mcm"]


# --- the plot of a crowded run ---------------------------------------------------------

def _trace(source: str, buttons: str, until_ms: int):
    from mercmac.sim import plot
    from mercmac.sim.simulate import simulate_program
    from mercmac.timespec import parse_buttons

    watch = plot.PlotObserver()
    simulate_program(program_of(source), presses=parse_buttons(buttons), until_ms=until_ms, watch=watch)
    return watch.close(until_ms * 1000)


@pytest.fixture
def plot():
    pytest.importorskip("matplotlib")
    from mercmac.sim import plot

    return plot


def test_each_lane_is_one_collection_and_a_crowded_one_is_drawn_coarser(plot):
    trace = _trace(POLL, presses(1000), 60_000)  # 6,000 macro changes, 2,000 LED changes
    assert len(trace.macros) > plot.LANE_STEPS
    fig = plot.figure(trace)
    try:
        buttons, leds, macro = fig.axes[1:]
        assert len(macro.collections) == 1  # was one collection per macro change
        bars = macro.collections[0]
        assert len(bars.get_paths()) <= 2 * plot.LANE_STEPS
        colours = {tuple(c) for c in bars.get_facecolors()}
        assert len(colours) == 2  # both macros still show: blocks split between them
        assert [len(c.get_paths()) for c in buttons.collections] == [1000, 0, 0, 0]
    finally:
        import matplotlib.pyplot as plt

        plt.close(fig)


def test_coarse_lanes_keep_wide_bars_and_share_a_block_between_keys(plot):
    wide = [(0.0, 5.0), (10.0, 5.0)]
    assert plot._coarse(wide, ["a", "b"], 1.0) == (wide, ["a", "b"])
    near = [(0.0, 2.0), (2.5, 2.0)]  # one key, a gap under a step: one bar
    assert plot._coarse(near, ["a", "a"], 1.0) == ([(0.0, 4.5)], ["a"])
    turns = [(i * 0.1, 0.1) for i in range(10)]  # a and b taking turns, 0.1 wide each
    spans, keys = plot._coarse(turns, ["a", "b"] * 5, 0.5)  # blocks a,b,a,b,a and b,a,b,a,b
    assert keys == ["a", "b", "b", "a"]
    assert [v for span in spans for v in span] == pytest.approx([0, 0.3, 0.3, 0.2, 0.5, 0.3, 0.8, 0.2])


def test_a_move_under_a_1ms_poll_is_sampled_per_segment_not_per_event(plot):
    source = "autostart {\n  MR 200000\n  every 1ms { when 1 { CN 1 } }\n}\n"
    trace = _trace(source, "", 5000)  # 4.56 s of motion, a poll every 4 ms
    assert len(trace.position) <= 3 * (plot.CURVE + 1) + 4
    t, x = zip(*trace.position)
    assert list(t) == sorted(t)
    assert x[-1] == 200000 and max(x) == pytest.approx(200000)


def test_many_compressed_stretches_draw_one_hatch_and_labels_that_fit(plot):
    trace = _trace(POLL, presses(300, 20_000), 300 * 20_000)
    fig = plot.figure(trace)
    try:
        top = fig.axes[0]
        assert sum(p.get_hatch() == "///" for p in top.patches) == 1
        labels = [t for t in top.texts if "fast-forwarded" in t.get_text()]
        assert 1 <= len(labels) <= 1 / plot.LABEL_WIDTH + 1
    finally:
        import matplotlib.pyplot as plt

        plt.close(fig)


@pytest.mark.slow
def test_the_html_of_6000_presses_is_a_few_mb(plot, crowded, tmp_path):
    out = tmp_path / "run.html"
    result = cli("sim", *crowded, "--plot", out)
    assert result.exit_code == 0, result.output
    page = out.read_text(encoding="utf-8")
    svg = page[:page.index('<script type="application/json"')]
    assert len(svg) < 2_000_000  # was 15 MB of SVG, one path per press and macro change
    assert "<svg" in svg and page.rstrip().endswith("</html>")
