"""The stage axis: profile generator, home, soft and hard limits, reference switch (MS176E §4).

Positions are in the controller's coordinates (counts or microsteps); the limit
switches and the reference switch sit at fixed physical places, so DH (which
redefines the coordinates) shifts where they appear (§4.4.2: soft limits refer
to the current home, hard ones do not).
"""
from __future__ import annotations

import math

from mercmac.commands import MAX_POSITION
from mercmac.vm import fastforward as ff
from mercmac.vm.models import Defaults, Options
from mercmac.vm.trapezoid import PER_S, PER_S2, Segment, plan, stop

INF = math.inf


class Axis:
    """One motor axis with a trapezoidal profile generator."""

    # fast-forward's state key (fastforward.key_fields): everything that decides future motion
    STATE_KEY = ("segs", "final", "target", "shift", "sv", "sa", "jh", "jl", "servo",
                 "joystick", "homing", "referenced", "stalled", "edge_ahead", "negative", "limit")
    NOT_KEYED = {
        "defaults": "the model's power-on values: fixed for the axis's life",
        "options": "bench facts (switch positions, servo at power-on): fixed for the axis's life",
    }
    state_key = ff.key_fields(*STATE_KEY)

    def __init__(self, defaults: Defaults, options: Options):
        self.defaults, self.options = defaults, options
        self.reset()

    def reset(self) -> None:
        """Power-on state: position 0 (§3.5.1: "upon power-on ... set to zero")."""
        self.segs: tuple[Segment, ...] = ()  # a tuple: replaced, never changed in place
        self.final = 0.0  # where the axis rests once segs are done
        self.target = 0
        self.shift = 0.0  # coordinates = physical position + shift (DH)
        self.sv, self.sa = self.defaults.sv, self.defaults.sa
        self.jh, self.jl = self.defaults.jh, self.defaults.jl
        self.servo = self.options.servo_on
        self.joystick = 0  # JN velocity, 0 = off
        self.homing = self.referenced = self.stalled = False
        self.edge_ahead = False  # the running FE search heads for the edge (not away from it)
        self.negative = False  # last move direction, TS block 3 bit 2
        self.limit: tuple[float, str] | None = None  # (time, 'positive'|'negative')

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

    def limit_switch(self, t: float) -> str | None:
        """'positive'/'negative' while a hard limit switch is pressed."""
        if self.options.hard_limits is None:
            return None
        lo, hi = self.options.hard_limits
        p = self.position(t) - self.shift
        return "positive" if p >= hi else "negative" if p <= lo else None


    # -- commanding it --
    def move(self, t: float, target: int, vmax: float | None = None) -> None:
        """Start a profile to target from the present state of motion."""
        x, v = self.position(t), self.velocity(t) * PER_S
        self.target = target
        speed = (self.sv if vmax is None else vmax) * PER_S
        self.stalled = x != target and (speed <= 0 or self.sa <= 0)
        if self.stalled:  # SV0 or SA0: the profile never gets anywhere
            self.segs, self.final = (), x
            return
        self.segs = tuple(plan(t, x, v, target, speed, self.sa * PER_S2))
        self.final = float(target)
        if self.segs:
            self.negative = self.segs[-1].v0 < 0
        self._find_limit()

    def halt(self, t: float) -> None:
        """AB: profile velocity zero at once, target := position (§6.4 AB)."""
        self.final = self.position(t)
        self.segs, self.stalled, self.homing, self.limit = (), False, False, None
        self.target = round(self.final)

    def decelerate(self, t: float) -> None:
        """AB1: decelerate with SA; the target becomes the stop point (SPEC §3)."""
        if self.sa <= 0:
            return self.halt(t)
        self.segs = tuple(stop(t, self.position(t), self.velocity(t) * PER_S, self.sa * PER_S2))
        self.final = self.segs[-1].x(self.segs[-1].t1) if self.segs else self.position(t)
        self.target, self.stalled, self.homing = round(self.final), False, False
        self._find_limit()

    def define_home(self, t: float, value: int) -> None:
        """DH: the present position becomes `value`, target shifted alike (SPEC §3)."""
        delta = value - self.position(t)
        self.shift += delta
        self.segs = tuple(Segment(s.t0, s.x0 + delta, s.v0, s.a, s.dt) for s in self.segs)
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
        if self.options.hard_limits is not None:
            lo, hi = self.options.hard_limits
            return (hi if positive else lo) + self.shift
        return MAX_POSITION if positive else -MAX_POSITION

    # -- events --
    def _find_limit(self) -> None:
        """Schedule the first crossing of a hard limit switch by the new profile."""
        self.limit = None
        if self.options.hard_limits is None:
            return
        lo, hi = (p + self.shift for p in self.options.hard_limits)
        for seg in self.segs:
            end = seg.x(seg.t1)
            for side, edge, toward in (("positive", hi, end > seg.x0), ("negative", lo, end < seg.x0)):
                when = seg.time_at(edge) if toward else None
                if when is not None:
                    self.limit = (math.ceil(when), side)
                    return

    def next_event(self) -> float:
        """Time of the next arrival or limit hit, INF if none."""
        if self.limit is not None:
            return self.limit[0]
        end = self.arrival()
        return end if self.segs else INF

    def advance(self, t: float) -> tuple[str, float] | None:
        """Handle the event due at t: ('limit', side) or ('arrived', position)."""
        if self.limit is not None and self.limit[0] <= t:
            side = self.limit[1]
            lo, hi = (p + self.shift for p in self.options.hard_limits)
            self.halt(t)
            self.final = hi if side == "positive" else lo
            self.target = round(self.final)
            return ("limit", side)
        if self.segs and self.arrival() <= t:
            self.segs = ()
            self.referenced = self.referenced or (self.homing and self.edge_ahead)
            self.homing = False
            return ("arrived", self.final)
        return None
