"""A rig over one port: flash every controller of a daisy chain at its address; pull a chain.

docs/rigs.md, MS176E §3.2: up to 16 controllers share one RS-232/USB link and each takes only
what follows its address selection code (`\\x01` + one hex digit, §3.1.1, §3.1.3). A rig
flash first meets every chosen controller (identify, model as the rig says, read back,
plan, back up), and only then writes: controller after controller, each verified with macro
0 last (flasher.write). A failure stops before the next controller and says what each one
holds now. Selection codes are sent only where the target changes (Link).
"""
from __future__ import annotations

import os
import re
from contextlib import contextmanager
from dataclasses import dataclass, replace
from enum import Enum
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Iterator

from mercmac import mdtext, outfile
from mercmac.upload import backup, flasher, history, protocol, survey
from mercmac.upload.connect import Identity, identify, open_controller
from mercmac.upload.controller import Controller, ControllerError
from mercmac.upload.errors import (FlashFailed, FlashInterrupted, NotChosen,
                                   ProgramUnreadable, Refused)
from mercmac.upload.flasher import FlashOptions, FlashResult, Notify
from mercmac.upload.transport import DEFAULT_BAUD, Timing, Transport

if TYPE_CHECKING:
    from mercmac.compiler import Compilation
    from mercmac.rig.open import Accepted
    from mercmac.rig.model import Controller as Member, Rig


class State(str, Enum):
    """What a controller holds after a rig flash (or its failure); the words are the table's."""

    FLASHED = "flashed and verified"
    UNCHANGED = "unchanged: it holds its program"
    UNTOUCHED = "untouched"
    LEFT_OUT = "untouched (not in --only)"
    PARTLY = "partly written"
    PLANNED = "dry run"


@dataclass(slots=True)
class Part:
    """One controller of the rig in this flash: what it gets, who answered, what happened."""

    member: "Member"
    compiled: "Compilation | None" = None  # None: left out by --only
    identity: Identity | None = None
    result: FlashResult | None = None
    state: State = State.UNTOUCHED
    backup_path: Path | None = None  # where its backup goes (--backup), None: the default

    @property
    def name(self) -> str:
        return self.member.name

    @property
    def chosen(self) -> bool:
        return self.compiled is not None


@dataclass(slots=True)
class RigResult:
    """A finished rig flash (or dry run): a Part per controller of the rig, in its order."""

    rig: "Rig"
    parts: list[Part]
    dry_run: bool = False
    reset: bool = False
    sent: int = 0  # bytes on the wire, both ways (benchmarks/flash_bytes.py)
    received: int = 0

    @property
    def changes_nothing(self) -> bool:
        return all(p.result is None or p.result.plan.changes_nothing for p in self.parts)

    def wire(self) -> list[tuple[bytes, str]]:
        """The exact bytes a flash sends after reading back, with what each is for: each
        controller's steps after its selection code, the code only where the target changes."""
        out, last = [], None
        for part in self.parts:
            if part.result is None or part.result.plan.changes_nothing:
                continue
            address = part.member.address
            if address != last:
                out.append((protocol.select(address), f"address selection: {part.name} "
                            f"(0x01 + address {address})"))
            steps = part.result.wire(address)[1:]  # [0]: its own selection code, sent above
            out += [(data, f"{part.name}: {what}") for data, what in steps]
            last = address
        return out + self._resets(last)

    def _resets(self, last: int | None) -> list[tuple[bytes, str]]:
        """--reset: RT to every flashed controller once all are verified (_reset_all)."""
        out = []
        for part in self.parts if self.reset else ():
            if part.chosen:
                if part.member.address != last:
                    out.append((protocol.select(part.member.address),
                                f"address selection: {part.name}"))
                out.append((protocol.command(mdtext.rt()), f"{part.name}: reset, macro 0 starts"))
                last = None  # RT deselects (MS176E §3.1)
        return out


class RigWatch:
    """What `flash_rig` tells its caller, in order; each part does nothing unless overridden."""

    def refused_rig(self, findings: list) -> None:
        """`check` finds errors in the rig or a program (rig.accept: its Findings, the rig
        file's first): shown before the refusal."""

    def compiled(self, compilation: "Compilation") -> None:
        """A program as it will be flashed (it may have warnings to show)."""

    def identified(self, part: Part, warning: str | None) -> None:
        """The controller at the part's address answered and is the rig's model."""

    @contextmanager
    def meeting(self, part: Part) -> Iterator[Notify]:
        """Around one controller's read-back and backup; yields where events go."""
        yield lambda event: None

    @contextmanager
    def writing(self, part: Part) -> Iterator[Notify]:
        """Around one controller's writes and their verification; yields where events go."""
        yield lambda event: None

    def finished(self, result: RigResult) -> None:
        """Every chosen controller is flashed and verified; the port is still open."""


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


