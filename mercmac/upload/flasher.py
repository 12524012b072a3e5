"""Flashing one controller: back up, write what differs in the safe order, verify, report.

The steps of docs/uploader.md, "A flash, step by step", for a controller already identified
(connect.identify); chain.py runs them for a program file or every controller of a rig.
Everything the controller holds is saved before the first write; each write is read back,
written once more on a mismatch, and a failure stops the flash with a message that says what
was written, what was not, and where the backup is.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum
from pathlib import Path
from typing import Callable

from mercmac.compiler import Compilation
from mercmac.compiler.program import Program
from mercmac import mdtext
from mercmac.errors import how, signal_of
from mercmac.upload import backup, protocol
from mercmac.upload.controller import Controller, ControllerError, LinkLost
from mercmac.upload.errors import FlashFailed, FlashInterrupted, Refused
from mercmac.upload.plan import Action, Plan, Step, make_plan
from mercmac.upload.connect import Identity, refusal

CLEANUP_TIMEOUT = 0.5  # s: after Ctrl-C, how long one tidy-up read may take


class EventKind(str, Enum):
    """What an Event tells; its words are render.upload's."""

    BACKUP = "backup"  # the controller's macros saved before the first write
    STEP = "step"  # a step of the plan begins
    VERIFIED = "verified"  # that step read back right
    RETRY = "retry"  # it read back wrong and is written once more
    REPAIR = "repair"  # a garbled line changed another slot, which is restored
    RESET = "reset"  # RT sent: macro 0 starts


@dataclass(frozen=True, slots=True)
class Event:
    """Something to show while flashing; `done`/`total` drive a progress bar."""

    kind: EventKind
    text: str  # backup: the backup's path
    done: int = 0  # backup: how many macros it holds
    total: int = 0
    sent: int = 0  # bytes of the plan's steps sent so far (commands and read-backs)
    size: int = 0  # bytes of all the plan's steps: with `sent`, a rate and the time left


Notify = Callable[[Event], None]


@dataclass(slots=True)
class FlashOptions:
    """What the user asked for on the command line."""

    erase_unused: bool = False
    dry_run: bool = False
    reset: bool = False
    # --backup: one controller's file; for a rig a folder or a prefix (rig.backup_paths), kept
    # as given, since a str's ending separator names a folder
    backup: Path | str | None = None


@dataclass(slots=True)
class FlashResult:
    """A finished flash (or dry run): the plan, the backup, and what needed a second try."""

    identity: Identity
    plan: Plan
    backup: Path | None
    dry_run: bool = False
    reset: bool = False
    retried: list[int] = field(default_factory=list)
    repaired: list[int] = field(default_factory=list)
    recorded: Path | None = None  # the history record of this flash (mercmac.upload.history)
    unrecorded: str = ""  # why that record could not be written ('' when it was)

    restoring: bool = False  # the file is a backup (pull or flash wrote it)

    @property
    def left_over(self) -> list[int]:
        """Slots the controller holds that the file does not define, kept (no --erase-unused)."""
        from mercmac.upload.plan import Fate

        return [s for s, fate in sorted(self.plan.fates.items()) if fate is Fate.KEPT]

    def wire(self, address: int | None = None) -> list[tuple[bytes, str]]:
        """The exact bytes a flash sends after reading back, with what each is for."""
        address = self.identity.address if address is None else address
        out = [(protocol.select(address), "address selection (0x01 + address)")]
        out += self.steps_wire()
        if self.reset:
            out.append((protocol.command(mdtext.rt()), "reset: macro 0 starts"))
        return out

    def steps_wire(self) -> list[tuple[bytes, str]]:
        """The plan's steps on the wire: each command and its read-back, with what it is for."""
        out = []
        for step in self.plan.steps:
            out.append((protocol.command(step.wire), step.describe))
            out.append((protocol.command(step.readback), f"read back {step.name}"))
        return out


