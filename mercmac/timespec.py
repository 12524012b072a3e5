"""Durations (`20ms`, `1.5s`, `1500d`), button scripts (`--buttons`, docs/cli.md), and the one way
times are written for people: `format_span` (a length) and `format_clock` (a time on the run's
clock). Every number goes with its unit after a space, as `--until` takes it: `1.5 s`, `31.7 min`,
`1,500 d`; a clock from 1000 s on reads `1 d 1:01:01.5`."""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
from fractions import Fraction

UNIT_MS = {"ms": 1, "s": 1000, "min": 60_000, "h": 3_600_000, "d": 86_400_000}
# 100 years: far beyond any bench run (`--until 1500d`, the longest the benchmarks run, is
# ~4 years), and small enough that times in microseconds stay exact in a float and far from
# any int64 limit.
MAX_MS = 36_525 * UNIT_MS["d"]
MAX_DIGITS = 40  # longer numbers are out of range anyway; int() refuses > 4300 digits
# ASCII digits only: int() would also take other scripts' digits, which nobody means here
_DURATION = re.compile(r"\s*([0-9]+(?:\.[0-9]+)?|\.[0-9]+)\s*(ms|s|min|h|d)?\s*", re.IGNORECASE)
_INPUTS = re.compile(r"\s*[1-6](?:\s*\+\s*[1-6])*\s*")
_EXPECTED = "use a number with ms, s, min, h or d, e.g. 250ms or 1.5s"


class TimeSpecError(ValueError):
    """A duration or button script that cannot be read; the message says why."""


def parse_duration(text: str) -> int:
    """Milliseconds in a duration such as '20ms', '2s', '1.5min' or a bare '250' (ms)."""
    m = _DURATION.fullmatch(text)
    if not m:
        if text.strip().startswith("-"):
            raise TimeSpecError(f"{_quote(text)}: negative times are not allowed; {_EXPECTED}")
        raise TimeSpecError(f"{_quote(text)} is not a duration: {_EXPECTED}")
    whole, _, fraction = m.group(1).partition(".")
    whole, fraction = whole.lstrip("0"), fraction.rstrip("0")
    if len(whole) > MAX_DIGITS:
        raise _too_large(text)
    if len(fraction) > MAX_DIGITS:  # x 86,400,000 ms cannot make that many decimals whole
        raise TimeSpecError(f"{_quote(text)} is not a whole number of milliseconds")
    # exact arithmetic: '1.0000000000000000001s' is not 1000 ms
    value = Fraction(f"{whole or 0}.{fraction or 0}") * UNIT_MS[(m.group(2) or "ms").lower()]
    if value > MAX_MS:
        raise _too_large(text)
    if value.denominator != 1:
        raise TimeSpecError(f"{_quote(text)} is not a whole number of milliseconds")
    return int(value)


def format_span(t_us: float, digits: int | None = 3, parts: int = 1) -> str:
    """A length of time in the largest unit it reaches: '39 ms', '1.5 s', '31.7 min', '1,500 d'.

    `digits` significant digits, rounded (a span that rounds up to the next unit is said in
    it: 59.99 s is '1 min'); None: every digit, exact to the microsecond ('1.001 s', '90 s' is
    '1.5 min'), which `parse_duration` reads back. `parts=2`: whole units from the largest
    down, truncated: '23 h 59 min' (a plot's band, where '1 d' would overstate it).
    """
    if t_us == math.inf:
        return "forever"
    if parts > 1 and t_us >= _UNITS_US[2][1]:  # below a minute one unit says it
        return _in_parts(t_us, parts)
    return _rounded(t_us, digits) if digits else _exact(t_us)