def flash_rig(port: str, path: str, *, only: list[str] | None = None, baud: int = DEFAULT_BAUD,
              timing: Timing = Timing(), options: FlashOptions | None = None,
              watch: RigWatch | None = None) -> RigResult:
    """Flash every controller of the rig file PATH (or those named in `only`) over PORT.

    Refused before the first write: the rig file or a program has errors, a name in `only`
    is not in the rig (NotChosen, exit 2), a controller does not answer or is not the rig's
    model. backup.BackupError (exit 2, before the port opens): a backup cannot be written,
    at --backup or in the data folder. FlashFailed: a write failed; the message says what
    each controller holds now.
    `options.backup`: a folder (it exists, or a str ending in a separator) gets RIG-NAME.mcm
    per controller, anything else is a prefix: PREFIX-NAME.mcm (backup_paths).
    """
    watch = watch or RigWatch()
    options = options or FlashOptions()
    accepted = _read(path, watch)
    rig = accepted.rig
    result = RigResult(rig, _parts(accepted, only, watch), options.dry_run, options.reset)
    for part, target in zip(result.parts, backup_paths(rig, options.backup)):
        if part.chosen and target is not None:
            part.backup_path = backup.check(target)  # refused before the port opens
    if options.backup is None and not options.dry_run:
        backup.check_default()  # the data folder too, as for a single flash (exit 2)
    chosen = [p for p in result.parts if p.chosen]
    with open_controller(port, chosen[0].member.address, baud=baud, timing=timing) as first:
        link = Link(first.transport)
        _meet(link, chosen, result, options, watch)
        if not options.dry_run:
            _write_all(link, chosen, result, path, watch)
        result.sent, result.received = link.transport.sent, link.transport.received
        watch.finished(result)
    return result


def _read(path: str, watch: RigWatch) -> "Accepted":
    """The rig and its programs, checked as `check RIG` checks it (rig.accept: the rig rules
    and every program with its controller's model); Refused, after `watch.refused_rig`,
    when that finds errors. InputError (exit 2) when it or a program cannot be read."""
    from mercmac.rig.open import ProgramsUnread, RigRefused, accept

    try:
        return accept(path)
    except RigRefused as e:
        watch.refused_rig(e.findings)
        kind = ProgramUnreadable if isinstance(e, ProgramsUnread) else Refused
        raise kind(f"{e.message}; nothing was flashed", hint=e.hint) from None


def _parts(accepted: "Accepted", only: list[str] | None, watch: RigWatch) -> list[Part]:
    """A Part per controller, those `only` names (all without it) with their program."""
    rig = accepted.rig
    names = [c.name for c in rig.controllers]
    unknown = [n for n in only or () if n not in names]
    if unknown:
        raise NotChosen(f"--only names {', '.join(unknown)}, which {rig.path} does not have; "
                        f"nothing was flashed", hint=f"its controllers: {', '.join(names)}")
    parts = [Part(c, accepted.programs[c.name]) if not only or c.name in only
             else Part(c, None, state=State.LEFT_OUT) for c in rig.controllers]
    for part in parts:
        if part.chosen:
            watch.compiled(part.compiled)
    return parts


def backup_paths(rig: "Rig", given: Path | str | None) -> list[Path | None]:
    """Where each controller's backup goes: `given` a folder (it exists, or its name ends in
    a separator): FOLDER/RIG-NAME.mcm; else a prefix: PREFIX-NAME.mcm (a `.mcm` ending is
    dropped first); None: each gets backup.default_path (timestamped, never overwritten)."""
    if given is None:
        return [None for _ in rig.controllers]
    text = str(given)  # a str keeps the separator at its end that Path drops
    if Path(text).is_dir() or text.endswith(("/", os.sep)):
        folder, head = Path(text), f"{rig.name}-"
    else:
        stem = Path(text[:-4] if text.lower().endswith(".mcm") else text)
        folder, head = stem.parent, f"{stem.name}-"
    # the names are checked names (rig.load), and in_folder makes sure of it: never a path
    return [outfile.in_folder(folder, f"{head}{c.name}.mcm") for c in rig.controllers]


