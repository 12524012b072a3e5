"""A simulation run as plain data."""
from __future__ import annotations


def observed(record) -> dict:
    """What a simulation run recorded, as plain data to compare two runs (fast-forward on/off)."""
    return {
        "reports": [(r.t, r.text) for r in record.reports],
        "outputs": [(o.t, o.pattern) for o in record.outputs],
        "dropped": (record.dropped["reports"], record.dropped["outputs"]),
        "hazards": [(h.t, h.rule, h.where) for h in record.hazards],
        "ended": record.ended_at,
    }
