"""One flash for one controller or a chain: meet every chosen controller, then write each.

docs/uploader.md, "A flash, step by step", and docs/rigs.md, "Flashing and pulling a rig". A
program file is a chain of one controller (at `--address`, or the only one a search finds);
a rig file names each controller's address, model and program (MS176E §3.2: controllers on
one RS-232/USB link each take only what follows their address selection code, §3.1.1). Every
chosen controller is met first (reached, identified, its model checked, read back, planned,
backed up); only then is each written, verified with macro 0 last (flasher.write), and its
flash recorded in the history; with --reset, RT goes to each once all are verified. Selection
codes are sent only where the target changes (Link). A failure stops before the next
controller; for a rig the message also says what each controller holds now (Flash.states).
"""
from __future__ import annotations

import os
from contextlib import contextmanager
from dataclasses import dataclass, replace
from enum import Enum
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Callable, Iterator

from mercmac import mdtext
from mercmac.compiler import Compilation
from mercmac.upload import backup, flasher, history, protocol, survey
from mercmac.upload.connect import Identity, check_model, identify, open_controller
from mercmac.upload.controller import Controller, ControllerError
from mercmac.upload.errors import (FlashFailed, FlashInterrupted, NotChosen, ProgramUnreadable,
                                   Refused)
from mercmac.upload.flasher import FlashOptions, FlashResult, Notify
from mercmac.upload.rig import backup_paths
from mercmac.upload.transport import DEFAULT_BAUD, Timing, Transport

if TYPE_CHECKING:
    from mercmac.rig.open import Accepted
    from mercmac.rig.model import Rig


class State(str, Enum):
    """What a controller holds after a flash (or its failure); the words are the rig table's."""

    FLASHED = "flashed and verified"
    UNCHANGED = "unchanged: it holds its program"
    UNTOUCHED = "untouched"
    LEFT_OUT = "untouched (not in --only)"
    PARTLY = "partly written"
    PLANNED = "dry run"


@dataclass(slots=True)
class Part:
    """One controller of the chain in this flash: what it gets, who answered, what happened."""

    name: str | None  # its name in the rig; None: the one controller of a program file
    address: int | None  # None until found: a program file without --address (survey.reach)
    model: str | None  # the rig's model; for a program file, --target or None
    program: str  # the .mcm file
    compiled: Compilation | None = None  # None: compiled once the model answers (no `target`)
    chosen: bool = True  # False: left out by --only
    identity: Identity | None = None
    result: FlashResult | None = None
    state: State = State.UNTOUCHED
    backup_path: Path | None = None  # where its backup goes (--backup), None: the default


@dataclass(slots=True)
class Flash:
    """A finished flash (or dry run) of a program file or a rig: a Part per controller."""

    path: str  # the program or rig file
    parts: list[Part]
    rig: "Rig | None" = None  # None: a program file, shown as one controller is
    dry_run: bool = False
    reset: bool = False
    sent: int = 0  # bytes on the wire, both ways (benchmarks/flash_bytes.py)
    received: int = 0

    @property
    def named(self) -> bool:
        """A rig: its controllers have names, and a failure lists each one's state."""
        return self.rig is not None

    @property
    def chosen(self) -> list[Part]:
        return [p for p in self.parts if p.chosen]

    @property
    def changes_nothing(self) -> bool:
        return all(p.result is None or p.result.plan.changes_nothing for p in self.parts)

    def wire(self) -> list[tuple[bytes, str]]:
        """The exact bytes a flash sends after reading back, with what each is for: each
        controller's steps after its selection code, the code only where the target changes,
        then RT to each with --reset."""
        out, last = [], None
        for part in self.parts:
            if part.result is None or part.result.plan.changes_nothing:
                continue
            if part.address != last:
                out.append(self._selection(part))
            out += [(data, self._of(part, what)) for data, what in part.result.steps_wire()]
            last = part.address
        for part in self.chosen if self.reset else ():
            if part.address != last:
                out.append(self._selection(part, code=False))
            rt = f"{part.name}: reset, macro 0 starts" if self.named else "reset: macro 0 starts"
            out.append((protocol.command(mdtext.rt()), rt))
            last = None  # RT deselects (MS176E §3.1)
        return out

    def _selection(self, part: Part, *, code: bool = True) -> tuple[bytes, str]:
        if not self.named:
            return protocol.select(part.address), "address selection (0x01 + address)"
        said = f" (0x01 + address {part.address})" if code else ""
        return protocol.select(part.address), f"address selection: {part.name}{said}"

    def _of(self, part: Part, what: str) -> str:
        return f"{part.name}: {what}" if self.named else what

    def states(self) -> str:
        """'  x (address 0): flashed and verified' for each controller, with the backup."""
        lines = ["what each controller holds now:"]
        for part in self.parts:
            saved = part.result.backup if part.result else None
            kept = f"; backup of what it held: {saved}" if saved and \
                part.state is not State.UNTOUCHED else ""
            lines.append(f"  {part.name} (address {part.address}): {part.state.value}{kept}")
        return "\n".join(lines)

    def refused_at(self, part: Part, e: Refused) -> Refused:
        """A refusal while meeting PART; for a rig, which controller, and the state table."""
        if not self.named:
            return e
        return Refused(f"{part.name} (address {part.address}): {e.message}\n{self.states()}",
                       hint=e.hint)

    def interrupted_at(self, part: Part, by: BaseException) -> FlashInterrupted:
        """A signal while meeting PART, before the first write."""
        if isinstance(by, FlashInterrupted):  # during the read-back or backup (flasher.prepare)
            return by if not self.named else FlashInterrupted(
                f"{part.name}: {by.message}\n{self.states()}", by=by)
        if not self.named:
            return FlashInterrupted("interrupted before the first write; nothing was written",
                                    by=by)
        return FlashInterrupted(f"interrupted at {part.name}, before the first write; nothing "
                                f"was written\n{self.states()}", by=by)

    def stopped_at(self, part: Part, e: FlashFailed) -> FlashFailed:
        """A write (or RT) to PART failed or was interrupted: flasher's report, and for a rig
        which controller, and the state table."""
        if not self.named:
            return e
        kind = partial(FlashInterrupted, by=e) if isinstance(e, FlashInterrupted) else FlashFailed
        return kind(f"rig flash stopped at {part.name} (address {part.address}): {e.message}\n"
                    f"{self.states()}", hint=e.hint)


