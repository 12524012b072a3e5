"""`sim --plot` tells the truth.

The README tour's jog sets a target of 9999999 and is stopped after 300 ms: the position
axis spans where the stage goes (0 .. 20650), and the far target is an arrow on the edge
with its value. Macro labels that do not fit their bar are left out. A run whose program
ends long before `--until` has its idle tail drawn compressed, like a skipped stretch.
The figures are read back from matplotlib as `sim` drew them; the HTML page from its data
and its SVG.
"""
from __future__ import annotations

import shlex

import pytest

from helpers.cli import cli
from helpers.plots import inline_svg, page_data, svg_texts
from helpers.readme import commands, tour_program

pytest.importorskip("matplotlib")

from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: E402
from matplotlib.patches import PathPatch  # noqa: E402

from mercmac.sim import plot  # noqa: E402

FAR = 9_999_999
# moves out and back, and ends at 2.22 s; the move back arrives at 2.78 s
ONCE = "target C-863\nautostart {\n    MR 50000, WS, MR -20000\n}\n"
ARRIVED_MS = 2780.557


@pytest.fixture
def drawn(monkeypatch):
    """The figures `sim --plot` makes, kept (and given a canvas again) after it closed them."""
    figures = []
    make = plot.figure

    def figure(*args, **kw):
        figures.append(make(*args, **kw))
        return figures[-1]

    monkeypatch.setattr(plot, "figure", figure)
    return figures


def _rendered(fig):
    """The figure drawn once more (as the file was), and the renderer that drew it."""
    FigureCanvasAgg(fig).draw()
    return fig, fig.canvas.get_renderer()


def _tour(folder, out):
    """The README's tour command, as the README writes it, with `--plot OUT`."""
    (folder / "prog.mcm").write_text(tour_program(), encoding="utf-8")
    (command,) = [c for c in commands() if c.startswith("mercmac sim prog.mcm")]
    args = shlex.split(command)[1:]
    result = cli(*[folder / a if a == "prog.mcm" else a for a in args], "--plot", out)
    assert result.exit_code == 0, result.output
    return result


def _once(folder, out):
    (folder / "once.mcm").write_text(ONCE, encoding="utf-8")
    result = cli("sim", folder / "once.mcm", "--until", "1h", "--plot", out)
    assert result.exit_code == 0, result.output
    return result


def _drawn_texts(ax) -> list:
    return [t for t in ax.texts if t.get_visible() and t.get_text()]


def test_the_tour_position_axis_spans_where_the_stage_goes(tmp_path, drawn):
    _tour(tmp_path, tmp_path / "tour.png")
    low, high = drawn[-1].axes[0].get_ylim()
    assert low <= 0 and high >= 20_650  # out to 20650 and back to 10650
    assert high < 2 * 20_650  # not 9999999: the motion is not a flat line at 0


def test_a_target_beyond_the_axis_is_an_arrow_with_its_value(tmp_path, drawn):
    _tour(tmp_path, tmp_path / "tour.png")
    fig, _ = _rendered(drawn[-1])
    ax = fig.axes[0]
    arrows = [line for line in ax.lines if line.get_marker() == "^"]
    assert len(arrows) == 1 and list(arrows[0].get_ydata()) == [1]  # on the top edge
    assert arrows[0].get_xdata()[0] < 0.05  # set at 5 ms
    assert [t.get_text() for t in _drawn_texts(ax)] == [f"target {FAR}"]


def _overlap(a, b) -> bool:
    return a.x0 < b.x1 and b.x0 < a.x1 and a.y0 < b.y1 and b.y0 < a.y1


def test_no_two_macro_labels_overlap(tmp_path, drawn):
    _tour(tmp_path, tmp_path / "tour.png")
    fig, renderer = _rendered(drawn[-1])
    labels = _drawn_texts(fig.axes[3])
    assert "jog (MC01)" in [t.get_text() for t in labels]  # the long stretch keeps its name
    boxes = [t.get_window_extent(renderer) for t in labels]
    assert not [(labels[i].get_text(), labels[j].get_text()) for i in range(len(boxes))
                for j in range(i) if _overlap(boxes[i], boxes[j])]


