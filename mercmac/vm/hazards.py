"""Hazards: what would hurt on the bench, reported once per rule and instruction."""
from __future__ import annotations

# rule -> what it means; the simulator reports each with time and source line.
RULES = {
    "move-servo-off": "a move was commanded while the servo is off (MF): error 0A, §6.4 TS",
    "move-joystick-on": "a move was commanded while the joystick is on: refused, error 0B, §6.4 MA",
    "soft-limit-clamp": "the target lies beyond a soft limit and was clamped to it, §4.4.2",
    "hard-limit": "the stage ran into a limit switch and stopped abruptly, §4.4.1",
    "ws-never-finishes": "WS waits for an on-target state the profile never reaches (SV0/SA0)",
    "busy-loop": "a long loop repeats without any wait, at the full command rate",
    "reference-not-found": "FE searches away from the reference switch, §6.4 FE",
}


class HazardLog:
    """Remembers which (rule, instruction) pairs were reported, so each is reported once."""

    def __init__(self):
        self.seen: set[tuple] = set()

    def first(self, rule: str, where_key: tuple) -> bool:
        """True the first time this rule fires at this place."""
        if rule not in RULES:
            raise KeyError(f"unknown hazard rule {rule}")
        key = (rule, where_key)
        if key in self.seen:
            return False
        self.seen.add(key)
        return True