class Watch:
    """What a flash tells its caller, in order; each part does nothing unless overridden."""

    def refused(self, findings: list) -> None:
        """The program or the rig has errors (checking.Findings, a rig file's own first):
        shown before the refusal."""

    def compiled(self, compilation: Compilation) -> None:
        """A program as it will be flashed (no errors; it may have warnings to show)."""

    @contextmanager
    def flashing(self, flash: Flash) -> Iterator[None]:
        """Around the whole flash once the port is open: every meeting, every write, and
        `finished`."""
        yield

    @contextmanager
    def searching(self) -> Iterator[Callable[[int], None]]:
        """No --address and nothing at 0: around the search of 1-15; yields where each goes."""
        yield lambda address: None

    def identified(self, part: Part, warning: str | None) -> None:
        """The controller at the part's address answered and fits its program; `warning`:
        its model is not the program's, flashed anyway (--force), or VE names none known."""

    @contextmanager
    def meeting(self, part: Part) -> Iterator[Notify]:
        """Around one controller's read-back and backup; yields where events go."""
        yield lambda event: None

    @contextmanager
    def writing(self, part: Part) -> Iterator[Notify]:
        """Around one controller's writes and their verification; yields where events go."""
        yield lambda event: None

    @contextmanager
    def resetting(self, flash: Flash) -> Iterator[Notify]:
        """Around RT to every flashed controller (--reset); yields where events go."""
        yield lambda event: None

    def finished(self, flash: Flash) -> None:
        """Every chosen controller is flashed and verified; the port is still open (closing it
        may yet be cut short)."""


class Link:
    """The controllers of one transport, with the address selected last: a selection code
    is sent only where the target changes (MS176E §3.1.1)."""

    def __init__(self, transport: Transport):
        self.transport, self.current = transport, None

    def controller(self, address: int) -> Controller:
        return Controller(self.transport, address)

    def use(self, controller: Controller) -> Controller:
        if self.current != controller.address:
            controller.select()  # 0x01 + address: the others ignore what follows (§3.2)
        self.current = controller.address
        return controller

    def identify(self, controller: Controller) -> Identity:
        """connect.identify, which always selects: the link knows it."""
        self.current = controller.address
        return identify(controller)