def test_the_idle_tail_of_an_ended_run_is_drawn_compressed(tmp_path, drawn):
    _once(tmp_path, tmp_path / "once.png")
    fig = drawn[-1]
    assert fig.axes[-1].get_xlim()[1] < 10  # seconds drawn: 2.8 s of action and a band
    assert any(isinstance(a, PathPatch) and a.get_hatch() for a in fig.axes[0].get_children())
    assert "idle" in fig.axes[-1].get_xlabel()
    assert any("idle" in t.get_text() for t in fig.axes[0].texts)
    assert [t.get_text() for t in fig.axes[-1].get_xticklabels()][-1] == "1:00:00"


def test_a_move_still_running_after_the_program_ended_is_not_idle(tmp_path):
    """The tail is idle only once the stage rests: the jog runs 143 s after the program ends."""
    (tmp_path / "far.mcm").write_text(f"autostart {{ MR {FAR} }}\n", encoding="utf-8")
    assert cli("sim", tmp_path / "far.mcm", "--until", "1min", "--plot",
               tmp_path / "far.html").exit_code == 0
    data = page_data((tmp_path / "far.html").read_text(encoding="utf-8"))
    assert data["ended_ms"] is not None and data["compressed"] == []
    assert data["clipped_targets"] == [[0.0, FAR]]


def test_the_html_page_follows_the_same_rules(tmp_path):
    _tour(tmp_path, tmp_path / "tour.html")
    page = (tmp_path / "tour.html").read_text(encoding="utf-8")
    data, texts = page_data(page), svg_texts(inline_svg(page))
    low, high = data["position_range"]
    assert low <= 0 and 20_650 <= high < 2 * 20_650
    assert [x for _, x in data["clipped_targets"]] == [FAR]
    assert f"target {FAR}" in texts
    assert "jog (MC01)" in texts and "jog.when@11 (MC03)" not in texts  # too long for its bar
    _once(tmp_path, tmp_path / "once.html")
    page = (tmp_path / "once.html").read_text(encoding="utf-8")
    data = page_data(page)
    assert data["compressed"] == [[pytest.approx(ARRIVED_MS), 3_600_000, "idle"]]
    assert "idle: program ended" in " ".join(svg_texts(inline_svg(page)))


def test_the_run_starts_at_0_s_before_thousands_of_bands():
    """5,000 presses 20 s apart: the first tick is the start, not the end of the first band."""
    skips = [(i * 20_000_000 + 50_000, (i + 1) * 20_000_000, 799, "MC00") for i in range(5000)]
    presses = [i * 20_000_000 + 10_000 for i in range(5000)]  # keep the skips apart
    axis = plot.TimeAxis(skips, 5000 * 20_000_000, presses)
    assert len(axis.stretches) == 5000
    assert axis.ticks()[1][0] == "0 s"
    bands = sum(d1 - d0 for d0, d1 in zip(axis.drawn[1::2], axis.drawn[2::2]))
    assert bands <= axis.drawn[-1] / 2  # the parts drawn to scale keep half the axis


def test_the_cut_note_does_not_narrow_the_plot(tmp_path, drawn, monkeypatch):
    """The note sits inside the axes: sticking out, it made the layout shrink every lane."""
    monkeypatch.setattr(plot, "CAP", 5)
    _once(tmp_path, tmp_path / "cut.png")
    fig, renderer = _rendered(drawn[-1])
    (note,) = [t for t in fig.axes[0].texts if "plot cut here" in t.get_text()]
    box, inside = note.get_window_extent(renderer), fig.axes[0].bbox
    assert inside.x0 <= box.x0 and box.x1 <= inside.x1
