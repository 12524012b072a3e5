"""The simulator's hazards as rules: what would hurt on the bench (docs/simulator.md, "Hazards").

Each is a `Rule` like the checks of `mercmac.diagnostics`, with a stable code
(MHnnn), its story and its message templates, so that `mercmac explain MH004` /
`explain hard-limit` shows it. The machine reports each with values, never wording
(mercmac.vm.hazards.HazardLog). The table is data beside the checks' rules, so that
what names a hazard (`// mercmac: expect[...]`, read with the suppression comments;
`sim --allow-hazard`) reads it without the simulator.
"""
from __future__ import annotations

from mercmac.diagnostics import Rule, Severity

_W = Severity.WARNING

RULES: tuple[Rule, ...] = (
    Rule("MH001", "move-servo-off", _W, "a move was commanded while the servo is off (MF)", """\
With the servo off (MF) the controller does not drive the motor: the stage
neither holds its position nor moves, and the C-863 refuses the move with
error 0A "Servo off" in the TS report (MS176E §6.4 TS, MN/MF). The manual's
stand-alone examples never send MN, so whether the servo is on at power-on is
a simulator option (`sim --servo-off`); on the bench it depends on the
controller's settings. Send MN before the first move, e.g. at the start of
the autostart macro.""", {
        "move": "move while the servo is off: the stage will not hold or move; send MN first",
        "search": "reference search while the servo is off; send MN first",
    }),
    Rule("MH002", "move-joystick-on", _W, "a move was commanded while the joystick is on", """\
While a joystick axis is enabled (JN) the controller refuses motion commands
(MA, MR, GH, FE, ...) with error 0B (MS176E §3.6.1, §6.4 MA): the macro runs on
but the stage does not go where the macro says. Send JF before the move and
JN again after it, or keep joystick and macro moves in different modes
(Example 4 switches with EM).""", {
        "": "move refused: the joystick is on (JN); send JF first"}),
    Rule("MH003", "soft-limit-clamp", _W, "a target beyond a soft limit was clamped to it", """\
The soft limits set with JH and JL (MS176E §4.4.2) clamp every target: a move
beyond them ends at the limit instead, so the position the macro expects and
the one the stage reaches differ, and everything after it (reports, relative
MR moves) is off by the difference. Move within the limits, widen them with
JH/JL, or clear them with JC if the travel allows. Each clamp of a new target
is reported. A jog that runs to the limit on purpose (`MR 9999999` stopped by
JH, as §4.4.2 intends) means it: accept it on its line with
`// mercmac: expect[soft-limit-clamp]`, in a scenario with `allow_hazards`, or
for a run with `sim --allow-hazard soft-limit-clamp`.""", {
        "": "target {target} lies beyond the {side} soft limit: the stage stops at {clamped}"}),
    Rule("MH004", "hard-limit", _W, "the stage ran into a limit switch and stopped abruptly", """\
The stage reached a limit switch of the travel range (MS176E §4.4.1): the
controller stops the motor at once, without the deceleration ramp, and sets
error 07 in the TS report. That is hard on the mechanics and the load, and
the target was not reached. Keep targets inside the travel (the simulator
places the switches with `sim --hard-limits NEG,POS`), or set soft limits
with JH/JL so that moves stop in time.""", {
        "": "the stage hit the {side} limit switch at {position} and stopped abruptly"}),
    Rule("MH005", "ws-never-finishes", _W, "WS waits for an on-target state the profile never reaches", """\
WS waits until the move is finished, then n ms (MS176E §6.4 WS). With a
programmed velocity SV0 or acceleration SA0 the profile never reaches its
target, so the macro hangs in WS for good and nothing after it runs. Set SV
and SA before the move (power-on defaults: C-863 SV 45000, SA 400000; C-663
SV 20000, SA 250000, §3.4), or use WA to wait a fixed time.""", {
        "": "WS waits for a move that never ends: SV is {sv}, SA is {sa}"}),
    Rule("MH006", "busy-loop", _W, "a long loop repeats without any wait, at the full command rate", """\
A loop (RP, or macros that call each other round) that runs many passes
without WA, WS, WN or WF executes at the full command rate, one command per
controller cycle. A polling loop like that keeps the controller
busy, floods the host with any reports it makes, and on a bench usually means
a missing wait. Add a WA of a few ms to each pass (`every 20ms { ... }` does
this for you).""", {
        "": "{macro} loops without a wait: it runs at the full command rate; add WA"}),
    Rule("MH007", "reference-not-found", _W, "FE searches away from the reference switch", """\
FE starts a reference (home) search in the direction its argument gives
(MS176E §6.4 FE, §4.3). When the reference switch lies the other way, the
stage runs to the end of its travel and stops at the limit switch without
having found the reference, so every later absolute move is off. Use the
other fixed direction (FE0 / FE1), or FE2 / FE3, which pick the direction from
the switch state. The simulator places the switch with `sim --reference-at`.""", {
        "": "FE{mode} searches away from the reference switch and runs to the end of travel"}),
    Rule("MH008", "rig-deadlock", _W, "every controller of a rig waits on a line no one will change",
         """\
In a rig (several controllers wired output to input, MS176E §3.8, §4.5.1) a
macro that waits with WN/WF on an input goes on only when that line changes:
the output at the far end of its wire, or a button of the C-170.PB box. An
input that no wire and no box button drives never changes on the rig, and an
output changes only while its controller runs. When every controller has
ended or waits for good (on an input nothing drives, on a wire from a
controller that has ended or waits too, or in a WS for a move that never
ends), and no move, timer, scripted button or joystick change is left, none
of them will ever go on: a dead-lock. On the bench the stand stops with no
error. A wait on an input a box button drives is never a dead-lock: a person
may still press the button. Typical causes: each side waits for the other's
signal before giving its own (raise your output before you wait), an output
is cleared before the other side saw it, or a wait on an input that is not
wired (add the wire, or name the box on that controller). `mercmac check` on
the rig finds wait cycles and sure dead-locks on unwired inputs before a run
(MR011).""", {
        "": "dead-lock: {waits}; no one will change these lines"}),
)

BY_NAME = {r.name: r for r in RULES}
NAMES = frozenset(BY_NAME)
_BY_KEY = BY_NAME | {r.code: r for r in RULES}


def named(key: str) -> str | None:
    """The name of the hazard rule `key` names (code or name, any case), or None."""
    found = _BY_KEY.get(key.strip().lower()) or _BY_KEY.get(key.strip().upper())
    return found.name if found else None


def accepted_rules(keys, what: str) -> frozenset[str]:
    """The names of the hazard rules KEYS name (codes or names, each may hold several,
    comma-separated): `--allow-hazard`, a scenario's `allow_hazards`. ValueError naming
    the first that is no hazard rule, with the nearest (`what`: where it was written)."""
    from mercmac.suggest import did_you_mean

    found = set()
    for key in (k.strip() for item in keys for k in str(item).split(",")):
        if not key:
            continue
        name = named(key)
        if name is None:
            near = did_you_mean(key, sorted(BY_NAME))
            also = f"; {near}" if near else ""
            raise ValueError(f"{what}: no hazard rule {key!r}{also} (the hazard rules: "
                             f"{', '.join(f'{r.code} {r.name}' for r in RULES)})")
        found.add(name)
    return frozenset(found)
