"""Trapezoidal motion profiles in closed form (docs/simulator.md, "Motion";
MS176E §3.4, §6.4 SV/SA).

Velocity is limited to SV and acceleration equals deceleration, SA. Times are
microseconds and speeds counts per microsecond, so the clock stays integer.
"""
from __future__ import annotations

import math
from typing import NamedTuple

PER_S = 1e-6  # counts/s -> counts/us
PER_S2 = 1e-12  # counts/s^2 -> counts/us^2


class Segment(NamedTuple):
    """Constant acceleration `a` for `dt` us from (t0, x0, v0); position is monotonic in it.

    A NamedTuple, not a frozen dataclass: made for every move and for every move a skip
    lists (sim/record.py), three times faster."""

    t0: float
    x0: float
    v0: float
    a: float
    dt: float

    @property
    def t1(self) -> float:
        return self.t0 + self.dt

    def moved(self, dt: float, dx: float) -> Segment:
        """The same segment `dt` us later and `dx` counts further (DH, a skip's passes)."""
        return Segment(self.t0 + dt, self.x0 + dx, self.v0, self.a, self.dt)

    def x(self, t: float) -> float:
        tau = min(max(t - self.t0, 0.0), self.dt)
        return self.x0 + (self.v0 + 0.5 * self.a * tau) * tau

    def v(self, t: float) -> float:
        return self.v0 + self.a * min(max(t - self.t0, 0.0), self.dt)

    def time_at(self, x: float) -> float | None:
        """First time in this segment the position equals x, or None."""
        lo, hi = sorted((self.x0, self.x(self.t1)))
        if not lo <= x <= hi:
            return None
        d = x - self.x0
        if self.a == 0:
            return self.t0 if self.v0 == 0 else self.t0 + d / self.v0
        # x0 + v0 tau + a tau^2 / 2 = x: the root that lies in [0, dt]
        disc = max(self.v0 * self.v0 + 2 * self.a * d, 0.0)
        for tau in sorted(((-self.v0 + s * math.sqrt(disc)) / self.a for s in (1, -1))):
            if -1e-9 <= tau <= self.dt + 1e-9:
                return self.t0 + min(max(tau, 0.0), self.dt)
        return None


def _seg(out: list[Segment], t: float, x: float, v: float, a: float, dt: float):
    """Append a segment if it lasts; return the state (t, x, v) at its end."""
    if dt > 0:
        out.append(Segment(t, x, v, a, dt))
    return t + dt, x + (v + 0.5 * a * dt) * dt, v + a * dt


def plan(t: float, x: float, v: float, target: float, vmax: float, acc: float) -> list[Segment]:
    """Segments from state (t, x, v) to rest at target; [] when already there.

    A move that cannot stop in time, or starts moving away, first decelerates to
    rest and then turns round (how ST overshoots and "moves back", §6.4 ST).
    """
    out: list[Segment] = []
    d = target - x
    if v != 0 and (d == 0 or (d > 0) != (v > 0) or v * v / (2 * acc) > abs(d) + 1e-9):
        t, x, v = _seg(out, t, x, v, -math.copysign(acc, v), abs(v) / acc)
        v, d = 0.0, target - x
    if abs(d) < 1e-9:
        return out
    s, dist, u = math.copysign(1.0, d), abs(d), abs(v)
    if u > vmax:  # SV lowered during a move: slow down to the new velocity first
        t, x, _ = _seg(out, t, x, s * u, -s * acc, (u - vmax) / acc)
        u, dist = vmax, abs(target - x)
    peak = min(vmax, math.sqrt(acc * dist + u * u / 2))
    up, down = (peak * peak - u * u) / (2 * acc), peak * peak / (2 * acc)
    t, x, _ = _seg(out, t, x, s * u, s * acc, (peak - u) / acc)
    t, x, _ = _seg(out, t, x, s * peak, 0.0, max(dist - up - down, 0.0) / peak)
    _seg(out, t, x, s * peak, -s * acc, peak / acc)
    return out


def stop(t: float, x: float, v: float, acc: float) -> list[Segment]:
    """Decelerate to rest as fast as SA allows (AB1, §6.4)."""
    out: list[Segment] = []
    if v != 0:
        _seg(out, t, x, v, -math.copysign(acc, v), abs(v) / acc)
    return out

