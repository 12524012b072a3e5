"""Hazards reported once per rule and instruction: the machine's log of them. The rules
themselves, codes, stories and message templates, are mercmac.hazards.
"""
from __future__ import annotations

from mercmac.hazards import BY_NAME


class HazardLog:
    """Remembers which (rule, instruction) pairs were reported, so each is reported once:
    a loop's passes would report the same thing again and again. A key may say more than
    the instruction (a clamp's target: each clamp of a new target is reported)."""

    def __init__(self):
        self.seen: set[tuple] = set()

    def add(self, rule: str, where_key: tuple | None, variant: str = "", /,
            **values) -> str | None:
        """The message of `rule` at this place, in the words of its `variant` template, the
        first time it fires there; None after (each is reported once)."""
        found = BY_NAME.get(rule)
        if found is None:
            raise KeyError(f"unknown hazard rule {rule}")
        key = (rule, where_key)
        if key in self.seen:
            return None
        self.seen.add(key)
        return found.text(variant, **values)
