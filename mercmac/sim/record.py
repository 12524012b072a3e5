"""The recorder: what a simulation run keeps of the machine's events
(docs/simulator.md, "What sim writes").

Reports and output changes are kept up to a cap (10,000 each, the rest
counted), those of fast-forwarded passes too: a skip lists what its passes
emitted while there is room and counts the rest, so the lists and the totals
are what plain stepping would give. Macro entries and exits, which a polling
loop makes by the thousand, are folded: between two other events each (macro,
what happened) appears once with a count. A macro entered only to fail its
first `XN`/`XF` and leave is a poll; entering a macro with a tail `EM` (a
`goto`) or one that loops for long is a mode change. The timeline shows the
three apart (render/sim.py: default, `-v`, `-vv`). Past its cap the timeline
is only counted, by kind of entry, so that the text can say exactly how many
lines it leaves out at each verbosity.
"""
from __future__ import annotations

import math
from collections import Counter, deque
from dataclasses import dataclass, fields
from functools import lru_cache
from operator import attrgetter
from itertools import islice
from typing import Iterator

from mercmac.ops import TextEnum
from mercmac.vm import events as ev
from mercmac.vm import shapes
from mercmac.vm.opcodes import Opcode

# Reports, output changes and events beyond this are counted, not listed
# (docs/simulator.md, "What sim writes").
CAP = 10_000
TIMELINE_CAP = 100_000  # timeline entries listed; the rest are counted (Recorder.unlisted)
# events remembered to copy a skipped pass from: a pass of more could not be listed anyway
# (two of them, stepped before the skip, filled the list), and is counted by the skip's own
# count (FastForwarded.events); more live objects would slow every collection of the GC
RECENT = CAP
_MOVE_FIELDS = attrgetter(*(f.name for f in fields(ev.MoveStarted)))
LONG_LOOP = 1000  # an RP repeating this often or more makes a macro a mode, not a step


class Fold(TextEnum):
    """What a fold of the timeline is (Folded.kind)."""

    ENTRY = "entry"  # a macro entered
    POLL = "poll"  # entered and left at its first failed condition
    LEFT = "left"  # a macro left
    # mode changes: power-on or host, tail EM (a `goto`), an entry into a long loop
    START = "start"
    GOTO = "goto"
    LOOP = "loop"


@dataclass(slots=True)
class Folded:
    """A macro entered (or left the same way) `count` times from `first_t` to `last_t`.

    A POLL's `event` is the exit, its `first_t` the first entry.
    """

    event: ev.MacroEntered | ev.MacroLeft
    count: int
    last_t: int
    kind: Fold = Fold.ENTRY
    first_t: int = 0


@dataclass(slots=True, frozen=True)
class Block:
    """A skip as the events list sees it: `passes` copies of `template` (the events of the
    stepped pass before it, inner skips as Blocks), each `period` us and `shift` counts on."""

    t: int
    period: int
    passes: int
    shift: int
    template: tuple
    size: int  # events in one pass
    steady: bool = False  # the passes leave the running profile going on (shapes.steady)


def _size(entry) -> int:
    return entry.size * entry.passes if isinstance(entry, Block) else 1


def _moved(event, dt: int, dx: int, texts, kept_dt: int, steady: bool = False):
    """An event of a stepped pass as the pass `dt` us and `dx` counts later makes it; a
    report's text comes from the skip's own reports (shapes.expand) when it shifts.
    (Built by the constructors: dataclasses.replace is four times slower, and a skip may list
    10,000 of them.)"""
    cls = type(event)
    if cls is ev.MoveStarted:
        t, kind, target, arrival, segments, where, kept, planned = _MOVE_FIELDS(event)
        if kept and steady and dx:  # the profile from its start to a target further on
            planned = planned._replace(target=target + dx)  # (Axis.retarget)
            segments = planned.segments()
            return cls(t + dt, kind, target + dx, math.ceil(segments[-1].t1), segments,
                       where, kept, planned)
        moved = kept_dt if kept else dt  # a kept profile, from before the pass, stays
        if planned is not None:
            planned = planned._replace(t=planned.t + moved, x=planned.x + dx,
                                       target=planned.target + dx)
        return cls(t + dt, kind, target + dx, arrival + moved,
                   tuple([s.moved(moved, dx) for s in segments]),
                   where, kept, planned)
    if cls is ev.MoveEnded:
        return cls(event.t + dt, event.how, event.position + dx)
    if cls is ev.HomeDefined:
        return cls(event.t + dt, event.position + dx, event.where)
    if cls is ev.Reported and texts is not None:
        shifted = next(texts, None)  # None only were pass and shape to disagree
        return cls(event.t + dt, event.text if shifted is None else shifted.text, event.where)
    return cls(event.t + dt, *_rest(cls)(event))