def _meet(link: Link, chosen: list[Part], result: RigResult, options: FlashOptions,
          watch: RigWatch) -> None:
    """Identify, read back, plan and back up every chosen controller: no write yet."""
    for part in chosen:
        c = link.controller(part.member.address)
        try:
            part.identity = link.identify(c)
            watch.identified(part, _model_warning(part, result))
            prepared = replace(options, backup=part.backup_path, reset=False)
            with watch.meeting(part) as notify:
                part.result = flasher.prepare(c, part.identity, part.compiled.program, prepared,
                                              notify)
        except Refused as e:
            raise Refused(f"{part.name} (address {part.member.address}): {e.message}\n"
                          f"{_states(result)}", hint=e.hint) from None
        except FlashInterrupted as e:
            raise FlashInterrupted(f"{part.name}: {e.message}\n{_states(result)}", by=e) from None
        except KeyboardInterrupt as e:
            raise FlashInterrupted(f"interrupted at {part.name}, before the first write; "
                                   f"nothing was written\n{_states(result)}", by=e) from None
        part.state = State.PLANNED if options.dry_run else State.UNTOUCHED


def _model_warning(part: Part, result: RigResult) -> str | None:
    """Refused when the controller is not the rig's model; a warning when VE names none
    mercmac knows (it is taken to be the rig's model, as connect.check_model does)."""
    said = part.identity.version
    if said.model == part.member.model:
        return None
    if said.model is None:
        return (f"VE answered {protocol.quote(said.text)}, which names no model mercmac "
                f"knows; going on as the {part.member.model} the rig says")
    raise Refused(f"the controller at address {part.member.address} is a {said.model}, but "
                  f"{os.path.basename(result.rig.path)} says {part.name} is a "
                  f"{part.member.model}; nothing was written",
                  hint="check the address (DIP switches 1-4, MS176E §3.1.3) and the rig's "
                       "`model`; `mercmac scan` lists who answers where")


def _write_all(link: Link, chosen: list[Part], result: RigResult, path: str,
               watch: RigWatch) -> None:
    """Write each controller in turn, verified, macro 0 last; stop at the first failure."""
    for part in chosen:
        c = link.controller(part.member.address)
        if not part.result.plan.changes_nothing:  # nothing to say to it: no selection code
            link.use(c)
            part.state = State.PARTLY
        try:
            with watch.writing(part) as notify:
                flasher.write(c, part.result, notify)
        except FlashFailed as e:
            kind = partial(FlashInterrupted, by=e) if isinstance(e, FlashInterrupted) \
                else FlashFailed
            raise kind(f"rig flash stopped at {part.name} (address {part.member.address}): "
                       f"{e.message}\n{_states(result)}", hint=e.hint) from None
        part.state = State.UNCHANGED if part.result.plan.changes_nothing else State.FLASHED
        part.result.recorded = flasher.record(
            c, part.identity, part.compiled, part.result,
            history.InRig(path, result.rig.name, part.name))
    if result.reset:
        _reset_all(link, chosen, result)


def _reset_all(link: Link, chosen: list[Part], result: RigResult) -> None:
    """RT to each controller once all are verified, so the macros 0 start together."""
    for part in chosen:
        c = link.use(link.controller(part.member.address))
        try:
            c.reset()  # RT: macro 0 starts; the controller is then deselected (MS176E §6.4 RT)
        except ControllerError as e:
            raise FlashFailed(f"every controller is written and verified, but RT to {part.name} "
                              f"failed: {e}\n{_states(result)}",
                              hint="power-cycle the rig to start the macros 0") from None
        link.current = None  # RT deselects (MS176E §3.1)


def _states(result: RigResult) -> str:
    """'  x (address 0): flashed and verified' for each controller, with the backup."""
    lines = ["what each controller holds now:"]
    for part in result.parts:
        saved = part.result.backup if part.result else None
        kept = f"; backup of what it held: {saved}" if saved and part.state is not State.UNTOUCHED \
            else ""
        lines.append(f"  {part.name} (address {part.member.address}): {part.state.value}{kept}")
    return "\n".join(lines)


# -- pulling a chain into a rig folder ---------------------------------------------------------

@dataclass(frozen=True, slots=True)
class Pulled:
    """One controller of a scanned chain: its name, what it holds, and the history record
    of the flash that left exactly that (None when mercmac did not flash it)."""

    name: str
    address: int
    pulled: survey.Pulled
    record: history.Record | None = None

    @property
    def model(self) -> str | None:
        return self.pulled.identity.version.model


