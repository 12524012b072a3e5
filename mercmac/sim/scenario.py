"""Scenarios: timed button steps and expectations kept in TOML (`--scenario`).

    until = "10s"
    allow_hazards = ["soft-limit-clamp"]  # hazards the program means (shown, not counted)
    [[step]]                     # inputs change at a time
    at = "0ms"
    press = [3]                  # and/or release = [3]
    [[expect]]                   # at one time ...
    at = "250ms"
    macro = 26                   # a macro number, a macro name, or "none" for direct mode
    [[expect]]                   # ... or at some time within a window
    within = ["1s", "2s"]
    outputs = 1                  # the 4-bit LED pattern (bit 0 = LED 1)
    position = [3990, 4010]      # exact, or an inclusive range

The first expectation that fails ends the run with its reason (exit 1).

A macro name matches the macro of that name in the source and the parts the
compiler hoisted out of it into slots of their own (`run` matches `run`,
`run.when@20`, `run.every@19`, ...): a name says which of the user's macros is
at work, whichever of its slots runs. A name the program does not have is
refused before the run, with the nearest one. A misspelled key is named, with
the nearest valid key.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

from mercmac.errors import MercmacError
from mercmac.suggest import did_you_mean
from mercmac.timespec import TimeSpecError, parse_duration
from mercmac.vm.machine import Machine

if TYPE_CHECKING:
    from mercmac.sim.simulate import Simulation

CHECKS = ("outputs", "position", "macro", "running")


class ScenarioError(ValueError):
    """A scenario file that cannot be read or says something impossible; the message says where."""


class ScenarioFailed(MercmacError):
    """An expectation did not hold (exit 1)."""


@dataclass(frozen=True, slots=True)
class Step:
    at_ms: int
    press: tuple[int, ...]
    release: tuple[int, ...]
    controller: str | None = None  # a rig's controller (`run`); None: the box's


@dataclass(frozen=True, slots=True)
class Expect:
    number: int
    start_ms: int
    end_ms: int
    checks: dict
    controller: str | None = None  # a rig's controller (`run`)

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
    accepted: frozenset[str] = frozenset()  # hazard rules the scenario accepts (mercmac/hazards.py)


def load(path: str) -> Scenario:
    """Read and validate a scenario file; ScenarioError names the file and the place.
    (mercmac.tomlfile reads it, as settings and rigs are read; an OSError such as no such
    file is left to the CLI, which names the file.)"""
    from mercmac import tomlfile
    from mercmac.source import SourceError

    try:
        data = tomlfile.read(path).table
    except SourceError as e:  # a FIFO, /dev/zero, a file of many MB: the scenario's fault
        raise ScenarioError(f"{path}: {e.strerror}") from None
    except tomlfile.TomlError as e:
        at = f" (at line {e.line}, column {e.column})" if e.line else ""
        raise ScenarioError(f"{path}: {e.why}{at}") from None
    return parse(path, data)


def parse(path: str, data: dict) -> Scenario:
    """Check the tables read from a scenario file; ScenarioError says which key and why."""
    try:
        return _parse(path, data)
    except ScenarioError as e:
        raise ScenarioError(f"{path}: {e}") from None


def _parse(path: str, data: dict) -> Scenario:
    _refuse_unknown("", data, ("until", "allow_hazards", "step", "expect"),
                    "use until, allow_hazards, [[step]], [[expect]]")
    until = _duration("until", data["until"]) if "until" in data else None
    steps = [_step(i, s) for i, s in enumerate(_tables("step", data), 1)]
    expects = [_expect(i, e) for i, e in enumerate(_tables("expect", data), 1)]
    return Scenario(path, until, sorted(steps, key=lambda s: s.at_ms), expects,
                    _allowed(data.get("allow_hazards", [])))


def _allowed(value) -> frozenset[str]:
    """allow_hazards: a list of hazard rules, codes or names (mercmac/hazards.py)."""
    from mercmac.hazards import accepted_rules

    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise ScenarioError(f"allow_hazards = {_show(value)}: write a list of hazard rules, "
                            'e.g. allow_hazards = ["soft-limit-clamp"]')
    try:
        return accepted_rules(value, "allow_hazards")
    except ValueError as e:
        raise ScenarioError(str(e)) from None


def _tables(key: str, data: dict) -> list[dict]:
    """The [[key]] tables; anything else in their place is refused with what to write."""
    value = data.get(key, [])
    if isinstance(value, dict):
        raise ScenarioError(f"[{key}] is a single table: write [[{key}]] (double brackets), "
                            f"one per {key}")
    if not isinstance(value, list):
        raise ScenarioError(f"{key} = {_show(value)}: write [[{key}]] tables, one per {key}")
    for i, table in enumerate(value, 1):
        if not isinstance(table, dict):
            raise ScenarioError(f"{key} {i} is {_kind(table)} ({_show(table)}), expected a table: "
                                f"write [[{key}]] with its keys below")
    return value


def _duration(name: str, value) -> int:
    """Milliseconds from a TOML string such as "1.5s" or a whole number of ms."""
    if isinstance(value, bool) or not isinstance(value, (str, int)):
        raise ScenarioError(f"{name} is {_kind(value)} ({_show(value)}), expected a duration "
                            'such as "250ms" or "1.5s", or a whole number of ms')
    try:
        return parse_duration(str(value))
    except TimeSpecError as e:
        raise ScenarioError(f"{name}: {e}") from None


def _whole(value) -> bool:
    """A TOML integer (bool is an int in Python, but `true` is not a number)."""
    return isinstance(value, int) and not isinstance(value, bool)


def _inputs(name: str, value) -> tuple[int, ...]:
    values = value if isinstance(value, list) else [value]
    if not all(_whole(v) and 1 <= v <= 6 for v in values):
        raise ScenarioError(f"{name} = {_show(value)}: inputs are numbers 1-6, alone or in a list "
                            "such as [1, 3] (1-4 buttons, 5 joystick, 6 joystick button)")
    return tuple(values)


def _refuse_unknown(where: str, raw: dict, valid: tuple[str, ...], use: str) -> None:
    """Name the first key that is not one of `valid`, with the nearest valid one."""
    unknown = sorted(str(k) for k in raw if k not in valid)
    if not unknown:
        return
    key = unknown[0]
    hint = did_you_mean(key, valid, _reach(key))
    hint = f"{hint} " if hint else ""
    more = f" (and {len(unknown) - 1} more)" if len(unknown) > 1 else ""
    raise ScenarioError(f"{where}unknown key {_show(key)}{more}: {hint}{use}")


def _reach(word: str) -> int:
    """How far a key or macro name may be misspelled: two edits for short words (`untill`)."""
    return max(2, len(word) // 3)


def _step(i: int, raw: dict) -> Step:
    _refuse_unknown(f"step {i}: ", raw, ("at", "press", "release", "controller"),
                    "a step has at, press and release (and in a rig, controller)")
    if "at" not in raw:
        raise ScenarioError(f"step {i}: write at = \"1s\" with press = [..] and/or "
                            "release = [..]")
    return Step(_duration(f"step {i}: at", raw["at"]),
                _inputs(f"step {i}: press", raw.get("press", [])),
                _inputs(f"step {i}: release", raw.get("release", [])),
                _controller(f"step {i}", raw))


def _controller(where: str, raw: dict) -> str | None:
    """`controller = "y"`: which controller of a rig a step or an expectation is about."""
    name = raw.get("controller")
    if name is not None and not (isinstance(name, str) and name.strip()):
        raise ScenarioError(f"{where}: controller = {_show(name)}: expected the name of a "
                            "controller of the rig, e.g. controller = \"y\"")
    return name


def _expect(i: int, raw: dict) -> Expect:
    _refuse_unknown(f"expect {i}: ", raw, ("at", "within", "controller") + CHECKS,
                    f"an expectation has at or within, and {', '.join(CHECKS)}")
    checks = {k: v for k, v in raw.items() if k in CHECKS}
    timing = set(raw) - set(checks) - {"controller"}
    if not checks or timing not in ({"at"}, {"within"}):
        raise ScenarioError(f"expect {i}: give `at` or `within` and one or more of "
                            f"{', '.join(CHECKS)}")
    if "at" in raw:
        start = end = _duration(f"expect {i}: at", raw["at"])
    else:
        window = raw["within"]
        if not (isinstance(window, list) and len(window) == 2):
            raise ScenarioError(f"expect {i}: within = {_show(window)}: "
                                'expected two times, within = ["T1", "T2"]')
        start, end = (_duration(f"expect {i}: within", t) for t in window)
        if end < start:
            raise ScenarioError(f"expect {i}: the window ends before it starts")
    for key, value in checks.items():
        _validate(i, key, value)
    return Expect(i, start, end, checks, _controller(f"expect {i}", raw))


EXPECTED = {  # what each check takes, and how to say so
    "outputs": (lambda v: _whole(v) and 0 <= v <= 15, "the LED pattern, a whole number 0-15"),
    "position": (lambda v: _whole(v) or (isinstance(v, list) and len(v) == 2
                                         and all(map(_whole, v)) and v[0] <= v[1]),
                 "a whole number, or a range [low, high] with low <= high"),
    "macro": (lambda v: (isinstance(v, str) and v.strip() != "") or (_whole(v) and 0 <= v <= 31),
              'a macro number 0-31, a macro name, or "none" for direct mode'),
    "running": (lambda v: isinstance(v, bool), "true or false"),
}


def _validate(i: int, key: str, value) -> None:
    ok, expected = EXPECTED[key]
    if not ok(value):
        raise ScenarioError(f"expect {i}: {key} = {_show(value)}: expected {expected}")


def _kind(value) -> str:
    """The TOML name of a value's type, for messages."""
    kinds = ((bool, "a boolean"), (int, "an integer"), (float, "a float"), (str, "a string"),
             (list, "an array"), (dict, "a table"))
    return next((name for t, name in kinds if isinstance(value, t)), "a date or time")


