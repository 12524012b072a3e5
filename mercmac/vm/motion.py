"""The stage axis: profile generator, home, soft and hard limits, reference switch (MS176E §4).

Positions are in the controller's coordinates (counts or microsteps); the limit
switches and the reference switch sit at fixed physical places, so DH (which
redefines the coordinates) shifts where they appear (§4.4.2: soft limits refer
to the current home, hard ones do not).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

from mercmac.commands import MAX_POSITION
from mercmac.ops import TextEnum
from mercmac.vm.models import Defaults, Options
from mercmac.vm.statekey import key, keyed, unkeyed
from mercmac.vm.trapezoid import PER_S, PER_S2, Segment, plan, stop

INF = math.inf


class Side(TextEnum):
    """A limit switch of the travel (§4.4.1)."""

    POSITIVE = "positive"
    NEGATIVE = "negative"


class Ended(TextEnum):
    """How a profile ended (events.MoveEnded.how)."""

    ARRIVED = "arrived"  # on target
    LIMIT = "limit"  # stopped abruptly by a hard limit switch


class Ending(NamedTuple):
    """What `Axis.advance` found: the profile ended, and at which switch if at one."""

    how: Ended
    side: Side | None = None


class Plan(NamedTuple):
    """What the running profile was planned from (trapezoid.plan's inputs): planned again
    from the same inputs moved on, it is what stepping plans there (Axis.translate)."""

    t: int  # us, the command's time
    x: float
    v: float  # counts/us
    target: int
    speed: float  # counts/us
    acc: float  # counts/us^2

    def segments(self) -> tuple[Segment, ...]:
        """The profile planned from it."""
        return tuple(plan(*self))


def shared(p: Plan, segs: tuple, t: float, target: int) -> tuple | None:
    """The profile planned from p's start to `target` if it takes the path of `segs` (planned
    from p) up to t: the same segments before the one the stage is on at t, that one the
    same but for its length, and still on at t; else None (Axis.keeps)."""
    on = next((i for i, s in enumerate(segs) if t < s.t1), None)
    if on is None:
        return None
    other = p._replace(target=target).segments()
    same = (len(other) > on and other[:on] == segs[:on] and other[on][:4] == segs[on][:4]
            and t < other[on].t1)
    return other if same else None


class LimitHit(NamedTuple):
    """When the running profile first reaches a limit switch, and which one."""

    t: int
    side: Side


@keyed()
@dataclass(eq=False)
class Axis:
    """One motor axis with a trapezoidal profile generator.

    Every field but the two fixed ones decides future motion: fast-forward's state key.
    """

    defaults: Defaults = unkeyed("the model's power-on values: fixed for the axis's life")
    options: Options = unkeyed("bench facts (switch positions, servo at power-on): fixed "
                               "for the axis's life")
    # a tuple: replaced, never changed in place; with plan, the key has them relative to the
    # time and the target while the axis moves (vm/optimiser.py)
    segs: tuple[Segment, ...] = key(init=False, shifts=True)
    plan: Plan | None = key(init=False, shifts=True)  # None: at rest, or not planned (DH, AB1)
    final: float = key(init=False, shifts=True)  # where the axis rests once segs are done
    target: int = key(init=False, shifts=True)
    shift: float = key(init=False)  # coordinates = physical position + shift (DH)
    sv: int = key(init=False)
    sa: int = key(init=False)
    jh: int = key(init=False)
    jl: int = key(init=False)
    servo: bool = key(init=False)
    joystick: int = key(init=False)  # JN velocity, 0 = off
    homing: bool = key(init=False)
    referenced: bool = key(init=False)
    stalled: bool = key(init=False)
    edge_ahead: bool = key(init=False)  # the running FE search heads for the edge (not away)
    negative: bool = key(init=False)  # last move direction, TS block 3 bit 2
    limit: LimitHit | None = key(init=False)

    def __post_init__(self):
        self.reset()

    def reset(self) -> None:
        """Power-on state: position 0 (§3.5.1: "upon power-on ... set to zero")."""
        self.segs, self.plan = (), None
        self.final = 0.0
        self.target = 0
        self.shift = 0.0
        self.sv, self.sa = self.defaults.sv, self.defaults.sa
        self.jh, self.jl = self.defaults.jh, self.defaults.jl
        self.servo = self.options.servo_on
        self.joystick = 0
        self.homing = self.referenced = self.stalled = False
        self.edge_ahead = False
        self.negative = False
        self.limit = None

    # -- reading the state --
    def _seg(self, t: float) -> Segment | None:
        for seg in self.segs:
            if t < seg.t1:
                return seg
        return None

    def position(self, t: float) -> float:
        seg = self._seg(t)
        return self.final if seg is None else seg.x(t)

    def velocity(self, t: float) -> float:
        """Profile velocity in counts/s (what TV reports)."""
        seg = self._seg(t)
        return 0.0 if seg is None else seg.v(t) / PER_S

    def moving(self, t: float) -> bool:
        return self.stalled or (bool(self.segs) and t < self.segs[-1].t1)

    def arrival(self) -> float:
        """When the profile ends (INF if it never will); the on-target time (§4.2, WT0)."""
        if self.stalled:
            return INF
        return math.ceil(self.segs[-1].t1) if self.segs else -INF

    def reference_high(self, t: float) -> bool:
        """The reference line: high on the negative side of the switch (§6.4 FE2)."""
        return self.position(t) - self.shift < self.options.reference_at

    def at_rest_on_count(self) -> bool:
        """Still, with its rest position a whole count: a move from here shifts exactly."""
        return not (self.segs or self.stalled or not float(self.final).is_integer())

    def relative(self, now: int) -> tuple | None:
        """The running profile relative to `now` and the target: what two passes that repeat
        it (shifted) have alike, fast-forward's key while the axis moves; None when it was
        not planned by `move` (DH moved it, AB1 stops it) or never ends (a stall)."""
        p = self.plan
        if p is None or self.stalled:
            return None
        return p.t - now, p.x - self.target, p.v, p.target - self.target, p.speed, p.acc

    def translate(self, dt: int, dx: int) -> None:
        """Move the axis on by `dt` us and `dx` counts: where the passes a fast-forward skips
        leave it (vm/optimiser.py). A profile planned from rest on a count is planned again
        from there, as stepping plans it; any other is moved on, the same floats within one
        power of two (skips._same_binade bounds such skips)."""
        self.target += dx
        self.final += dx
        p = self.plan
        if p is None:
            return
        self.plan = p._replace(t=p.t + dt, x=p.x + dx, target=p.target + dx)
        if p.v == 0 and float(p.x).is_integer():
            self.segs = tuple(plan(p.t + dt, p.x + dx, 0.0, p.target + dx, p.speed, p.acc))
        else:
            self.segs = tuple(s.moved(dt, dx) for s in self.segs)
        self._find_limit()

    def soft_range(self) -> tuple[int, int]:
        """Where a target is not clamped: the soft limits within the 32-bit range (§4.4.2)."""
        return max(self.jl, -MAX_POSITION), min(self.jh, MAX_POSITION)

    def switches(self) -> tuple[float, float] | None:
        """The hard limit switches in present coordinates (DH shifts them, §4.4.2), if any."""
        if self.options.hard_limits is None:
            return None
        lo, hi = self.options.hard_limits
        return lo + self.shift, hi + self.shift

    def limit_switch(self, t: float) -> Side | None:
        """The hard limit switch pressed at t, if one is."""
        if self.options.hard_limits is None:
            return None
        lo, hi = self.options.hard_limits
        p = self.position(t) - self.shift
        return Side.POSITIVE if p >= hi else Side.NEGATIVE if p <= lo else None

    # -- commanding it --
    def move(self, t: float, target: int, vmax: float | None = None) -> bool:
        """Start a profile to target from the present state of motion; True when the running
        profile goes on instead (Axis.keeps)."""
        speed = (self.sv if vmax is None else vmax) * PER_S
        kept = self.keeps(t, target, speed)
        if kept is not None:
            if kept is not self.segs:
                self.plan = self.plan._replace(target=target)
                self._run(kept)
            return True
        x, v = self.position(t), self.velocity(t) * PER_S
        self.target = target
        self.stalled = x != target and (speed <= 0 or self.sa <= 0)
        if self.stalled:  # SV0 or SA0: the profile never gets anywhere
            self.segs, self.final, self.plan = (), x, None
            return
        self.plan = Plan(t, x, v, target, speed, self.sa * PER_S2)
        self.segs = tuple(plan(*self.plan))
        if not self.segs:
            self.plan = None
        self.final = float(target)
        if self.segs:
            self.negative = self.segs[-1].v0 < 0
        self._find_limit()
        return False

    def keeps(self, t: float, target: int, speed: float) -> tuple | None:
        """The profile a move to `target` at `speed` (counts/us) commanded at t goes on along,
        planned from the running plan's start; None when it is planned anew from here.

        In flight, with that velocity and SA, to that very target: the running profile. A
        trapezoid planned from any state it passes through is the rest of itself (what stays
        of it keeps a*d + v^2/2, so the peak, the turn and the deceleration point stay), so
        the profile planned from here is the one running, and planned again in floats it
        would differ only by rounding. To another target, the profile planned from the same
        start when it takes the same path up to t (a target further on while the stage has
        not begun to slow down): the path so far is the stage's, and what follows is what
        planning from here gives (docs/simulator.md, "Motion")."""
        p = self.plan
        if not (p is not None and p.target == self.target and speed == p.speed
                and self.sa * PER_S2 == p.acc and not self.stalled and self.moving(t)):
            return None
        if target == p.target:
            return self.segs
        return shared(p, self.segs, t, target)

    def retarget(self, target: int) -> None:
        """The running profile planned from its start to `target` (a skip's passes moved it
        on so, each keeping it: Axis.keeps)."""
        self.plan = self.plan._replace(target=target)
        self._run(self.plan.segments())

    def _run(self, segs: tuple) -> None:
        """Run `segs`, planned from self.plan, to its target."""
        self.segs = segs
        self.target = self.plan.target
        self.final = float(self.target)
        self.negative = segs[-1].v0 < 0
        self._find_limit()

    def halt(self, t: float) -> None:
        """AB: profile velocity zero at once, target := position (§6.4 AB)."""
        self.final = self.position(t)
        self.segs, self.stalled, self.homing, self.limit = (), False, False, None
        self.plan = None
        self.target = round(self.final)

    def decelerate(self, t: float) -> None:
        """AB1: decelerate with SA; the target becomes the stop point (docs/simulator.md)."""
        if self.sa <= 0:
            return self.halt(t)
        self.segs = tuple(stop(t, self.position(t), self.velocity(t) * PER_S, self.sa * PER_S2))
        self.plan = None
        self.final = self.segs[-1].x(self.segs[-1].t1) if self.segs else self.position(t)
        self.target, self.stalled, self.homing = round(self.final), False, False
        self._find_limit()

    def define_home(self, t: float, value: int) -> None:
        """DH: the present position becomes `value`, target shifted alike (docs/simulator.md)."""
        delta = value - self.position(t)
        self.shift += delta
        self.segs = tuple(s.moved(0, delta) for s in self.segs)
        self.plan = None
        self.final += delta
        self.target = round(self.target + delta)

    def find_edge(self, t: float, mode: int) -> bool:
        """FEn (§6.4 FE): search for the reference edge; False when it runs away from it."""
        high = self.reference_high(t)
        positive = {0: True, 1: False, 2: high, 3: not high}[mode]
        edge = self.options.reference_at + self.shift
        found = (edge >= self.position(t)) == positive or edge == self.position(t)
        goal = edge if found else self._runaway(positive)
        self.move(t, round(goal))  # §6.4 FE: not affected by the soft limits
        self.homing, self.edge_ahead = bool(self.segs), found
        self.referenced = self.referenced or (found and not self.segs)  # already on the edge
        return found

    def _runaway(self, positive: bool) -> float:
        """Where a search in the wrong direction ends: the limit switch, or out of range."""
        switches = self.switches()
        if switches is not None:
            return switches[1] if positive else switches[0]
        return MAX_POSITION if positive else -MAX_POSITION

    # -- events --
    def _find_limit(self) -> None:
        """Schedule the first crossing of a hard limit switch by the new profile."""
        self.limit = None
        switches = self.switches()
        if switches is None:
            return
        lo, hi = switches
        for seg in self.segs:
            end = seg.x(seg.t1)
            for side, edge, toward in ((Side.POSITIVE, hi, end > seg.x0),
                                       (Side.NEGATIVE, lo, end < seg.x0)):
                when = seg.time_at(edge) if toward else None
                if when is not None:
                    self.limit = LimitHit(math.ceil(when), side)
                    return

    def next_event(self) -> float:
        """Time of the next arrival or limit hit, INF if none."""
        if self.limit is not None:
            return self.limit.t
        end = self.arrival()
        return end if self.segs else INF

    def advance(self, t: float) -> Ending | None:
        """Handle the event due at t: a limit hit or the arrival; None if none is due."""
        if self.limit is not None and self.limit.t <= t:
            side = self.limit.side
            lo, hi = self.switches()
            self.halt(t)
            self.final = hi if side is Side.POSITIVE else lo
            self.target = round(self.final)
            return Ending(Ended.LIMIT, side)
        if self.segs and self.arrival() <= t:
            self.segs, self.plan = (), None
            self.referenced = self.referenced or (self.homing and self.edge_ahead)
            self.homing = False
            return Ending(Ended.ARRIVED)
        return None