def record(controller: Controller, identity: Identity, compiled: Compilation,
           result: FlashResult, rig=None) -> Path | None:
    """Note the verified flash in the history (mercmac.upload.history); None if it cannot be.
    `rig`: a history.InRig when the controller was flashed as part of a rig."""
    from mercmac import outfile
    from mercmac.upload import history

    try:
        return history.record(port=controller.transport.port, address=controller.address,
                              model=identity.version.model, firmware=identity.version.firmware,
                              file=compiled.source.name, source=compiled.source.text,
                              build=compiled.program.md_lines(),
                              backup_path=result.backup, rig=rig)
    except (OSError, outfile.OutputError) as e:
        # the flash is done and verified; a history that cannot be written is no failure,
        # but `pull` will not give this source back: the summary says so
        result.unrecorded = (e.message if isinstance(e, outfile.OutputError)
                             else f"{history.folder()}: {outfile.reason(e)}")
        return None


def flash(controller: Controller, identity: Identity, program: Program,
          options: FlashOptions, notify: Notify = lambda e: None) -> FlashResult:
    """Read back, back up, write and verify (and RT with `options.reset`); FlashFailed names
    the state on any failure."""
    result = prepare(controller, identity, program, options, notify)
    if not options.dry_run:
        write(controller, result, notify)
        if result.reset:
            reset(controller, result, notify)
    return result


def prepare(controller: Controller, identity: Identity, program: Program,
            options: FlashOptions, notify: Notify = lambda e: None) -> FlashResult:
    """Read back, plan and (unless a dry run) back up: nothing is written yet. A chain backs
    up every controller this way before it writes to any (chain.py)."""
    result = None
    try:
        stored = controller.read_all()  # TM, TZ: all of it, before any write
        plan = make_plan(program, stored, erase_unused=options.erase_unused)
        result = FlashResult(identity, plan, None, options.dry_run, options.reset)
        if options.dry_run:
            return result
        result.backup = _save_backup(controller, identity, stored, options.backup)
        # words are render.upload's: the count of macros backed up, and where
        notify(Event(EventKind.BACKUP, str(result.backup), len(stored)))
    except ControllerError as e:
        raise refusal(controller, e) from None
    except KeyboardInterrupt as e:
        saved = f"; backup: {result.backup}" if result and result.backup else ""
        raise FlashInterrupted(f"interrupted before the first write; nothing was written{saved}",
                               by=e) from None
    return result


def write(controller: Controller, result: FlashResult, notify: Notify = lambda e: None) -> None:
    """Carry out a prepared plan: write, verify, macro 0 last."""
    _Run(controller, result.plan, notify, result).execute()


def reset(controller: Controller, result: FlashResult, notify: Notify = lambda e: None, *,
          select: bool = False) -> None:
    """RT once the plan is written and verified, so macro 0 starts as after power-on; the
    controller is then deselected (MS176E §6.4 RT, §3.1). `select`: send its selection code
    first (another controller of the chain was addressed since)."""
    try:
        if select:
            controller.select()  # 0x01 + address: the others ignore the RT (§3.2)
        controller.reset()
    except ControllerError as e:
        raise FlashFailed(f"all macros are written and verified, but RT failed: {failure(e)}",
                          hint="power-cycle the controller to start macro 0") from None
    except KeyboardInterrupt as e:
        raise FlashInterrupted(f"all macros are written and verified (backup: "
                               f"{result.backup}); interrupted while sending RT, so "
                               f"macro 0 may not have started",
                               hint="power-cycle the controller to start macro 0",
                               by=e) from None
    notify(Event(EventKind.RESET, "RT sent: the controller restarts and runs macro 0"))


def _save_backup(controller: Controller, identity: Identity, stored: dict[int, str],
                 path: Path | None) -> Path:
    t = controller.transport
    text = backup.to_mcm(stored, identity.version, port=t.port, address=controller.address)
    try:
        return backup.save(text, path or backup.default_path(t.port, controller.address))
    except backup.BackupError as e:
        raise Refused(f"{e}; nothing was written to the controller",
                      hint="give a writable file with --backup PATH") from None