def pull_rig(port: str, *, baud: int = DEFAULT_BAUD, timing: Timing = Timing(),
             records: list | None = None, on_address=None) -> list[Pulled]:
    """Every controller that answers a scan of PORT (addresses 0-15), read (which stops a
    running macro, MS176E §3.8.3), named as the history's `records` name it, else aN.
    Refused when none answers, or two answer at one address (survey.Found.shared)."""
    with open_controller(port, 0, baud=baud, timing=timing) as first:
        t = first.transport
        with t.per_address():
            found = [f for f in survey.scan(t, stop=True, on_address=on_address) if f.status]
        if not found:
            raise Refused(f"no controller answers at addresses 0-15 on {port}",
                          hint=f"check power and cable, and that DIP switches 5-6 set the "
                               f"baud rate {baud}; each address was given {timing.search:g} s "
                               f"(--timeout gives more)")
        _one_at_each(found, port)
        read = [(f.address, survey.pull(Controller(t, f.address))) for f in found]
    return _named(read, port, records or [])


def _one_at_each(found: list[survey.Found], port: str) -> None:
    """Refused when two controllers answered at one address: what is read there mixes both
    answers (MS176E §3.2), and a rig of it would merge two controllers into one."""
    shared = [str(f.address) for f in found if f.shared]
    if shared:
        where = f"address {shared[0]}" if len(shared) == 1 else f"addresses {', '.join(shared)}"
        raise Refused(f"two controllers answered at {where} on {port}: both are set to it, so "
                      f"what is read there mixes them; nothing was written",
                      hint="give each controller its own address (DIP switches 1-4, MS176E "
                           "§3.1.3), then pull again")


def _named(read: list[tuple[int, survey.Pulled]], port: str, records: list) -> list[Pulled]:
    """Names from the history when a record of exactly these macros gives one, else aN;
    a name taken already (two rigs' `x`) falls back to aN too, and an aN taken already
    gets a '_' more: two controllers never share a file."""
    from mercmac.rig.load import is_name

    out, taken = [], set()
    for address, pulled in read:
        record = history.recall(pulled.macros, records, port=port, address=address).record
        name = record.controller if record and record.controller else ""
        if not is_name(name) or name in taken:  # a history file may say anything
            name = f"a{address}"
        while name in taken:  # aN named by the history for another address: one file each
            name += "_"
        taken.add(name)
        out.append(Pulled(name, address, pulled, record))
    return out


def rig_name(members: list[Pulled], folder: Path) -> str:
    """The rig's name as the history has it, when the records agree on one that is a name
    (a history file may say '../x'); else one made from the folder's name."""
    from mercmac.rig.load import is_name

    names = {m.record.rig_name for m in members if m.record and m.record.rig_name}
    if len(names) == 1 and is_name(said := names.pop()):
        return said
    return name_from(folder.name)


def name_from(text: str) -> str:
    """A rig name (rig.load.is_name) made from TEXT, a folder's name: 'my rig' -> 'my_rig',
    '2026' -> '_2026', '' -> 'rig'."""
    name = re.sub(r"[^A-Za-z0-9_]+", "_", text).strip("_") or "rig"
    return f"_{name}" if name[0].isdigit() else name


def rig_text(name: str, members: list[Pulled], port: str) -> str:
    """A rig file for the pulled controllers (keys as mercmac.rig.load reads them); what a
    controller cannot tell (wires, box, joystick) is said in a comment, the port escaped
    (TOML refuses control characters in a comment, and a newline would end it)."""
    import datetime as _dt
    import json

    from mercmac import __version__
    from mercmac.names import printable

    when = _dt.datetime.now().astimezone().isoformat(timespec="seconds")
    head = [f"# read by mercmac {__version__} from {printable(port)} on {when}: the "
            f"controllers that answered a scan",
            "# Wires cannot be read from controllers (nor which one has the C-170.PB box,",
            "# nor the joystick's branches): add them, e.g. wires = [\"x.out1 -> y.in1\"]",
            f"name = {json.dumps(name)}",  # a JSON string is a TOML basic string
            "wires = []"]
    for m in members:
        model = json.dumps(m.model) if m.model else '"?"  # VE named no model mercmac knows'
        head += ["", f"[controllers.{m.name}]", f"address = {m.address}", f"model = {model}",
                 f"program = {json.dumps(m.name + '.mcm')}"]
    return "\n".join(head) + "\n"