def format_clock(t_us: float, places: int | None = None, fixed: bool = False) -> str:
    """A time on the run's clock: '1.5 s', '999.999 s', then '0:16:40', '1 d 1:01:01.5'.

    `places` decimals of a second, or None: as many as it has, to the microsecond (the
    machine's resolution). `fixed`: a line redrawn in place keeps its width: always
    HH:MM:SS, days as '3d' (test_ff_shift pins this spelling of the progress line).
    """
    if t_us == math.inf:
        return "never"
    step = 1 if places is None else 10 ** (6 - places)
    # rounded once, exactly, half up, before the form is chosen: 999.9996 s at 3 places is
    # 0:16:40.000 (a fraction of a microsecond is not rounded first: 1.2324996 s is 1.232 s)
    exact = int(t_us) if float(t_us).is_integer() else Fraction(t_us)
    whole, us = divmod((2 * exact + step) // (2 * step) * step, 1_000_000)
    tail = _fraction(us, places)
    if whole < CLOCK_IN_SECONDS and not fixed:
        return f"{whole}{tail} s"
    days, rest = divmod(whole, 86_400)
    hours, rest = divmod(rest, 3600)
    text = f"{hours:0{2 if fixed else 1}d}:{rest // 60:02d}:{rest % 60:02d}{tail}"
    if not days:
        return text
    return f"{days}d {text}" if fixed else f"{days:,} d {text}"


def _fraction(us: int, places: int | None) -> str:
    """'.5' (places None: trailing zeros dropped), '.500' (3 places), '' (0 places or none)."""
    digits = f"{us:06d}"
    shown = digits.rstrip("0") if places is None else digits[:places]
    return f".{shown}" if shown else ""


# Seconds read best up to a few minutes (a timeline of 360.000 s stays in seconds, and its
# column keeps its width); H:MM:SS from 1000 s, where seconds would need a fourth digit.
CLOCK_IN_SECONDS = 1000
_UNITS_US = tuple((unit, size * 1000) for unit, size in reversed(UNIT_MS.items()))  # d .. ms


def _rounded(t_us: float, digits: int) -> str:
    for i, (unit, size) in enumerate(_UNITS_US):
        value = float(f"{t_us / size:.{digits}g}")
        if value >= 1 or unit == "ms":
            if i and value * size >= _UNITS_US[i - 1][1]:  # 59.99 s rounds to 60 s: 1 min
                return _rounded(_UNITS_US[i - 1][1], digits)
            return f"{t_us / size:,.0f} {unit}" if value >= 10 ** digits else f"{value:g} {unit}"
    raise AssertionError("unreachable: ms takes every span")


def _exact(t_us: float) -> str:
    """In the largest unit it is at least one of with at most three decimals: '1.5 min'."""
    for unit, size in _UNITS_US:
        value = Fraction(t_us) / size
        if unit == "ms" or (value >= 1 and (value * 1000).denominator == 1):
            return f"{float(value):,.3f}".rstrip("0").rstrip(".") + f" {unit}"
    raise AssertionError("unreachable: ms takes every span")


def _in_parts(t_us: float, parts: int) -> str:
    """'23 h 59 min', '2 min 5 s', '1 d': whole units, zeros left out."""
    start = next(i for i, (_, size) in enumerate(_UNITS_US) if t_us >= size)
    words = []
    for unit, size in _UNITS_US[start:start + parts]:
        n, t_us = divmod(t_us, size)
        if n:
            words.append(f"{int(n):,} {unit}")
    return " ".join(words)


def _too_large(text: str) -> TimeSpecError:
    days = MAX_MS // UNIT_MS["d"]
    return TimeSpecError(f"{_quote(text)} is too large: durations are at most {days}d (100 years)")


def _quote(text: str, limit: int = 40) -> str:
    """'text' for a message: control characters escaped, a long text shortened in the middle."""
    shown = text.encode("unicode_escape").decode("ascii") if not text.isprintable() else text
    if len(shown) > limit:
        shown = f"{shown[:limit - 12]}...{shown[-9:]}"
    return f"'{shown}'"


@dataclass(frozen=True, slots=True)
class Press:
    """Inputs held from start_ms to end_ms (None: held to the end of the run)."""

    inputs: tuple[int, ...]
    start_ms: int
    end_ms: int | None


def parse_buttons(spec: str) -> list[Press]:
    """Parse '1@0-2s,2+3@5s-5.2s,4@7s' into presses (inputs 1-6), overlaps merged."""
    return merge(_read_presses(spec))


def _read_presses(spec: str) -> list[Press]:
    presses = []
    for item in filter(None, (p.strip() for p in spec.split(","))):
        who, at, when = item.partition("@")
        if not at:
            raise TimeSpecError(f"{_quote(item)}: write B@T1-T2 or B@T1, e.g. 1@0-2s")
        if not _INPUTS.fullmatch(who):
            raise TimeSpecError(f"{_quote(item)}: inputs are numbers 1-6 joined by '+': "
                                "1-4 (buttons), 5 (joystick), 6 (joystick button)")
        inputs = tuple(int(b) for b in who.split("+"))
        if when.strip().startswith("-"):
            raise TimeSpecError(f"{_quote(item)}: negative times are not allowed; "
                                "write B@T1-T2 or B@T1, e.g. 1@0-2s")
        start, dash, end = when.partition("-")
        try:
            t0 = parse_duration(start)
            t1 = parse_duration(end) if dash else None
        except TimeSpecError as e:
            raise TimeSpecError(f"{_quote(item)}: {e}") from None
        if t1 is not None and t1 < t0:
            raise TimeSpecError(f"{_quote(item)}: the release time is before the press time")
        presses.append(Press(inputs, t0, t1))
    return presses


def merge(presses: list[Press]) -> list[Press]:
    """One input's overlapping or touching presses as one: `1@1s-2s,1@1.5s-3s` is `1@1s-3s`.

    A button is either held or not: a second press while it is held adds nothing,
    and only the last release of the merged span lets it go (otherwise the first
    release would cut the longer press short). Inputs held over the same span
    stay together; the result is in time order.
    """
    spans: dict[int, list[list]] = {}
    for press in sorted(presses, key=lambda p: p.start_ms):
        for n in press.inputs:
            held = spans.setdefault(n, [])
            last = held[-1] if held else None
            if last is not None and (last[1] is None or press.start_ms <= last[1]):
                last[1] = None if press.end_ms is None or last[1] is None \
                    else max(last[1], press.end_ms)
            else:
                held.append([press.start_ms, press.end_ms])
    together: dict[tuple, list[int]] = {}
    for n, held in sorted(spans.items()):
        for start, end in held:
            together.setdefault((start, end), []).append(n)
    order = sorted(together, key=lambda span: (span[0], math.inf if span[1] is None else span[1]))
    return [Press(tuple(together[span]), *span) for span in order]