class _Run:
    """The steps of one plan against one controller, with what we believe it now holds."""

    def __init__(self, controller: Controller, plan: Plan, notify: Notify, result: FlashResult):
        self.c, self.plan, self.notify, self.result = controller, plan, notify, result
        self.believed = dict(plan.before)
        self.done: list[Step] = []
        self.current: Step | None = None
        self.verify_failed = False

    def execute(self) -> None:
        total = len(self.plan.steps)
        sizes = [len(protocol.command(s.wire)) + len(protocol.command(s.readback))
                 for s in self.plan.steps]
        size, sent = sum(sizes), 0
        try:
            for i, step in enumerate(self.plan.steps):
                self.current = step
                self.notify(Event(EventKind.STEP, step.describe, i, total, sent, size))
                self._apply(step)
                self.done.append(step)
                self.current = None
                sent += sizes[i]
                self.notify(Event(EventKind.VERIFIED, f"{step.describe}: verified", i + 1, total,
                                  sent, size))
        except KeyboardInterrupt as e:  # Ctrl-C, SIGTERM or SIGHUP (mercmac.errors.Signalled)
            cause, alive, by = None, True, e
        except _Mismatch as e:
            self.verify_failed = True
            cause, alive, by = e.args[0], True, None
        except ControllerError as e:
            cause, alive, by = failure(e), not isinstance(e, LinkLost), None
        else:
            return
        # Inline, with no call before the `try`: a second signal, pending since the first,
        # fires at the first call and must land inside it. It skips the tidy-up, never the report.
        while True:
            try:
                stopped = self._stopped(cause, alive, by)
                break
            except KeyboardInterrupt:
                alive = False  # no more talking to the controller: just say where things stand
        raise stopped from None

    def _stopped(self, cause: str | None, alive: bool, by: KeyboardInterrupt | None) -> FlashFailed:
        """The error that ends the flash, with the report; FlashInterrupted when a signal BY
        stopped it (its words, and its exit code 128+N)."""
        if by is None:
            return FlashFailed(self._report(cause, alive=alive), hint=self._hint())
        cause = f"interrupted ({how(signal_of(by))})"
        return FlashInterrupted(self._report(cause, alive=alive), hint=self._hint(), by=by)

    def _apply(self, step: Step) -> None:
        """Send, read back; on a mismatch repair what a lost character hit and send once more."""
        self._send(step)
        got = self.c.read_slot(step.slot)
        if not protocol.same_macro(got, step.expected):
            self.notify(Event(EventKind.RETRY, f"{step.name} read back wrong "
                              f"({protocol.difference(step.expected, got)}); writing it again"))
            self.result.retried.append(step.slot)
            self._reconcile(step.slot)
            self._send(step)
            got = self.c.read_slot(step.slot)
            if not protocol.same_macro(got, step.expected):
                raise _Mismatch(f"{step.name} does not verify after a second write: "
                                f"{protocol.difference(step.expected, got)}")
        self.believed[step.slot] = step.expected
        if step.expected is None:
            self.believed.pop(step.slot, None)

    def _reconcile(self, skip: int) -> None:
        """Re-read every slot: a lost digit sends `MD15` to slot 1, a lost one `RM5` erases all."""
        actual = self.c.read_all()
        for slot in sorted(actual.keys() | self.believed.keys()):
            want = self.believed.get(slot)
            if slot == skip or protocol.same_macro(actual.get(slot), want):
                continue
            fix = Step(Action.WRITE if want else Action.ERASE, slot,
                       self.plan.names.get(slot, mdtext.slot_name(slot)), want)
            self.notify(Event(EventKind.REPAIR,
                              f"{fix.name} was changed by a garbled line; restoring it"))
            self._send(fix)
            got = self.c.read_slot(slot)
            if not protocol.same_macro(got, want):
                raise _Mismatch(f"{fix.name} was hit by a garbled line and does not verify "
                                f"after repair: {protocol.difference(want, got)}")
            self.result.repaired.append(slot)

    def _send(self, step: Step) -> None:
        if step.action is Action.WRITE:
            self.c.define(step.slot, step.line)
        else:
            self.c.remove(step.slot)

    def _report(self, cause: str, *, alive: bool) -> str:
        """What was written, what was not, the state of macro 0 and where the backup is."""
        zero = self._settle_autostart(alive)
        current = self.current
        pending = self.plan.steps[len(self.done) + (current is not None):]
        lines = [f"flash stopped: {cause}",
                 "  written and verified: " + (_names(self.done) or "nothing")]
        if current and self.verify_failed:
            lines.append(f"  failed verification: {_names([current])}")
        elif current:
            lines.append(f"  in progress, state unknown: {_names([current])}")
        lines += ["  not written: " + (_names(pending) or "nothing"),
                  "  macro 0: " + zero,
                  f"  backup of the controller as it was: {self.result.backup}"]
        return "\n".join(lines)

    def _settle_autostart(self, alive: bool) -> str:
        """Macro 0's state for the report; a half-written macro 0 is removed if the link lives."""
        current = self.current
        if current and current.slot == 0 and current.action is Action.WRITE:
            if alive and self._unarm(current):
                return "its write did not complete, so it was removed: the controller will not autostart"
            if current in self.done:
                return "written last and verified"
            return ("its write was in progress and it may be incomplete: check with "
                    "`mercmac pull` and remove it (RZ) before the next power-on")
        if current and current.action is Action.PARK:
            return ("was being removed: either gone, or still the old autostart with "
                    "nothing it calls touched yet")
        if any(s.slot == 0 and s.action is Action.WRITE for s in self.done):
            return "written last and verified"
        if any(s.action is Action.PARK for s in self.done):
            return ("removed before the first write and not written back: the controller "
                    "will not autostart a half-written program")
        if 0 in self.believed:
            return "unchanged"
        if 0 in self.plan.after:
            return "not written yet: the controller will not autostart a half-written program"
        return "none: the controller will not autostart"

    def _unarm(self, step: Step) -> bool:
        """After a failed write of macro 0: keep it if it verifies, else RZ; False if unsure."""
        try:
            self.c.transport.timing = _short(self.c.transport.timing)
            if protocol.same_macro(self.c.read_slot(0), step.expected):
                self.done.append(step)
                self.current = None
                return False
            self.c.remove(0)  # RZ: no autostart beats a garbled one (MS176E §3.8.5)
            return self.c.read_slot(0) is None
        except (ControllerError, KeyboardInterrupt):
            return False

    def _hint(self) -> str:
        t = self.c.transport
        at = f" --address {self.c.address}" if self.c.address else ""  # a chain's other controller
        return (f"run the same `mercmac flash` again to finish (it writes only what differs); "
                f"`mercmac flash {t.port} {self.result.backup}{at} --erase-unused` puts the old "
                f"program back")


class _Mismatch(Exception):
    """A write that does not read back right, even after the second try."""


def _names(steps: list[Step]) -> str:
    """'MC00 (autostart removed), MC05, MC09 (erased)'."""
    tags = {Action.WRITE: "", Action.PARK: " (autostart removed)", Action.ERASE: " (erased)"}
    return ", ".join(f"{s.name}{tags[s.action]}" for s in steps)


def failure(e: ControllerError) -> str:
    """A controller error as the reports say it: a lost port is named as such."""
    if isinstance(e, LinkLost):
        return f"the port went away ({e})"
    return str(e)


def _short(timing):
    from dataclasses import replace

    return replace(timing, timeout=min(timing.timeout, CLEANUP_TIMEOUT))