def flash_chain(port: str, path: str, *, address: int | None = 0, target: str | None = None,
                force: bool = False, only: list[str] | None = None, baud: int = DEFAULT_BAUD,
                timing: Timing = Timing(), options: FlashOptions | None = None,
                watch: Watch | None = None) -> Flash:
    """Flash the program file PATH to the controller at `address` on PORT, or every
    controller of the rig file PATH (those `only` names) at its address (docs/uploader.md).

    A program file without `target` (and no `target` given) is compiled again for the model
    that answers; a model other than the program's is refused unless `force`. `address` None:
    0 if anything answers there, else the only address that answers (survey.reach).
    Refused before the first write: a program or the rig has errors, a controller does not
    answer or is not its program's model. NotChosen (exit 2): a name in `only` is not in the
    rig, or several controllers answer a search. backup.BackupError (exit 2, before the port
    opens): a backup cannot be written, at --backup or in the data folder. FlashFailed,
    FlashInterrupted: the message says what each controller holds now. PortError: the port.
    `options.backup`: for a program file the backup's path; for a rig a folder (it exists,
    or a str ending in a separator) with RIG-NAME.mcm each, else a prefix: PREFIX-NAME.mcm.
    """
    watch = watch or Watch()
    options = options or FlashOptions()
    rig, parts = _read(path, target, address, only, watch)
    flash = Flash(path, parts, rig, options.dry_run, options.reset)
    _check_backups(flash, options)
    chosen = flash.chosen
    with open_controller(port, chosen[0].address or 0, baud=baud, timing=timing) as first, \
            watch.flashing(flash):
        link = Link(first.transport)
        for part in chosen:
            _meet(link, part, flash, options, force, watch)
        if not options.dry_run:
            _write_all(link, flash, watch)
        flash.sent, flash.received = link.transport.sent, link.transport.received
        watch.finished(flash)
    return flash


def _read(path: str, target: str | None, address: int | None, only: list[str] | None,
          watch: Watch) -> tuple["Rig | None", list[Part]]:
    """The controllers to flash: the rig file's (read in one place, _accepted), or the one
    of a program file, compiled for `target` (or its own; None: the model that answers)."""
    from mercmac.rig import is_rig_path

    if is_rig_path(path):
        accepted = _accepted(path, watch)
        return accepted.rig, _rig_parts(accepted, only, watch)
    compiled = _compile(path, target, watch)
    if compiled.program.target is None:  # compiled again for the model that answers
        return None, [Part(None, address, target, path)]
    watch.compiled(compiled)
    return None, [Part(None, address, target, path, compiled)]


def _accepted(path: str, watch: Watch) -> "Accepted":
    """The rig and its programs, checked as `check RIG` checks it (rig.open: the rig rules
    and every program with its controller's model); Refused, after `watch.refused`, when that
    finds errors. InputError (exit 2) when it or a program cannot be read."""
    from mercmac.rig.open import ProgramsUnread, RigRefused, accept

    try:
        return accept(path)
    except RigRefused as e:
        watch.refused(e.findings)
        kind = ProgramUnreadable if isinstance(e, ProgramsUnread) else Refused
        raise kind(f"{e.message}; nothing was flashed", hint=e.hint) from None


def _rig_parts(accepted: "Accepted", only: list[str] | None, watch: Watch) -> list[Part]:
    """A Part per controller of the rig; those `only` names (all without it) are chosen."""
    rig = accepted.rig
    names = [c.name for c in rig.controllers]
    unknown = [n for n in only or () if n not in names]
    if unknown:
        raise NotChosen(f"--only names {', '.join(unknown)}, which {rig.path} does not have; "
                        f"nothing was flashed", hint=f"its controllers: {', '.join(names)}")
    parts = []
    for c in rig.controllers:
        chosen = not only or c.name in only
        parts.append(Part(c.name, c.address, c.model, c.program, accepted.programs[c.name],
                          chosen, state=State.UNTOUCHED if chosen else State.LEFT_OUT))
        if chosen:
            watch.compiled(parts[-1].compiled)
    return parts


def _compile(path: str, target: str | None, watch: Watch) -> Compilation:
    """PATH compiled for `target`, opened as every command opens a lone program
    (rig.open.open_program); Refused (after `watch.refused`) if it has errors."""
    from mercmac.rig.open import RigRefused, open_program

    try:
        (compilation,) = open_program(path, target=target).programs.values()
    except RigRefused as e:
        watch.refused(e.findings)
        against = f" for the {target}" if target else ""
        raise Refused(f"{path} has errors{against}; nothing was flashed") from None
    return compilation


def _check_backups(flash: Flash, options: FlashOptions) -> None:
    """Refuse, before the port opens, a backup that cannot be written: at --backup (a device,
    a FIFO, a folder) or, without it, in the data folder (the same I/O problem, exit 2)."""
    given = options.backup
    paths = backup_paths(flash.rig, given) if flash.named else \
        [None if given is None else Path(given)]
    for part, path in zip(flash.parts, paths):
        if part.chosen and path is not None:
            backup.check(path)
            part.backup_path = path
    if given is None and not options.dry_run:
        backup.check_default()


