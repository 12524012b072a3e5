"""One way to write a time for people: `timespec.format_span` for a length and
`timespec.format_clock` for a time on the run's clock, used by the timeline, the plot, the
progress lines, describe and the language server; no module keeps a formatter of its own."""
from __future__ import annotations

import re
from fractions import Fraction

import pytest
from click.testing import CliRunner
from hypothesis import given
from hypothesis import strategies as st

from mercmac.cli import main
from mercmac.source import split_lines
from mercmac.timespec import MAX_MS, UNIT_MS, format_clock, format_span, parse_duration
from helpers.paths import PACKAGE

DAY_US = UNIT_MS["d"] * 1000
TIMES_US = st.integers(0, MAX_MS * 1000)
CLOCKS = [dict(places=p, fixed=f) for p in (None, 0, 1, 3) for f in (False, True)]
SPANS = [dict(digits=3), dict(digits=None), dict(parts=2)]
_CLOCK = re.compile(r"(?:([\d,]+) ?d )?(\d+):(\d\d):(\d\d(?:\.\d+)?)|(\d+(?:\.\d+)?) s")
_SPAN = re.compile(r"([\d,]+(?:\.\d+)?) (ms|s|min|h|d)")


def clock_seconds(text: str) -> Fraction:
    """What a reader takes from a clock: '1 d 1:01:01.5' -> 90061.5."""
    m = _CLOCK.fullmatch(text)
    assert m, text
    if m.group(5):
        return Fraction(m.group(5))
    days = int((m.group(1) or "0").replace(",", ""))
    return days * 86400 + int(m.group(2)) * 3600 + int(m.group(3)) * 60 + Fraction(m.group(4))


def span_seconds(text: str) -> Fraction:
    """What a reader takes from a span: '23 h 59 min' -> 86340, '1,500 d' -> 129600000."""
    assert re.fullmatch(rf"{_SPAN.pattern}(?: {_SPAN.pattern})*", text), text
    return sum(Fraction(n.replace(",", "")) * UNIT_MS[u] / 1000 for n, u in _SPAN.findall(text))


@pytest.mark.parametrize("t_us, kw, text", [
    (59_999_999, {}, "59.999999 s"),
    (60_000_000, {}, "60 s"),  # seconds up to 1000 s: a timeline column of 360.000 s
    (999_999_000, dict(places=3), "999.999 s"),
    (1_000_000_000, dict(places=3), "0:16:40.000"),
    (999_999_500, dict(places=3), "0:16:40.000"),  # rounded before the form is chosen
    (1_232_499.6, dict(places=3), "1.232 s"),  # rounded once: not to 1,232,500 us first
    (999_999_999, {}, "999.999999 s"),
    (1_000_000_000, {}, "0:16:40"),
    (DAY_US - 1, {}, "23:59:59.999999"),
    (DAY_US, {}, "1 d 0:00:00"),
    (DAY_US, dict(places=3), "1 d 0:00:00.000"),
    (1500 * DAY_US, {}, "1,500 d 0:00:00"),
    (12_000_000, dict(places=0, fixed=True), "00:00:12"),
    (3 * DAY_US, dict(places=0, fixed=True), "3d 00:00:00"),
    (2_500_000, dict(places=1), "2.5 s"),
    (float("inf"), {}, "never"),
])
def test_clock_at_the_unit_boundaries(t_us, kw, text):
    assert format_clock(t_us, **kw) == text


@pytest.mark.parametrize("t_us, kw, text", [
    (59_999_000, {}, "1 min"),  # three digits: 60.0 s is a minute
    (59_999_000, dict(digits=None), "59.999 s"),
    (60_000_000, dict(digits=None), "1 min"),
    (90_000_000, dict(digits=None), "1.5 min"),
    (86_040_000_000, {}, "23.9 h"),
    (DAY_US - 60_000_000, {}, "1 d"),  # 23.98 h: three digits round it up to a day
    (DAY_US - 60_000_000, dict(parts=2), "23 h 59 min"),  # whole units do not
    (DAY_US - 1, {}, "1 d"),
    (DAY_US, dict(digits=None), "1 d"),
    (DAY_US + 1000, dict(digits=None), "86,400.001 s"),
    (1500 * DAY_US + 3_600_000_000, dict(parts=2), "1,500 d 1 h"),
    (125_700_000, dict(parts=2), "2 min 5 s"),
    (12_500_000, dict(parts=2), "12.5 s"),
    (float("inf"), {}, "forever"),
])
def test_span_at_the_unit_boundaries(t_us, kw, text):
    assert format_span(t_us, **kw) == text


@given(st.integers(0, MAX_MS))
def test_an_exact_span_reads_back_as_the_same_duration(ms):
    text = format_span(ms * 1000, digits=None)
    assert parse_duration(text.replace(",", "")) == ms, text


@given(TIMES_US, TIMES_US)
def test_later_times_never_read_earlier(a, b):
    a, b = sorted((a, b))
    for kw in CLOCKS:
        assert clock_seconds(format_clock(a, **kw)) <= clock_seconds(format_clock(b, **kw)), kw
    for kw in SPANS:
        assert span_seconds(format_span(a, **kw)) <= span_seconds(format_span(b, **kw)), kw


@given(TIMES_US)
def test_a_clock_is_off_by_at_most_half_its_last_place(t_us):
    for kw in CLOCKS:
        half = Fraction(1, 2 * 10 ** (6 if kw["places"] is None else kw["places"]))
        assert abs(clock_seconds(format_clock(t_us, **kw)) - Fraction(t_us, 10 ** 6)) <= half


@given(TIMES_US)
def test_a_span_for_people_keeps_three_digits(t_us):
    shown = span_seconds(format_span(t_us))
    assert abs(shown - Fraction(t_us, 10 ** 6)) <= Fraction(t_us, 10 ** 6) * Fraction(5, 1000)


def test_the_timeline_reads_past_1000_s_like_the_plot(tmp_path):
    """One style: 1179.657 s into a run is '0:19:39.657' in the timeline, as the plot's ticks
    write it ('1:00:00'), not '00:19:39.657'; `--until 1230s` is exactly 20.5 min."""
    source = tmp_path / "slow.mcm"
    source.write_text("[MC00] CN1,WA65535,CF1,WA65535,RP,RP\n")
    result = CliRunner().invoke(main, ["sim", str(source), "--until", "1230s"])
    assert result.exit_code == 0, result.output
    assert "from power-on until 20.5 min" in result.output
    assert re.search(r"^ +0:19:39\.657  LEDs ●", result.output, re.M), result.output
    assert "Summary: ran to 0:20:30.000;" in result.output


# what writes a clock or a span by hand: hours and days counted out, two-digit fields
BY_HAND = re.compile(r"\b86_?400\b|\b3_?600\b|:02d\}:\{|divmod\([^)]*\b60\b")


def test_no_module_but_timespec_writes_times_by_hand():
    found = [f"{path.relative_to(PACKAGE)}:{n}: {line.strip()}"
             for path in sorted(PACKAGE.rglob("*.py")) if path.name != "timespec.py"
             for n, line in enumerate(split_lines(path.read_text(encoding="utf-8")), 1)
             if BY_HAND.search(line)]
    assert not found, "\n".join(found)
