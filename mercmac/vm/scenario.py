"""Scenarios: timed button steps and expectations kept in TOML (issue 3, `--scenario`).

    until = "10s"
    [[step]]                     # inputs change at a time
    at = "0ms"
    press = [3]                  # and/or release = [3]
    [[expect]]                   # at one time ...
    at = "250ms"
    macro = 26                   # a macro number, or "none" for direct mode
    [[expect]]                   # ... or at some time within a window
    within = ["1s", "2s"]
    outputs = 1                  # the 4-bit LED pattern (bit 0 = LED 1)
    position = [3990, 4010]      # exact, or an inclusive range

The first expectation that fails ends the run with its reason (exit 1).
"""
from __future__ import annotations

from dataclasses import dataclass

from mercmac.errors import MercmacError, UsageError
from mercmac.timespec import TimeSpecError, parse_duration
from mercmac.vm.machine import Machine

CHECKS = ("outputs", "position", "macro", "running")


class ScenarioFailed(MercmacError):
    """An expectation did not hold (exit 1)."""


@dataclass(frozen=True, slots=True)
class Step:
    at_ms: int
    press: tuple[int, ...]
    release: tuple[int, ...]


@dataclass(frozen=True, slots=True)
class Expect:
    number: int
    start_ms: int
    end_ms: int
    checks: dict

    def describe(self) -> str:
        when = (f"at {self.start_ms} ms" if self.start_ms == self.end_ms
                else f"within {self.start_ms}-{self.end_ms} ms")
        return f"expectation {self.number} ({when})"


@dataclass(frozen=True, slots=True)
class Scenario:
    name: str
    until_ms: int | None
    steps: list[Step]
    expects: list[Expect]


def load(path: str) -> Scenario:
    """Read and validate a scenario file; any problem is a usage error naming the place."""
    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10
        import tomli as tomllib
    try:
        with open(path, "rb") as f:
            data = tomllib.load(f)
    except tomllib.TOMLDecodeError as e:
        raise UsageError(f"{path}: not valid TOML: {e}") from None
    try:
        return _parse(path, data)
    except (TimeSpecError, TypeError, ValueError) as e:
        raise UsageError(f"{path}: {e}") from None


def _parse(path: str, data: dict) -> Scenario:
    unknown = set(data) - {"until", "step", "expect"}
    if unknown:
        raise ValueError(f"unknown key(s) {', '.join(sorted(unknown))}: use until, [[step]], [[expect]]")
    until = parse_duration(str(data["until"])) if "until" in data else None
    steps = [_step(i, s) for i, s in enumerate(data.get("step", []), 1)]
    expects = [_expect(i, e) for i, e in enumerate(data.get("expect", []), 1)]
    return Scenario(path, until, sorted(steps, key=lambda s: s.at_ms), expects)


def _inputs(where: str, value) -> tuple[int, ...]:
    values = value if isinstance(value, list) else [value]
    if not all(isinstance(v, int) and 1 <= v <= 6 for v in values):
        raise ValueError(f"{where}: inputs are numbers 1-6")
    return tuple(values)


def _step(i: int, raw: dict) -> Step:
    if "at" not in raw or not set(raw) <= {"at", "press", "release"}:
        raise ValueError(f"step {i}: write at = \"1s\" with press = [..] and/or release = [..]")
    return Step(parse_duration(str(raw["at"])), _inputs(f"step {i}", raw.get("press", [])),
                _inputs(f"step {i}", raw.get("release", [])))


def _expect(i: int, raw: dict) -> Expect:
    checks = {k: v for k, v in raw.items() if k in CHECKS}
    timing = set(raw) - set(checks)
    if not checks or timing not in ({"at"}, {"within"}):
        raise ValueError(f"expect {i}: give `at` or `within` and one or more of {', '.join(CHECKS)}")
    if "at" in raw:
        start = end = parse_duration(str(raw["at"]))
    else:
        window = raw["within"]
        if not (isinstance(window, list) and len(window) == 2):
            raise ValueError(f"expect {i}: within = [\"T1\", \"T2\"]")
        start, end = (parse_duration(str(t)) for t in window)
        if end < start:
            raise ValueError(f"expect {i}: the window ends before it starts")
    for key, value in checks.items():
        _validate(i, key, value)
    return Expect(i, start, end, checks)


def _validate(i: int, key: str, value) -> None:
    ok = {
        "outputs": lambda v: isinstance(v, int) and 0 <= v <= 15,
        "position": lambda v: isinstance(v, int) or (isinstance(v, list) and len(v) == 2
                                                     and all(isinstance(x, int) for x in v)),
        "macro": lambda v: v == "none" or (isinstance(v, int) and 0 <= v <= 31),
        "running": lambda v: isinstance(v, bool),
    }[key](value)
    if not ok:
        raise ValueError(f"expect {i}: bad {key} = {value!r}")


def mismatch(m: Machine, checks: dict) -> str | None:
    """Why the machine does not meet the checks now, or None if it does."""
    actual = {"outputs": m.outputs_pattern(), "position": m.position(),
              "macro": "none" if m.macro is None else m.macro, "running": m.running}
    for key, want in checks.items():
        have = actual[key]
        if key == "position" and isinstance(want, list):
            good = want[0] <= have <= want[1]
        else:
            good = have == want
        if not good:
            return f"{key} is {have!r}, expected {want!r}"
    return None


def schedule_steps(m: Machine, scenario: Scenario) -> None:
    for step in scenario.steps:
        for n in step.press:
            m.schedule_input(step.at_ms, n, True)
        for n in step.release:
            m.schedule_input(step.at_ms, n, False)


def check(m: Machine, expect: Expect) -> None:
    """Run the machine through the expectation's time; raise ScenarioFailed if it never holds."""
    m.run_until(expect.start_ms)
    while True:
        why = mismatch(m, expect.checks)
        if why is None:
            return
        if m.now_ms >= expect.end_ms:
            raise ScenarioFailed(f"{expect.describe()} failed: {why}")
        m.run_until(min(expect.end_ms, next_change_ms(m)))


def next_change_ms(m: Machine) -> float:
    """When the checked state may change next: an event, a command, or 1 ms on while moving."""
    t = m.next_event_ms()
    if m.axis.moving(m.clock.now):
        t = min(t, m.now_ms + 1)
    return t if t > m.now_ms else m.now_ms + m.clock.cycle / 1000


def run(m: Machine, scenario: Scenario, until_ms: int) -> int:
    """Power on, play the steps, check every expectation in time order; the number checked."""
    schedule_steps(m, scenario)
    m.power_on()
    for expect in sorted(scenario.expects, key=lambda e: (e.start_ms, e.number)):
        check(m, expect)
    m.run_until(max(until_ms, m.now_ms))
    return len(scenario.expects)

