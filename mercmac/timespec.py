"""Durations (`20ms`, `1.5s`, `1500d`) and button scripts (SPEC §5 `--buttons`)."""
from __future__ import annotations

import re
from dataclasses import dataclass

UNIT_MS = {"ms": 1, "s": 1000, "min": 60_000, "h": 3_600_000, "d": 86_400_000}
_DURATION = re.compile(r"\s*(\d+(?:\.\d+)?|\.\d+)\s*(ms|s|min|h|d)?\s*", re.IGNORECASE)


class TimeSpecError(ValueError):
    """A duration or button script that cannot be read; the message says why."""


def parse_duration(text: str) -> int:
    """Milliseconds in a duration such as '20ms', '2s', '1.5min' or a bare '250' (ms)."""
    m = _DURATION.fullmatch(text)
    if not m:
        raise TimeSpecError(f"'{text}' is not a duration: use a number with ms, s, min, h or d")
    value = float(m.group(1)) * UNIT_MS[(m.group(2) or "ms").lower()]
    if value != int(value):
        raise TimeSpecError(f"'{text}' is not a whole number of milliseconds")
    return int(value)


@dataclass(frozen=True, slots=True)
class Press:
    """Inputs held from start_ms to end_ms (None: held to the end of the run)."""

    inputs: tuple[int, ...]
    start_ms: int
    end_ms: int | None


def parse_buttons(spec: str) -> list[Press]:
    """Parse '1@0-2s,2+3@5s-5.2s,4@7s' into presses (inputs 1-6)."""
    presses = []
    for item in filter(None, (p.strip() for p in spec.split(","))):
        who, at, when = item.partition("@")
        if not at:
            raise TimeSpecError(f"'{item}': write B@T1-T2 or B@T1, e.g. 1@0-2s")
        try:
            inputs = tuple(int(b) for b in who.split("+"))
        except ValueError:
            raise TimeSpecError(f"'{item}': inputs are numbers 1-6 joined by '+'") from None
        if not inputs or any(not 1 <= b <= 6 for b in inputs):
            raise TimeSpecError(f"'{item}': inputs are 1-4 (buttons), 5 (joystick), 6 (joystick button)")
        start, dash, end = when.partition("-")
        t0 = parse_duration(start)
        t1 = parse_duration(end) if dash else None
        if t1 is not None and t1 < t0:
            raise TimeSpecError(f"'{item}': the release time is before the press time")
        presses.append(Press(inputs, t0, t1))
    return presses