def _meet(link: Link, part: Part, flash: Flash, options: FlashOptions, force: bool,
          watch: Watch) -> None:
    """Reach, identify, check the model, read back, plan and back up PART: no write yet."""
    c = link.controller(part.address or 0)
    try:
        survey.reach(c, part.address, watch.searching)  # as pull_file finds it
        part.address = c.address
        part.identity = link.identify(c)
        if part.compiled is None:  # no `target`: checked against the model that answers
            part.compiled = _compile(part.program, part.identity.version.model, watch)
            watch.compiled(part.compiled)
        watch.identified(part, _model_warning(part, flash, force))
        with watch.meeting(part) as notify:
            part.result = flasher.prepare(c, part.identity, part.compiled.program,
                                          replace(options, backup=part.backup_path), notify)
    except Refused as e:
        raise flash.refused_at(part, e) from None
    except (FlashInterrupted, KeyboardInterrupt) as e:  # flasher.prepare's, or a signal here
        raise flash.interrupted_at(part, e) from None
    part.result.restoring = _is_backup(part.program)
    part.state = State.PLANNED if options.dry_run else State.UNTOUCHED


def _model_warning(part: Part, flash: Flash, force: bool) -> str | None:
    """Refused when the controller is not the program's model (for a program file, unless
    `force`: the warning to show then); a warning when VE names no model mercmac knows (it
    is taken to be the program's, as connect.check_model does)."""
    if not flash.named:
        return check_model(part.identity, part.compiled.program.target, part.program, force=force)
    said = part.identity.version
    if said.model == part.model:
        return None
    if said.model is None:
        return (f"VE answered {protocol.quote(said.text)}, which names no model mercmac "
                f"knows; going on as the {part.model} the rig says")
    raise Refused(f"the controller at address {part.address} is a {said.model}, but "
                  f"{os.path.basename(flash.rig.path)} says {part.name} is a "
                  f"{part.model}; nothing was written",
                  hint="check the address (DIP switches 1-4, MS176E §3.1.3) and the rig's "
                       "`model`; `mercmac scan` lists who answers where")


def _is_backup(path: str) -> bool:
    """Whether PATH was written by `mercmac pull` or a flash's backup (backup.to_mcm's header)."""
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            head = [f.readline() for _ in range(2)]
    except OSError:
        return False
    return head[0].startswith("// Mercury(TM) Macro File") and head[1].startswith("// read by mercmac")


def _write_all(link: Link, flash: Flash, watch: Watch) -> None:
    """Write each controller in turn, verified, macro 0 last; stop at the first failure.
    Each verified controller is recorded in the history at once; RT follows for all."""
    for part in flash.chosen:
        c = link.controller(part.address)
        try:
            if not part.result.plan.changes_nothing:  # nothing to say to it: no selection code
                _selected(link, c, part)
            with watch.writing(part) as notify:
                flasher.write(c, part.result, notify)
        except FlashFailed as e:
            raise flash.stopped_at(part, e) from None
        part.state = State.UNCHANGED if part.result.plan.changes_nothing else State.FLASHED
        in_rig = history.InRig(flash.path, flash.rig.name, part.name) if flash.named else None
        part.result.recorded = flasher.record(c, part.identity, part.compiled, part.result,
                                              in_rig)
    if flash.reset:
        _reset_all(link, flash, watch)


def _selected(link: Link, c: Controller, part: Part) -> None:
    """Select PART's controller before its first write; FlashFailed when the port fails
    (or a signal comes) on the way: nothing was written to it yet."""
    try:
        link.use(c)
    except ControllerError as e:
        raise FlashFailed(f"the port failed before anything was written to it: "
                          f"{flasher.failure(e)}", hint=_again()) from None
    except KeyboardInterrupt as e:
        raise FlashInterrupted("interrupted before anything was written to it", hint=_again(),
                               by=e) from None
    part.state = State.PARTLY


def _again() -> str:
    return "run the same `mercmac flash` again to finish (it writes only what differs)"


def _reset_all(link: Link, flash: Flash, watch: Watch) -> None:
    """RT to each controller once all are verified, so the macros 0 start together."""
    with watch.resetting(flash) as notify:
        for part in flash.chosen:
            c = link.controller(part.address)
            try:
                flasher.reset(c, part.result, notify, select=link.current != part.address)
            except FlashFailed as e:
                raise flash.stopped_at(part, e) from None
            link.current = None  # RT deselects (MS176E §3.1)
