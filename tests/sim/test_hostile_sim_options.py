"""`mercmac sim` refuses hostile numbers, times and scenario files with a usage error.

Every case: exit code 2, a message that names the option or scenario key, no traceback.
"""
from __future__ import annotations

import os

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from helpers.budgets import budget
from helpers.cli import sim
from mercmac.timespec import MAX_MS, TimeSpecError, parse_buttons, parse_duration
from mercmac.sim import scenario

HUGE = "9" * 400
LED = "[MC00] CN1,WA100,CF1\n"  # LED 1 on for 100 ms


def refused(result, *words: str) -> None:
    """A usage error (exit 2) without a traceback whose message holds every word."""
    assert isinstance(result.exception, SystemExit), repr(result.exception)
    assert result.exit_code == 2, result.output
    assert "Traceback" not in result.output
    for word in words:
        assert word in result.output, (word, result.output)


# ------------------------------------------------------------------ options
@pytest.mark.parametrize("args, words", [
    (["--until", HUGE], ["--until", "at most"]),
    (["--until", "1" + "0" * 13], ["--until", "at most"]),
    (["--until", "-5"], ["--until", "negative"]),
    (["--until", "nan"], ["--until", "'nan'"]),
    (["--until", "inf"], ["--until", "'inf'"]),
    (["--until", "1e3"], ["--until", "'1e3'"]),
    (["--until", "9" * 5000], ["--until", "at most"]),
    (["--buttons", "1@" + HUGE], ["--buttons", "at most"]),
    (["--buttons", f"1@0-{HUGE}s"], ["--buttons", "at most"]),
    (["--buttons", HUGE + "@0"], ["--buttons", "1-6"]),
    (["--buttons", "1@-1s"], ["--buttons", "negative"]),
    (["--buttons", "1@0--1s"], ["--buttons", "negative"]),
    (["--buttons", "1@"], ["--buttons", "'1@'"]),
    (["--buttons", "1@nan"], ["--buttons", "'nan'"]),
    (["--buttons", "1@0-inf"], ["--buttons", "'inf'"]),
    (["--cycle", "nan"], ["--cycle", "nan"]),
    (["--cycle", "inf"], ["--cycle", "inf"]),
    (["--cycle", "-inf"], ["--cycle", "-inf"]),
    (["--cycle", "1e308"], ["--cycle", "1e+308"]),
    (["--cycle", "0"], ["--cycle", "0"]),
    (["--cycle", "-1"], ["--cycle", "-1"]),
    (["--speed", "nan"], ["--speed", "nan"]),
    (["--interactive", "--speed", "nan"], ["--speed", "nan"]),
    (["--interactive", "--speed", "inf"], ["--speed", "inf"]),
    (["--interactive", "--speed", "1e308"], ["--speed", "1e+308"]),
    (["--interactive", "--speed", "0"], ["--speed", "0"]),
    (["--interactive", "--speed", "-2"], ["--speed", "-2"]),
    (["--reference-at", HUGE], ["--reference-at"]),
    (["--reference-at", "99999999999"], ["--reference-at"]),
    (["--hard-limits", f"-{HUGE},{HUGE}"], ["--hard-limits"]),
    (["--hard-limits", "-1,99999999999"], ["--hard-limits"]),
])
def test_bad_numbers_in_options_are_usage_errors(write, args, words):
    refused(sim(write(LED), *args), *words)


@pytest.mark.parametrize("text, ms", [
    ("0", 0), ("250", 250), ("1.5s", 1500), ("2min", 120_000), ("1500d", 1500 * 86_400_000),
    (" 20 ms ", 20), (".5s", 500), ("36500d", 36_500 * 86_400_000),
])
def test_good_durations_still_parse(text, ms):
    assert parse_duration(text) == ms


@pytest.mark.parametrize("text, words", [
    ("-1s", ["negative"]), ("1.0000000000000000001s", ["whole"]), (HUGE, ["at most"]),
    ("nan", ["'nan'"]), ("", ["''"]),
])
def test_bad_durations_say_why(text, words):
    with pytest.raises(TimeSpecError) as caught:
        parse_duration(text)
    for word in words:
        assert word in str(caught.value)


def test_negative_press_time_says_negative():
    with pytest.raises(TimeSpecError, match="negative"):
        parse_buttons("1@-1s")


