"""The recorder: what a simulation run keeps of the machine's events (SPEC §5 `sim`).

Reports and output changes are kept up to a cap (SPEC §5: 10,000 each, the rest
counted), those of fast-forwarded passes too: a skip lists what its passes
emitted while there is room and counts the rest, so the lists and the totals
are what plain stepping would give. Macro entries and exits, which a polling
loop makes by the thousand, are folded: between two other events each (macro,
what happened) appears once with a count.
"""
from __future__ import annotations

from dataclasses import dataclass
from itertools import islice

from mercmac.vm import events as ev
from mercmac.vm import fastforward as ff

CAP = 10_000  # SPEC §5: reports and output changes beyond this are counted, not listed
TIMELINE_CAP = 100_000


@dataclass(slots=True)
class Folded:
    """A macro entered (or left the same way) `count` times from `event.t` to `last_t`."""

    event: ev.MacroEntered | ev.MacroLeft
    count: int
    last_t: int


class Recorder:
    """Collects events; pass its `on_event` to a Machine."""

    def __init__(self):
        self.reports: list[ev.Reported] = []
        self.outputs: list[ev.OutputsChanged] = []
        self.hazards: list[ev.HazardFound] = []
        self.timeline: list = []
        self.trace: list[ev.Executed] = []
        self.dropped = {"reports": 0, "outputs": 0, "timeline": 0, "trace": 0}
        self.ended_at: int | None = None
        self._folds: dict[tuple, Folded] = {}

    def on_event(self, event) -> None:
        if isinstance(event, ev.Executed):
            self._keep(self.trace, event, "trace")
            return
        if isinstance(event, (ev.MacroEntered, ev.MacroLeft)):
            self._flow(event)
            return
        if isinstance(event, ev.Reported):
            self._keep(self.reports, event, "reports")
        elif isinstance(event, ev.OutputsChanged):
            self._keep(self.outputs, event, "outputs")
        elif isinstance(event, ev.HazardFound):
            self.hazards.append(event)
        elif isinstance(event, ev.ProgramEnded):
            self.ended_at = event.t
        elif isinstance(event, ev.FastForwarded) and event.shape:
            self._skipped(event)
        self._folds.clear()
        self._keep(self.timeline, event, "timeline")

    def _skipped(self, skip: ev.FastForwarded) -> None:
        """The reports and output changes of skipped passes: listed up to the cap, counted."""
        for kind, into, what in ((ff.REPORT, self.reports, "reports"),
                                 (ff.OUTPUTS, self.outputs, "outputs")):
            total = ff.count(skip.shape, kind) * skip.passes
            if total:
                listed = len(into)
                room = max(CAP - listed, 0)
                into.extend(islice(ff.expand(skip.shape, skip.t, skip.period, skip.passes, kind),
                                   room))
                self.dropped[what] += total - (len(into) - listed)

    def _keep(self, into: list, event, what: str) -> None:
        if len(into) < (CAP if what in ("reports", "outputs") else TIMELINE_CAP):
            into.append(event)
        else:
            self.dropped[what] += 1

    def _flow(self, event: ev.MacroEntered | ev.MacroLeft) -> None:
        if isinstance(event, ev.MacroEntered):
            self.ended_at = None
        key = (type(event), event.slot, getattr(event, "why", ""))
        fold = self._folds.get(key)
        if fold is None:
            fold = self._folds[key] = Folded(event, 0, event.t)
            self._keep(self.timeline, fold, "timeline")
        fold.count += 1
        fold.last_t = event.t