def _show(value, limit: int = 40) -> str:
    """A value as TOML would write it, shortened for a message."""
    text = json.dumps(value, default=str, ensure_ascii=True)
    return text if len(text) <= limit else f"{text[:limit - 12]}...{text[-9:]}"


def _names(m: Machine) -> set[str]:
    """The macro names a scenario may use: each slot's name and the macros it was hoisted from."""
    names = set()
    for chunk in m.chunks.values():
        parts = chunk.name.split(".")
        names.update(".".join(parts[:k]) for k in range(1, len(parts) + 1))
    return names - {""}


def _is_named(name: str | None, want: str) -> bool:
    """`run` names the macro run and the parts hoisted out of it (`run.when@20`)."""
    return name is not None and (name == want or name.startswith(want + "."))


def check_names(m: Machine, scenario: Scenario) -> None:
    """Refuse a macro name that the program does not have, with the nearest one."""
    names = _names(m)
    for expect in scenario.expects:
        want = expect.checks.get("macro")
        if isinstance(want, str) and want != "none" and want not in names:
            near = did_you_mean(want, names, _reach(want))
            hint = f"; {near}" if near else \
                f"; it has {', '.join(sorted(names)) or 'no named macros'}"
            raise ScenarioError(f"{scenario.name}: expect {expect.number}: macro = {_show(want)}: "
                                f"the program has no macro of that name{hint}")