# ----------------------------------------------------------------- scenarios
SCENARIO_OK = 'until = "1s"\n[[expect]]\nat = "50ms"\noutputs = 1\n'


def test_utf16_scenario_with_a_bom_is_read(write):
    path = write(SCENARIO_OK.encode("utf-16"), "s.toml")
    result = sim(write(LED), "--scenario", path)
    assert result.exit_code == 0, result.output
    assert "1 expectations met" in result.output or "expectation" in result.output


def test_utf8_scenario_with_a_bom_is_read(write):
    path = write(SCENARIO_OK.encode("utf-8-sig"), "s.toml")
    assert sim(write(LED), "--scenario", path).exit_code == 0


def test_a_scenario_with_lone_cr_line_ends_is_read(write):
    """One TOML reader (mercmac.tomlfile) for scenarios, settings and rigs,
    each reading LF, CRLF and lone CR line ends alike (docs/cli.md)."""
    path = write(SCENARIO_OK.replace("\n", "\r").encode(), "s.toml")
    assert sim(write(LED), "--scenario", path).exit_code == 0


@pytest.mark.parametrize("text, words", [
    ('until = "1s"\n[[expect]]\nat = "50ms"\noutputs = ' + "1" * 5000 + "\n",
     ["s.toml", "too many digits", "line 4, column 11"]),
    ('until = "1s"\r[[expect]\r', ["s.toml", "not valid TOML", "line 2, column 9"]),
])
def test_a_scenario_that_is_no_toml_is_said_with_its_place(write, text, words):
    refused(sim(write(LED), "--scenario", write(text, "s.toml")), *words)


@pytest.mark.parametrize("raw", [
    b'until = "1s"\n# \xff\xfe\n',
    b"\xfe\xff\x00",
    b"\xff\xfe\x00",
    b'until = "\xc3"\n',
])
def test_undecodable_scenarios_are_usage_errors(write, raw):
    refused(sim(write(LED), "--scenario", write(raw, "s.toml")), "s.toml", "UTF-")


def test_bare_bom_bytes_are_an_empty_scenario(write):
    result = sim(write(LED), "--scenario", write(b"\xff\xfe", "s.toml"))
    assert result.exit_code == 0, result.output


@pytest.mark.parametrize("text, words", [
    ("expect = [5]\n", ["expect 1", "table"]),
    ('expect = ["x"]\n', ["expect 1", "table"]),
    ('[expect]\nat = "1s"\noutputs = 1\n', ["expect", "[[expect]]"]),
    ("step = 5\n", ["step", "[[step]]"]),
    ('[step]\nat = "0ms"\n', ["step", "[[step]]"]),
    ('[[step]]\nat = "0ms"\npress = true\n', ["step 1", "press", "true"]),
    ('[[step]]\nat = "0ms"\nrelease = [1, false]\n', ["step 1", "release"]),
    ('[[step]]\nat = "0ms"\npress = 7\n', ["step 1", "press", "1-6"]),
    ('[[step]]\nat = "0ms"\npress = 1\n[[step]]\nat = true\npress = 1\n', ["step 2", "at"]),
    ('[[step]]\nat = 1.5\npress = 1\n', ["step 1", "at"]),
    ('[[step]]\nat = nan\npress = 1\n', ["step 1", "at"]),
    ('[[step]]\nat = inf\npress = 1\n', ["step 1", "at"]),
    ('[[step]]\nat = "-1s"\npress = 1\n', ["step 1", "at", "negative"]),
    (f'[[step]]\nat = {HUGE}\npress = 1\n', ["step 1", "at", "at most"]),
    (f'[[step]]\nat = "{HUGE}ms"\npress = 1\n', ["step 1", "at", "at most"]),
    ("until = true\n", ["until"]),
    (f'until = "{HUGE}s"\n', ["until", "at most"]),
    ("until = [1]\n", ["until"]),
    ('[[expect]]\nat = "1s"\noutputs = true\n', ["expect 1", "outputs"]),
    ('[[expect]]\nat = "1s"\nmacro = true\n', ["expect 1", "macro"]),
    ('[[expect]]\nat = "1s"\nposition = true\n', ["expect 1", "position"]),
    ('[[expect]]\nat = "1s"\nposition = [5, true]\n', ["expect 1", "position"]),
    ('[[expect]]\nat = "1s"\nposition = [10, 5]\n', ["expect 1", "position"]),
    ('[[expect]]\nat = "1s"\nrunning = 1\n', ["expect 1", "running"]),
    ('[[expect]]\nwithin = ["1s", true]\noutputs = 1\n', ["expect 1", "within"]),
    ('[[expect]]\nwithin = "1s"\noutputs = 1\n', ["expect 1", "within"]),
    ('[[expect]]\nwithin = ["2s", "1s"]\noutputs = 1\n', ["expect 1", "window"]),
    ('[[expect]]\nat = "-1s"\noutputs = 1\n', ["expect 1", "negative"]),
    ("x = " + "[" * 5000 + "]" * 5000 + "\n", ["s.toml"]),
])
def test_bad_scenarios_are_usage_errors(write, text, words):
    refused(sim(write(LED), "--scenario", write(text, "s.toml")), "s.toml", *words)


