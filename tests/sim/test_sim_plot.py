"""`mercmac sim --plot`: the files are made and hold the lanes.

Position and target over time, with lanes for the buttons, the LEDs and the
running macro; long fast-forwarded stretches drawn compressed and marked. The
pictures themselves were looked at by eye; these tests pin what a file holds.
"""
from __future__ import annotations

import re
import sys
import time

import pytest

from helpers.cli import cli
from helpers.paths import EXAMPLE4, EXAMPLE4_MODE2, ROOT
from helpers.plots import inline_svg, page_data, svg_texts

pytest.importorskip("matplotlib")

from mercmac.sim import plot  # noqa: E402  (needs matplotlib only when drawing)

BLINK = "autostart {\n  every 500ms { CN 1, WA 500, CF 1 }\n}\n"  # CN1,WA500,CF1,WA500,RP,RP
MAGIC = {"png": b"\x89PNG\r\n\x1a\n", "pdf": b"%PDF-", "svg": b"<?xml", "html": b"<!DOCTYPE html>"}


def _example4(out, *more):
    return cli("sim", EXAMPLE4, "--scenario", EXAMPLE4_MODE2, "--plot", out, *more)


@pytest.mark.parametrize("kind", ["png", "svg", "pdf", "html"])
def test_each_kind_of_file_is_made(tmp_path, kind):
    out = tmp_path / f"run.{kind}"
    result = _example4(out)
    assert result.exit_code == 0, result.output
    assert out.read_bytes().startswith(MAGIC[kind])
    assert not list(tmp_path.glob(".mercmac-*"))  # written whole: no temporary file left


def test_the_svg_holds_the_lanes_and_the_macros_by_name(tmp_path):
    out = tmp_path / "run.svg"
    assert _example4(out).exit_code == 0
    texts = svg_texts(out.read_text())
    for lane in ("position", "target", "buttons", "LEDs", "macro"):
        assert lane in texts
    assert {"MC22", "MC21", "MC25", "MC20"} <= set(texts)  # Example 4, mode 2: the macros run


def test_the_html_page_is_self_contained_and_holds_the_lanes_data(tmp_path):
    out = tmp_path / "run.html"
    assert _example4(out).exit_code == 0
    page = out.read_text()
    assert "<script src" not in page and "http-equiv" not in page  # nothing fetched
    assert "wheel" in page and "pointermove" in page  # zooms and pans
    assert {"position", "buttons", "LEDs", "macro"} <= set(svg_texts(inline_svg(page)))
    data = page_data(page)
    assert data["lanes"] == ["position", "buttons", "LEDs", "macro"]
    assert data["buttons"]["2"][0] == [0, 400]  # the scenario holds button 2 to 400 ms
    assert data["buttons"]["1"] == [[1000, 1300]]
    assert any(label == "MC22" for *_, label in data["macro"])
    assert data["position"][-1][1] == 0 and max(x for _, x in data["position"]) == 100_000
    targets = [x for _, x in data["target"]]
    assert targets[targets.index(50_000):] == [50_000, 100_000, 0, 0]  # MA50000, MA100000, GH


def test_a_missing_extra_is_a_clear_message_before_simulating(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # `import matplotlib` fails
    out = tmp_path / "run.png"
    result = _example4(out)
    assert result.exit_code == 2
    assert "--plot needs the plot extra: pip install 'mercmac[plot]'" in result.output
    assert "Traceback" not in result.output and "expectations" not in result.output
    assert not out.exists()


@pytest.mark.parametrize("where, says", [
    ("folder.png", "directory"),
    ("no-such-folder/run.png", "does not exist"),
    ("run.gif", ".png, .svg, .pdf or .html"),
])
def test_a_bad_path_is_refused_before_simulating(tmp_path, monkeypatch, where, says):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "folder.png").mkdir()
    result = cli("sim", EXAMPLE4, "--until", "1s", "--plot", where)
    assert result.exit_code == 2
    assert says in result.output and "Summary" not in result.output


@pytest.mark.parametrize("kind", ["png", "html"])
def test_an_old_plot_stays_when_writing_fails_midway(tmp_path, monkeypatch, kind):
    out = tmp_path / f"run.{kind}"
    out.write_bytes(b"the old picture")
    drawn = plot.figure

    def figure(*args, **kw):
        fig = drawn(*args, **kw)
        fig.savefig = _half_written
        return fig

    monkeypatch.setattr(plot, "figure", figure)
    result = _example4(out)
    assert result.exit_code == 130  # Ctrl-C
    assert out.read_bytes() == b"the old picture"
    assert not list(tmp_path.glob(".mercmac-*"))


def _half_written(f, **_):
    f.write(b"half" if "b" in getattr(f, "mode", "") else "half")
    raise KeyboardInterrupt


def test_a_fast_forwarded_day_plots_quickly_with_the_stretch_compressed(tmp_path):
    program = tmp_path / "blink.mcm"
    program.write_text(BLINK)
    out = tmp_path / "day.html"
    started = time.monotonic()
    result = cli("sim", program, "--until", "1d", "--plot", out)
    assert result.exit_code == 0, result.output
    assert time.monotonic() - started < 30  # 172,284 LED changes, not drawn one by one
    page = out.read_text()
    data = page_data(page)
    assert data["fast_forwarded"] and data["end_ms"] == 86_400_000
    assert len(data["LEDs"]["1"]) < 100
    assert "fast-forwarded" in " ".join(svg_texts(inline_svg(page)))


def test_a_long_skip_is_drawn_short_and_a_short_one_to_scale():
    day = plot.TimeAxis([(2_000_000, 86_399_000_000, 1000, "MC00")], 86_400_000_000)
    assert day.stretches == [(2_000_000, 86_399_000_000)]
    assert day.drawn[-1] < 4  # seconds drawn: 2 s + a band + 1 s
    assert day.ticks()[1][-1] == "1 d 0:00:00"
    brief = plot.TimeAxis([(2_000_000, 5_000_000, 3, "MC00")], 6_000_000)
    assert brief.stretches == [] and brief.drawn[-1] == 6


def test_skips_with_an_input_change_between_them_stay_apart():
    skips = [(0, 20_000_000, 5, "MC20"), (21_000_000, 40_000_000, 5, "MC20")]
    assert len(plot.TimeAxis(skips, 40_000_000).stretches) == 1
    assert len(plot.TimeAxis(skips, 40_000_000, [20_500_000]).stretches) == 2


def test_durations_read_as_times():
    assert plot.duration(1.5) == "1.5 s"
    assert plot.duration(90061.5) == "1 d 1:01:01.5"
    assert plot.span(86_340_000_000) == "23 h 59 min"


def test_the_readme_picture_is_made_by_the_command_it_names(tmp_path):
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    named = re.search(r"`mercmac (sim [^`]*--plot docs/example4\.png)`", readme)
    assert named and "](docs/example4.png)" in readme
    assert (ROOT / "docs" / "example4.png").read_bytes().startswith(MAGIC["png"])
    args = named.group(1).split()[1:-1]  # the command's own words, the picture to tmp_path
    out = tmp_path / "example4.png"
    result = cli("sim", *[ROOT / a if a.startswith("examples/") else a for a in args], out)
    assert result.exit_code == 0, result.output
    assert out.read_bytes().startswith(MAGIC["png"])