def mismatch(m: Machine, checks: dict) -> str | None:
    """Why the machine does not meet the checks now, or None if it does."""
    actual = {"outputs": m.outputs_pattern(), "position": m.position(),
              "macro": "none" if m.macro is None else m.macro, "running": m.running}
    for key, want in checks.items():
        have = actual[key]
        if key == "position" and isinstance(want, list):
            good = want[0] <= have <= want[1]
        elif key == "macro" and isinstance(want, str) and want != "none":
            good = m.macro is not None and _is_named(m.chunk.name, want)
            have = m.label if m.macro is not None else "none"
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


def run(sim: Simulation, plan: Scenario, until_ms: int) -> int:
    """Power on, play the steps, check every expectation in time order (all controllers on
    the rig's one clock); the number checked. In a rig of several, a step or an expectation
    is about the controller it names (`controller = "y"`), else the box's (or the only one):
    a step presses only what a person can (rig.presses)."""
    default = _default(sim)
    parts = {name: _part(sim, plan, name, default) for name in sim.machines}
    _refuse_unknown_names(sim, plan, default)
    _refuse_unpressable(sim, plan, default)
    for name, part in parts.items():
        check_names(sim.machines[name], part)
        schedule_steps(sim.machines[name], part)
    sim.power_on()
    expects = sorted((e for part in parts.values() for e in part.expects),
                     key=lambda e: (e.start_ms, e.number))
    for expect in expects:
        check(sim, expect)
    sim.run_until(max(until_ms, sim.now_ms()))
    return len(expects)


def _default(sim: Simulation) -> str | None:
    """Who a step or expectation without `controller` is about: the box's controller, or
    the only one."""
    if sim.rig.box is not None:
        return sim.rig.box
    return next(iter(sim.machines)) if len(sim.machines) == 1 else None


