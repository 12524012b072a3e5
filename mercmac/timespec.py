"""Durations (`20ms`, `1.5s`, `1500d`) and button scripts (SPEC §5 `--buttons`)."""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
from fractions import Fraction

UNIT_MS = {"ms": 1, "s": 1000, "min": 60_000, "h": 3_600_000, "d": 86_400_000}
# 100 years: far beyond any bench run (SPEC's `--until 1500d` is ~4 years), and small enough
# that times in microseconds stay exact in a float and far from any int64 limit.
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


def format_duration(ms: int) -> str:
    """A duration with its unit, in the largest unit it is whole in: '3 ms', '10 s', '1500 d'."""
    for unit, size in reversed(UNIT_MS.items()):
        if ms and ms % size == 0:
            return f"{ms // size:,} {unit}"
    return f"{ms:,} ms"


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