# ------------------------------------------------------------------ fuzzing
@settings(max_examples=budget(300), deadline=None, derandomize=True)
@given(st.one_of(st.text(), st.text(alphabet="0123456789.-+@,smindh \t"), st.from_regex(
    r"\A[1-6](\+[1-6])*@-?\d{0,30}(\.\d{0,5})?(ms|s|min|h|d)?(-\d{0,30}(ms|s|d)?)?\Z")))
def test_fuzzed_time_specs_raise_only_timespec_errors(text):
    for parse in (parse_duration, parse_buttons):
        try:
            value = parse(text)
        except TimeSpecError:
            continue
        if parse is parse_duration:
            assert isinstance(value, int) and 0 <= value <= MAX_MS
        else:
            assert all(0 <= p.start_ms <= MAX_MS for p in value)


TOML_LEAF = st.one_of(st.booleans(), st.integers(), st.floats(), st.text(max_size=6),
                      st.sampled_from(["1s", "-1s", "0", "none", HUGE, "nan"]))
TOML_VALUE = st.recursive(
    TOML_LEAF, lambda inner: st.one_of(
        st.lists(inner, max_size=3),
        st.dictionaries(st.sampled_from(["at", "within", "press", "release", "outputs",
                                         "position", "macro", "running", "x"]), inner,
                        max_size=4)),
    max_leaves=12)


@settings(max_examples=budget(300), deadline=None, derandomize=True)
@given(st.dictionaries(st.sampled_from(["until", "step", "expect", "other"]), TOML_VALUE,
                       max_size=3))
def test_fuzzed_scenario_dictionaries_raise_only_scenario_errors(data):
    try:
        scenario.parse("s.toml", data)
    except scenario.ScenarioError as e:
        assert str(e).startswith("s.toml: ")


def test_a_fifo_or_device_as_scenario_is_refused_without_hanging(write, tmp_path):
    fifo = tmp_path / "s.toml"
    os.mkfifo(fifo)
    refused(sim(write(LED), "--scenario", str(fifo)), "s.toml", "regular file")
    refused(sim(write(LED), "--scenario", "/dev/zero"), "/dev/zero", "regular file")


def test_a_huge_scenario_is_refused(write):
    """The cap of every TOML file mercmac reads (mercmac.tomlfile)."""
    from mercmac.source import MAX_BYTES

    path = write(b"", "s.toml")
    with open(path, "r+b") as f:
        f.truncate(MAX_BYTES + 1)  # sparse: nothing is written, nothing must be read
    refused(sim(write(LED), "--scenario", path), "s.toml", "MB")


@pytest.mark.parametrize("kwargs, text, ok", [
    ({}, "2.5", True), ({}, "nan", False), ({}, "-inf", False), ({}, "1e999", False),
    ({"min": 0, "min_open": True}, "0", False), ({"min": 1, "max": 10}, "10", True),
    ({"min": 1, "max": 10}, "10.5", False),
])
def test_finite_float_option_type(kwargs, text, ok):
    import click

    from mercmac.cli.common import FiniteFloat

    if ok:
        assert FiniteFloat(**kwargs).convert(text, None, None) == float(text)
    else:
        with pytest.raises(click.BadParameter, match=repr(text)):
            FiniteFloat(**kwargs).convert(text, None, None)
