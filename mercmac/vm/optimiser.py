"""The fast-forward optimiser of one machine: its loops' last visits, its effect log and the
horizon of its run (the rules of when passes repeat are in vm/skips.py).

The machine runs every instruction itself and tells its optimiser what matters through a
few named hooks: a macro was entered, a loop came round or ran out, a wait began, an
input changed, an event was emitted, and what a shifted pass must know (a move asked
for, a profile started, a report that shows the position, a trigger). At a loop anchor
the optimiser compares this pass with the last one and, when the next passes are copies,
has the machine jump over them (`Machine._jump`), exactly.
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING, NamedTuple

from mercmac.commands import COMMANDS, Mnemonic
from mercmac.ops import TextEnum
from mercmac.vm import events as ev
from mercmac.vm import shapes, skips
from mercmac.vm.shapes import Note
from mercmac.vm.skips import Anchor, Loop, Visit

if TYPE_CHECKING:
    from mercmac.vm.machine import Machine

INF = math.inf
STEADY = "steady"  # a key's mark: the axis runs the profile it ran at the visit before
BUSY_PASSES = 1000  # a loop without waits this long (or endless) is a busy loop hazard
LOG_LIMIT = 100_000  # effects kept for comparing passes; a longer pass is not skipped


# reports that depend on the position or the motion: TP, TD, TT shift with it; TE and TV
# do not at rest; TS shows the limit and reference switches; while moving, all but TT take
# a fractional position (Optimiser.reported)
POSITIONAL = {Mnemonic.TP, Mnemonic.TD, Mnemonic.TT, Mnemonic.TE, Mnemonic.TV, Mnemonic.TS}


class FastForward(TextEnum):
    """Which repeating passes a machine skips."""

    OFF = "off"  # none: every pass is stepped (for comparisons)
    QUIET = "quiet"  # passes that emit nothing
    # any: a listener counts what the skipped passes emitted from FastForwarded.shape (the
    # Recorder does; on_report gets each report)
    ALL = "all"


class Jump(NamedTuple):
    """Passes the machine skips at once: `passes` copies of the pass that ended at an
    anchor, `period` us each, each one `shift` counts further on than the last."""

    anchor: Anchor
    own: int | None  # the jumping RP's place, whose counter counts the passes
    passes: int
    period: int
    shape: tuple  # what each pass emitted (shapes.shape or moved_shape)
    position: int  # where the first pass starts (a shifted jump)
    shift: int
    counted: tuple[int, int]  # events of each pass: (others, macro entries and exits)
    steady: bool = False  # the passes leave the running profile as it is (_key)


class Anchors:
    """The last visit of every loop anchor."""

    def __init__(self):
        self.visits: dict[Anchor, Visit] = {}

    def forget_slot(self, slot: int) -> None:
        """A macro was entered: its RP counters restart, so its loop visits are void."""
        for anchor in [a for a in self.visits if a.loop is Loop.RP and a.slot == slot]:
            del self.visits[anchor]


class Optimiser:
    """Fast-forward for one machine (the machine calls the hooks; it reads the machine)."""

    def __init__(self, machine: Machine, mode: FastForward):
        self.machine = machine
        self.mode = mode
        # what it must know of a pass: what it emitted, or only whether it emitted anything
        self.shape = shapes.shape if mode is FastForward.ALL else shapes.silent
        self.anchors = Anchors()
        self.log: list = []  # effects since log_base: what passes emitted (shapes.shape)
        self.log_base = 0
        self.horizon = INF  # the end of the run: it bounds a jump (skippable)
        self.waits = 0  # wait commands executed (a loop without any is a busy loop)
        self.inputs = 0  # input changes (a pass that sees one does not repeat)
        self.flows = 0  # macro entries and exits, of skipped passes too (Jump.counted)
        self.arrivals = 0  # loops come round (macro entries, RP jumps): a rig's anchors

    # ------------------------------------------------------------ hooks: the machine says
    def running_to(self, until: int) -> None:
        self.horizon = until

    def code_changed(self) -> None:
        """Macros were loaded, stored or erased, or the machine powered on: no visit holds."""
        self.anchors.visits.clear()

    def macro_entered(self, slot: int) -> None:
        """Its entry is a loop anchor (a macro may call itself, or goto round a ring)."""
        self.anchors.forget_slot(slot)
        self._arrive(Anchor(Loop.EM, slot), None, INF)

    def loop_jumped(self, slot: int, ip: int, remaining: float) -> None:
        """The RP at `ip` jumped back, with `remaining` passes left after this one."""
        self._arrive(Anchor(Loop.RP, slot, ip), ip, remaining)

    def loop_ended(self, slot: int, ip: int) -> None:
        self.anchors.visits.pop(Anchor(Loop.RP, slot, ip), None)

    def wait_begun(self) -> None:
        self.waits += 1

    def input_changed(self) -> None:
        self.inputs += 1

    def emitted(self, event: object) -> None:
        """An event the listeners heard: a pass's effects are all but its control flow (which
        repeats with it), and the inner skips that emitted something."""
        kind = type(event)
        if kind is ev.FastForwarded:
            if event.shape:
                self.log.append(event)
        elif kind is ev.MacroEntered or kind is ev.MacroLeft:
            self.flows += 1
        elif kind is not ev.Executed:
            self.log.append(event)

    def move_requested(self, target: int) -> None:
        """A move asked for `target`, clamped to the soft range it was asked in."""
        self.log.append(shapes.Requested(target, *self.machine.axis.soft_range()))

    def profile_note(self) -> Note | None:
        """What a profile started now computes with: from rest on a count, whole counts that
        shift exactly in any pass (None); from a moving or a fractional state, floats, the
        same only within one power of two (Note.FLOATS); from a profile it cannot key (DH
        moved it, AB1, a stall), nothing a pass repeats (Note.UNSHIFTABLE)."""
        axis = self.machine.axis
        if axis.at_rest_on_count():
            return None
        if axis.stalled or (axis.segs and axis.plan is None):
            return Note.UNSHIFTABLE
        return Note.FLOATS

    def profile_started(self, note: Note | None) -> None:
        """A profile started (not the running one kept): its profile_note, taken before."""
        if note is not None:
            self.log.append(note)

    def reported(self, mnemonic: str) -> None:
        """Note how the report just made depends on the position (shapes.moved_shape):
        TT shows the target; at rest on a count TP and TD show it, TS the switches; while
        moving, TP, TD and TE round a float position, TV shows a velocity and TS the
        switches and the motion, all the same a pass later within one power of two."""
        if mnemonic not in POSITIONAL:
            return
        axis = self.machine.axis
        if mnemonic == Mnemonic.TT:
            self.log.append(shapes.Shows(COMMANDS[mnemonic].report, axis.target))
            return
        if not axis.at_rest_on_count():
            now = self.machine.clock.now
            x = axis.position(now)
            if axis.stalled or (axis.segs and axis.plan is None) or x - math.floor(x) == 0.5:
                # round() takes a half to the even count: a pass an odd count on differs
                self.log.append(Note.UNSHIFTABLE)
                return
            if mnemonic in (Mnemonic.TP, Mnemonic.TD):  # (a Shows follows its report)
                self.log.append(shapes.Shows(COMMANDS[mnemonic].report, round(x)))
            elif mnemonic == Mnemonic.TS:
                self.log.append(Note.SWITCHES)
            self.log.append(Note.FLOATS)
        elif mnemonic == Mnemonic.TS:
            self.log.append(Note.SWITCHES)
        elif mnemonic in (Mnemonic.TP, Mnemonic.TD):
            self.log.append(shapes.Shows(COMMANDS[mnemonic].report, int(axis.final)))

    def trigger_set(self) -> None:
        """ZM, ZP or ZI in a pass: it arms the trigger at ZP, a position that does not move
        on with the pass (Trigger.relative keys a trigger armed before the loop)."""
        if self.machine.trigger.mode:
            self.log.append(Note.UNSHIFTABLE)

    def pulsed(self) -> None:
        """A trigger pulse: its time comes from where the profile reaches a position."""
        self.log.append(Note.FLOATS)

    # ------------------------------------------------------------ for a rig's joint skip
    def logged(self) -> int:
        """Effects logged so far: a mark in the effect log (Visit.logged, effects)."""
        return self.log_base + len(self.log)

    def effects(self, start: int, end: int) -> list | None:
        """The effects logged between two marks (logged()); None once the log was cut past
        `start` (LOG_LIMIT): the pass is not known whole."""
        if start < self.log_base:
            return None
        return self.log[start - self.log_base:end - self.log_base]

    def joint_key(self, t: int) -> tuple | None:
        """The machine's part of a rig's joint key at the instant t (sim/rig_skip.py): its shift
        key (_shift_key) over the state a rig compares (Machine._joint_state), its input lines
        (the wires' levels) and its next command relative to t. None when a trigger pulse is
        on or a JT table is being made (each ends at a time of its own), or _shift_key has
        none (the axis rests off a whole count, or moves on a profile it cannot key); see
        (docs/simulator.md, "Fast-forward")."""
        m = self.machine
        if m.table_done != INF or m.outputs.pulse_until > t:
            return None
        if m.chunk is None:
            return self._halted_key(t)
        key, _ = self._shift_key(self._key(None, at=t, state=m._joint_state(t)))
        if key is None:
            return None
        return key, tuple(m.inputs.state), m.wake - t if m.block is None else None

    def _halted_key(self, t: int) -> tuple | None:
        """A machine that runs nothing: only its axis and outputs go on (a joystick)."""
        m, axis = self.machine, self.machine.axis
        motion = ()
        if axis.segs or axis.stalled:
            relative = axis.relative(t)
            if relative is None:
                return None
            motion = relative, axis.final - axis.target
        elif axis.final != axis.target:
            return None
        return ("halted", axis.unshifted(axis.state_key()), motion,
                m.trigger.relative(axis.target), m.outputs.state_key(), m.deflection,
                tuple(m.inputs.state))

    # ------------------------------------------------------------ at a loop anchor
    def _arrive(self, anchor: Anchor, own: int | None, remaining: float) -> None:
        """A loop came round: report a busy loop, skip identical passes (vm/skips.py)."""
        self.arrivals += 1
        previous = self.anchors.visits.get(anchor)
        fresh = self._fresh(previous)
        key = self._key(own, previous, fresh)
        if previous is not None and self.waits == previous.waits and remaining >= BUSY_PASSES:
            self._busy_loop(anchor, key, previous)
        visit = self._visit(key, previous, fresh)
        self.anchors.visits[anchor] = visit
        if previous is None or self.mode is FastForward.OFF:
            return
        if not skips.same_pass(previous, visit):
            if self.mode is FastForward.ALL and skips.same_shifted_pass(previous, visit):
                self._skip_shifted(anchor, own, previous, visit, remaining)
            return
        if visit.shape and self.mode is not FastForward.ALL:
            return
        steady = _steady(key)
        if steady and visit.delta != previous.delta:
            return  # each of the two passes moved the target on by as much, or neither
        period = visit.wake - previous.wake
        passes = skips.skippable(previous, visit, self._bound(), remaining)
        if steady:
            passes = self._steady_passes(visit, period, passes)
        if passes > 0:
            self._jump(Jump(anchor, own, passes, period, visit.shape, visit.position,
                            visit.delta if steady else 0, self._counted(previous, visit),
                            steady), visit)

    def _steady_passes(self, visit: Visit, period: int, fit: int) -> int:
        """How many of `fit` passes that leave the running profile going on may be skipped
        (skips.steady_passes). A profile moved on in floats (Axis.translate) is no longer
        the one its plan plans: passes that plan from its start are not skipped then."""
        axis = self.machine.axis
        plan = axis.plan if axis.segs == axis.plan.segments() else None
        return skips.steady_passes(visit, period, fit, plan, axis.switches())

    def _skip_shifted(self, anchor: Anchor, own: int | None, previous: Visit, visit: Visit,
                      remaining: float) -> None:
        """Skip passes that repeat `visit.delta` further on, up to the next boundary."""
        period = visit.wake - previous.wake
        # the running profile's arrival is the pass's own (its shape has it; its limit hit is a
        # boundary, shifted_passes): only other hardware events bound the skip
        fit = skips.skippable(previous, visit, self._bound(axis=False), remaining)
        passes = self.shifted_passes(visit, period, fit)
        if passes < fit:  # a boundary, not the counter, ends it: enclosing passes differ
            self.log.append(Note.UNSHIFTABLE)
        if passes > 0:
            self._jump(Jump(anchor, own, passes, period, visit.moved, visit.position,
                            visit.delta, self._counted(previous, visit)), visit)

    def shifted_passes(self, now: skips.Pass | Visit, period: int, fit: int) -> int:
        """How many of `fit` passes, each `period` us and `now.delta` counts on from the one
        that ended at `now`, stay clear of this machine's boundaries (skips.shifted_passes)."""
        return skips.shifted_passes(now, period, fit, *self.boundaries())

    def boundaries(self) -> tuple:
        """What bounds a shifted skip here (skips.shifted_passes): the soft range, the
        limit switches, the reference edge in present coordinates, a grid trigger's ZI."""
        axis, trigger = self.machine.axis, self.machine.trigger
        grid = abs(trigger.increment) if trigger.mode == 3 else 0
        return (axis.soft_range(), axis.switches(), axis.options.reference_at + axis.shift,
                grid)

    def _jump(self, jump: Jump, visit: Visit) -> None:
        """Have the machine jump, then arrive again: the jump's own event belongs to enclosing
        loops, not to the next pass."""
        self.machine._jump(jump)
        self.flows += jump.passes * jump.counted[1]
        now = self.machine.clock.now + jump.passes * jump.period  # where the last pass ends
        key = self._key(jump.own, at=now)  # (moved on: as fresh as the pass it copies)
        skey, position = self._shift_key(key)
        self.anchors.visits[jump.anchor] = Visit(key, self.machine.wake, self.inputs, self.waits,
                                         self.logged(), visit.shape,
                                         skey, position, visit.delta, visit.moved, now,
                                         True, self.flows)

    def _counted(self, previous: Visit, visit: Visit) -> tuple[int, int]:
        """The events of the pass from `previous` to `visit`, as the recorder lists them:
        those besides macro entries and exits (its effects, and those of the skips inside
        it; not their markers), and its entries and exits (skipped ones too)."""
        effects = 0
        for e in self.log[previous.logged - self.log_base:visit.logged - self.log_base]:
            if type(e) is ev.FastForwarded:
                effects += e.passes * e.events[0] if e.events else 0
            elif not isinstance(e, shapes.NOTES):
                effects += 1
        return effects, visit.flows - previous.flows

    def _bound(self, axis: bool = True) -> float:
        """What a jump must stop before: the end of the run or the next hardware event (but
        the axis's own, without `axis`)."""
        return min(self.horizon, self.machine._next_hardware(axis))

    def _busy_loop(self, anchor: Anchor, key: tuple | None, previous: Visit) -> None:
        """A long pass without a wait came round: a busy loop, if it is a loop. Reported
        once; it ends the pass, so that pass is not skipped (a loop is skipped after two
        passes without a new hazard, as plain stepping would report none in the passes
        skipped)."""
        if anchor.loop is Loop.RP or (key is not None and key == previous.key):
            self.machine._busy_loop(anchor)

    def _visit(self, key: tuple | None, previous: Visit | None, fresh: bool) -> Visit:
        """This arrival at an anchor, with what the pass since `previous` emitted."""
        if len(self.log) > LOG_LIMIT:  # passes this long are not compared
            self.log_base += len(self.log)
            self.log.clear()
        pass_shape = moved = delta = None
        whole = (previous is not None and previous.logged >= self.log_base
                 and self.mode is not FastForward.OFF)  # which compares no passes
        steady, target = _steady(key), self.machine.axis.target
        if whole and key is not None and key == previous.key:
            effects = self.log[previous.logged - self.log_base:]
            if steady and self.mode is FastForward.ALL:
                pass_shape = shapes.steady(effects, previous.wake, previous.position)
            else:
                pass_shape = self.shape(effects, previous.wake)
            if steady:  # its target moved on by delta, the stage along the profile
                delta = target - previous.position
        skey, position = (None, target) if steady else self._shift_key(key)
        if (whole and pass_shape is None and skey is not None and skey == previous.skey
                and self.mode is FastForward.ALL):
            delta = position - previous.position
            moved = shapes.moved_shape(self.log[previous.logged - self.log_base:],
                                       previous.wake, previous.position)
        return Visit(key, self.machine.wake, self.inputs, self.waits,
                     self.logged(), pass_shape, skey, position, delta, moved,
                     self.machine.clock.now, fresh, self.flows)

    def _fresh(self, previous: Visit | None) -> bool:
        """Whether the axis runs a profile planned since the `previous` visit of the anchor."""
        plan = self.machine.axis.plan
        return plan is not None and (previous is None or plan.t > previous.t)

    def _key(self, own: int | None, previous: Visit | None = None, fresh: bool = True,
             at: int | None = None, state: tuple | None = None) -> tuple | None:
        """The machine's state key (Machine.STATE_KEY; `state`, a rig's, if given) at `at`
        (now); while the axis moves, with its profile relative to that time and the target
        (Axis.relative), or None if it has none. Only a pass that planned its profile anew,
        after one that did too, can repeat one shifted: a profile that ran at the previous
        visit is not at the same phase now. A pass that left the profile as it was (it
        planned none, or kept the running one: Axis.keeps) is keyed STEADY, with the
        profile as it stands: two such passes in a row repeat while the profile runs on,
        if nothing in them shows where the stage is on it (shapes.shape, `steady`), up to
        its next event (its arrival, a limit switch, a trigger pulse: _bound)."""
        m, axis = self.machine, self.machine.axis
        if axis.segs or axis.stalled:
            if previous is not None and not (previous.fresh and fresh):
                if fresh or axis.plan is None or axis.stalled:
                    return None
                p = axis.plan  # its start: the profile to any target is planned from it
                return (STEADY, m.unshifted(m._state_key(own) if state is None else state),
                        (p.t, p.x, p.v, p.speed, p.acc), axis.final - axis.target,
                        m.trigger.next_at)
            relative = axis.relative(m.clock.now if at is None else at)
            if relative is None:
                return None
            return (m.unshifted(m._state_key(own) if state is None else state), relative,
                    axis.target, axis.final, m.trigger.next_at)
        return m._state_key(own) if state is None else state

    def _shift_key(self, key: tuple | None) -> tuple[tuple | None, int]:
        """The state key without the axis's position and target, and the target; (None, 0)
        unless the axis rests on its target, a whole count, or moves on a profile it keys;
        with the trigger relative to the target (Trigger.relative)."""
        m = self.machine
        if key is None or _steady(key):  # a steady pass repeats unshifted only
            return None, 0
        axis = m.axis
        trigger = m.trigger.relative(axis.target) if m.trigger.mode else ()
        if axis.segs:  # key: (unshifted, relative, target, final, next_at), from _key
            return (key[0], key[1], axis.final - axis.target, trigger), axis.target
        if axis.final != axis.target:
            return None, 0
        return (m.unshifted(key), trigger), axis.target


def _steady(key: tuple | None) -> bool:
    """Whether a state key is a steady pass's (Optimiser._key)."""
    return key is not None and key[0] == STEADY
