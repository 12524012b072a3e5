"""The text timeline of `mercmac sim`: a story by default, more with -v and -vv."""
from __future__ import annotations

import re

import pytest
from click.testing import CliRunner

from mercmac.cli import main
from mercmac.render.sim import plural
from mercmac.timespec import format_span as duration
from helpers.paths import FOUR_MODES

README_ARGS = [str(FOUR_MODES), "--buttons", "3@0-300ms,1@1s-1.2s", "--until", "3s"]
POLLS = ("steps.when@49", "steps.when@50", "steps.when@51", "steps.when@52",
         "autostart.when@22", "autostart.when@23")


def sim(*args: str) -> list[str]:
    result = CliRunner().invoke(main, ["sim", *args])
    assert result.exit_code == 0, result.output
    header, *timeline = result.output.split("\n\nSummary")[0].splitlines()
    assert header.startswith("Simulating a C-863 from power-on until ")
    return timeline


def seconds(line: str) -> float:
    return float(re.match(r"\s*(\d+\.\d+) s  ", line).group(1))


def test_readme_command_tells_a_short_story():
    lines = sim(*README_ARGS)
    assert 8 <= len(lines) <= 16, "\n".join(lines)
    text = "\n".join(lines)
    assert "button 3 pressed" in text and "button 1 pressed" in text
    assert "goto steps (MC04)" in text
    assert "move to 2000 from -2000 (arrives 1.232 s" in text and "on target at 2000" in text
    assert "end of the run" in lines[-1]
    for line in lines:
        assert not re.search(r"\benter \w|exits on X[NF]", line), line
        assert not any(poll in line for poll in POLLS if "move" not in line), line


@pytest.mark.parametrize("flag", ["", "-v", "-vv"])
def test_lines_are_in_time_order(flag):
    lines = sim(*README_ARGS, *([flag] if flag else []))
    times = [seconds(line) for line in lines]
    assert times == sorted(times)


def test_v_shows_macro_entries_and_folds_polls():
    lines = sim(*README_ARGS, "-v")
    text = "\n".join(lines)
    assert "enter init (MC01)" in text and "init (MC01) ends, back to autostart (MC00)" in text
    assert "enter steps.when@49 (MC17)" in text  # the press of button 1: it moves
    assert not re.search(r"exits on X[NF]", text)
    assert re.search(r"\d+ polls since [\d.]+ s: MC\d\d", text)
    assert len(sim(*README_ARGS)) < len(lines) < len(sim(*README_ARGS, "-vv"))


def test_vv_shows_everything():
    text = "\n".join(sim(*README_ARGS, "-vv"))
    assert "autostart.when@22 (MC05) exits on XN1, back to autostart (MC00)" in text
    assert "enter steps.when@52 (MC20)  x3 since 0.334 s" in text
    assert "fast-forward 14 identical passes of steps (MC04) (39 ms each)" in text


def test_long_pass_reads_in_minutes(write):
    # MC01 waits 30 x 63.4 s; each pass of MC00 takes 31.7 min and turns LED 1 off and on
    program = write("[MC00] CN1,EM1,CF1,RP,RP\n[MC01] WA63398,RP29\n")
    text = "\n".join(sim(program, "--until", "3h"))
    assert "(31.7 min, 2 LED changes each)" in text


@pytest.mark.parametrize("t_us, text", [
    (0, "0 ms"), (500, "0.5 ms"), (39_000, "39 ms"), (1_500_000, "1.5 s"),
    (59_990_000, "1 min"), (1_900_054_000, "31.7 min"), (5.5 * 3600e6, "5.5 h"),
    (3 * 86400e6, "3 d"), (1500 * 86400e6, "1,500 d"),
])
def test_duration_for_people(t_us, text):
    assert duration(t_us) == text


def test_plurals():
    assert plural(1, "LED change") == "1 LED change"
    assert plural(2, "hazard") == "2 hazards"
    assert plural(1_000, "report") == "1,000 reports"
    assert plural(1, "identical pass", "identical passes") == "1 identical pass"


def test_summary_plurals(write):
    result = CliRunner().invoke(main, ["sim", write("[MC00] CN1,TP\n")])
    assert "1 report, 1 LED change, 0 hazards" in result.output