@lru_cache(maxsize=None)
def _rest(cls: type):
    """The fields of an event class after its time, read at once."""
    names = [f.name for f in fields(cls)][1:]
    getter = attrgetter(*names) if names else (lambda event: ())
    return (lambda event: (getter(event),)) if len(names) == 1 else getter


def unroll(template: tuple, passes: int, period: int, shift: int, dt: int, dx: int,
           texts, steady: bool = False, kept_dt: int = 0) -> Iterator:
    """The events of `passes` copies of a stepped pass, inner skips unrolled alike. A kept
    profile (MoveStarted.kept) moves on by `kept_dt` and the periods of the passes that are
    not steady: a steady pass leaves it where it is in time."""
    for k in range(1, passes + 1):
        at, by = dt + k * period, dx + k * shift
        kept_at = kept_dt if steady else kept_dt + k * period
        for entry in template:
            if isinstance(entry, Block):
                if not entry.size:  # passes that did nothing: a million of them list nothing
                    continue
                yield from unroll(entry.template, entry.passes, entry.period, entry.shift,
                                  at, by, texts, entry.steady, kept_at)
            else:
                yield _moved(entry, at, by, texts, kept_at, steady)


def modes(chunks: dict) -> tuple[set[tuple[int, int]], set[int]]:
    """The (caller, callee) pairs only ever reached by a tail EM, and the long-loop slots."""
    tail, inner, loops = set(), set(), set()
    for slot, chunk in chunks.items():
        for i, (op, arg) in enumerate(chunk.code):
            if op == Opcode.EM:
                (tail if i == len(chunk.code) - 1 else inner).add((slot, arg))
            elif op == Opcode.RP and (arg or 0) >= LONG_LOOP:
                loops.add(slot)
    return tail - inner, loops