def _part(sim: Simulation, plan: Scenario, name: str, default: str | None) -> Scenario:
    """The steps and expectations about controller `name`, each naming it; named in the
    messages where the rig has several."""
    steps = [s for s in plan.steps if (s.controller or default) == name]
    expects = [replace(e, controller=name) for e in plan.expects
               if (e.controller or default) == name]
    shown = f"{plan.name} ({name})" if sim.rig.several else plan.name
    return Scenario(shown, plan.until_ms, steps, expects)


def _refuse_unknown_names(sim: Simulation, plan: Scenario, default: str | None) -> None:
    named = next((e for e in [*plan.steps, *plan.expects] if e.controller), None)
    if named is not None and sim.rig.lone:
        raise ScenarioError(f"{plan.name}: controller = {_show(named.controller)} is for "
                            "a rig file (*.rig.toml); this run has one controller")
    names = ", ".join(sim.machines)
    for item in [*plan.steps, *plan.expects]:
        name = item.controller
        if name is None and default is None:
            raise ScenarioError(f"{plan.name}: the rig has no box: give each step and "
                                f"expectation its controller = \"...\" ({names})")
        if name is not None and name not in sim.machines:
            raise ScenarioError(f"{plan.name}: controller = \"{name}\": the rig has no "
                                f"controller of that name ({names})")


def _refuse_unpressable(sim: Simulation, plan: Scenario, default: str | None) -> None:
    """A step presses or releases only what a person can (rig.presses): the box's connected
    buttons on its controller, on inputs no wire drives; the joystick's on its branches."""
    from mercmac.rig.presses import refusal

    for step in plan.steps:
        name = step.controller or default
        for number in sorted({*step.press, *step.release}):
            why = refusal(sim.rig, name, number)
            if why:
                raise ScenarioError(f"{plan.name}: the step at {step.at_ms} ms on {name}, "
                                    f"input {number}: {why}")


def check(sim: Simulation, expect: Expect) -> None:
    """Run the rig through the expectation's time; ScenarioFailed if it never holds."""
    m = sim.machines[expect.controller]
    sim.run_until(expect.start_ms)
    while True:
        why = mismatch(m, expect.checks)
        if why is None:
            return
        if sim.now_ms() >= expect.end_ms:
            on = f" on {expect.controller}" if sim.rig.several else ""
            raise ScenarioFailed(f"{expect.describe()}{on} failed: {why}")
        sim.run_until(min(expect.end_ms, next_change_ms(sim)))


def next_change_ms(sim: Simulation) -> float:
    """When any controller's checked state may change next (a wire joins them): an event, a
    command, or 1 ms on while one moves."""
    now = sim.now_ms()
    t = sim.next_us() / 1000
    for m in sim.machines.values():
        t = min(t, m.next_event_ms())
        if m.moving():
            t = min(t, m.now_ms + 1)
    return t if t > now else now + min(m.cycle_ms for m in sim.machines.values())


def text(source: str, until_ms: int, changes: list[tuple[int, str, int, bool]],
         final: dict[str, tuple[int, int, int | None]], *, lone: bool) -> str:
    """A scenario file of button changes (at_ms, controller, button, down) that expects, at
    until_ms, each controller's final (position, outputs, macro): what `sim --web` saves.
    A lone program's steps and expectations name no controller."""
    def named(controller: str) -> list[str]:
        return [] if lone else [f"controller = {json.dumps(controller)}"]

    out = ["# A session of the live box (`mercmac sim --web`) from its last power-on: the",
           "# buttons pressed and released, and what each controller showed at its end.",
           f"#   mercmac sim {source} --scenario THIS_FILE",
           f'until = "{until_ms}ms"']
    steps: dict[tuple[int, str], dict[bool, list[int]]] = {}
    for at_ms, controller, button, down in changes:
        steps.setdefault((at_ms, controller), {True: [], False: []})[down].append(button)
    for (at_ms, controller), moved in steps.items():
        out += ["", "[[step]]", f'at = "{at_ms}ms"', *named(controller)]
        out += [f"{key} = {sorted(set(moved[down]))}" for key, down in
                (("press", True), ("release", False)) if moved[down]]
    for controller, (position, outputs, macro) in final.items():
        out += ["", "[[expect]]", f'at = "{until_ms}ms"', *named(controller),
                f"position = {position}", f"outputs = {outputs}",
                f"macro = {macro if macro is not None else json.dumps('none')}"]
    return "\n".join(out) + "\n"