class Recorder:
    """Collects events; its `on_event` is one of a Machine's listeners."""

    def __init__(self):
        self.reports: list[ev.Reported] = []
        self.outputs: list[ev.OutputsChanged] = []
        self.hazards: list[ev.HazardFound] = []
        self.accepted: list[ev.HazardFound] = []  # the hazards the user accepts (shown, not counted)
        self.timeline: list = []
        self.trace: list[ev.Executed] = []
        self.events: list = []  # every event but Executed, unfolded, for the JSON `events`
        # the latest events (skips as Blocks): a skip's passes copy the stepped one before it
        self._recent: deque = deque(maxlen=RECENT)
        self.dropped = {"reports": 0, "outputs": 0, "timeline": 0, "trace": 0, "events": 0}
        # past TIMELINE_CAP: folds by kind, other events (one line at every verbosity) and
        # stretches between two events with polls (one line at `-v`)
        self.unlisted: Counter[Fold] = Counter()
        self.unlisted_events = self.unlisted_polled = 0
        self.ended_at: int | None = None
        self._folds: dict[tuple, Folded] = {}
        self._gotos: set[tuple[int, int]] = set()
        self._loops: set[int] = set()
        self._current: int | None = None  # the running macro's slot, as the events tell it
        self._entered: Folded | None = None  # the entry just made, while nothing else happened
        self._polled = False  # this stretch (since the last other event) has a poll

    def know(self, chunks: dict) -> None:
        """Learn the program's gotos and long loops (the machine's assembled chunks)."""
        self._gotos, self._loops = modes(chunks)

    def on_event(self, event) -> None:
        kind = type(event)  # (every event comes here: a type is cheaper than isinstance)
        if kind is ev.Executed:
            self._keep(self.trace, event, "trace")
            return
        self._keep(self.events, event, "events")
        # a joystick moved from outside is no effect of a pass: a skip's copies never hold it
        if kind is not ev.FastForwarded and kind is not ev.JoystickMoved:
            self._recent.append(event)
        if isinstance(event, (ev.MacroEntered, ev.MacroLeft)):
            self._flow(event)
            return
        if isinstance(event, ev.Reported):
            self._keep(self.reports, event, "reports")
        elif isinstance(event, ev.OutputsChanged):
            self._keep(self.outputs, event, "outputs")
        elif isinstance(event, ev.HazardFound):
            (self.accepted if event.accepted else self.hazards).append(event)
        elif isinstance(event, ev.ProgramEnded):
            self.ended_at = event.t
        elif isinstance(event, ev.FastForwarded):
            self._skipped(event)
        self._folds.clear()
        self._entered = None
        self._polled = False
        self._log(event)

    def _skipped(self, skip: ev.FastForwarded) -> None:
        """What skipped passes emitted: listed up to the cap, counted."""
        for kind, into, what in ((shapes.REPORT, self.reports, "reports"),
                                 (shapes.OUTPUTS, self.outputs, "outputs")):
            total = shapes.count(skip.shape, kind) * skip.passes
            if total:
                listed = len(into)
                room = max(CAP - listed, 0)
                into.extend(islice(shapes.expand(skip.shape, skip.t, skip.period, skip.passes, kind,
                                                skip.position, skip.shift),
                                   room))
                self.dropped[what] += total - (len(into) - listed)
        self._skipped_events(skip)

    def _skipped_events(self, skip: ev.FastForwarded) -> None:
        """The moves, arrivals, reports and macro entries of skipped passes: copies of the
        stepped pass before the skip, listed up to the cap and counted (the JSON `events`)."""
        end = skip.t if skip.anchor_t is None else skip.anchor_t
        template = self._pass_before(end, skip.period)
        if template is not None:
            block = Block(end, skip.period, skip.passes, skip.shift, template,
                          sum(_size(entry) for entry in template), skip.steady)
        elif skip.events is not None:  # a pass of more than RECENT events: counted only
            block = Block(end, skip.period, skip.passes, skip.shift, (), sum(skip.events))
        else:  # a rig's skip of such a pass: a marker only
            return
        self._recent.append(block)
        if not block.size:
            return
        texts = None
        if skip.shift or not shapes.plain(skip.shape):  # positions in reports move on
            texts = shapes.expand(skip.shape, skip.t, skip.period, skip.passes, shapes.REPORT,
                                  skip.position, skip.shift)
        listed = len(self.events)
        self.events.extend(islice(unroll(block.template, skip.passes, skip.period,
                                         skip.shift, 0, 0, texts, block.steady),
                                  max(CAP - listed, 0)))
        self.dropped["events"] += _size(block) - (len(self.events) - listed)

    def _pass_before(self, t: int, period: int) -> tuple | None:
        """The events of the stepped pass that ends at t, as plain stepping repeats them: those
        after t - period up to t, and those at t - period past the ones the pass ends with
        (at t, before the loop's anchor)."""
        start, inside, at_start = t - period, [], []
        recent = self._recent
        i = len(recent) - 1
        while i >= 0 and recent[i].t > start:
            inside.append(recent[i])
            i -= 1
        while i >= 0 and recent[i].t == start:
            at_start.append(recent[i])
            i -= 1
        if i < 0 and len(recent) == recent.maxlen:
            return None
        ending = sum(1 for entry in inside if entry.t == t)
        at_start.reverse()
        inside.reverse()
        return tuple(at_start[ending:] + inside)

    def _keep(self, into: list, event, what: str) -> None:
        if len(into) < (CAP if what in ("reports", "outputs", "events") else TIMELINE_CAP):
            into.append(event)
        else:
            self.dropped[what] += 1

    def _log(self, entry) -> None:
        """Onto the timeline; past its cap counted by kind, since what an entry shows
        depends on the verbosity (a poll is two lines at `-vv`, none by default)."""
        kind = entry.kind if isinstance(entry, Folded) else None
        first_poll = kind is Fold.POLL and not self._polled
        self._polled = self._polled or kind is Fold.POLL
        if len(self.timeline) < TIMELINE_CAP:
            self.timeline.append(entry)
            return
        self.dropped["timeline"] += 1
        if kind is None:
            self.unlisted_events += 1
        else:
            self.unlisted[kind] += 1
        self.unlisted_polled += first_poll

    def _flow(self, event: ev.MacroEntered | ev.MacroLeft) -> None:
        entered, self._entered = self._entered, None
        if isinstance(event, ev.MacroEntered):
            self.ended_at = None
            kind = self._entry_kind(event)
            self._current = event.slot
            self._entered = self._fold((kind, event.slot, ""), event, kind, event.t)
            return
        self._current = event.back_slot
        if entered is not None and entered.kind is Fold.ENTRY and event.why.failed:
            self._unfold(entered)
            self._fold((Fold.POLL, event.slot, event.why), event, Fold.POLL, entered.last_t)
        else:
            self._fold((Fold.LEFT, event.slot, event.why), event, Fold.LEFT, event.t)

    def _entry_kind(self, event: ev.MacroEntered) -> Fold:
        if event.via is not ev.Via.EM:
            return Fold.START
        if (self._current, event.slot) in self._gotos:
            return Fold.GOTO
        return Fold.LOOP if event.slot in self._loops else Fold.ENTRY

    def _fold(self, key: tuple, event, kind: Fold, first_t: int) -> Folded:
        fold = self._folds.get(key)
        if fold is None:
            fold = self._folds[key] = Folded(event, 0, event.t, kind, first_t)
            self._log(fold)
        fold.count += 1
        fold.last_t = event.t
        return fold

    def _unfold(self, fold: Folded) -> None:
        """Take back the last count of an entry that turned out to be a poll."""
        fold.count -= 1
        if fold.count:
            return
        del self._folds[(fold.kind, fold.event.slot, "")]
        if self.timeline and self.timeline[-1] is fold:
            self.timeline.pop()
        else:  # past the cap: it was counted, not listed
            self.dropped["timeline"] -= 1
            self.unlisted[Fold.ENTRY] -= 1
