"""What a rig adds to the uploader: a backup file per controller, and pulling a chain.

docs/rigs.md, MS176E §3.2: up to 16 controllers share one RS-232/USB link and each takes only
what follows its address selection code (`\\x01` + one hex digit, §3.1.1, §3.1.3). A rig is
flashed as a program file is, by chain.py (a program file is a chain of one controller);
here: where each controller's backup goes (backup_paths), and reading every controller that
answers a scan into a rig folder (pull_rig).
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, NamedTuple

from mercmac import outfile
from mercmac.upload import history, survey
from mercmac.upload.connect import open_controller
from mercmac.upload.controller import Controller
from mercmac.upload.errors import Refused
from mercmac.upload.transport import DEFAULT_BAUD, Timing

if TYPE_CHECKING:
    from mercmac.rig.model import Rig


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


class Wiring(NamedTuple):
    """What a chain's history gives back beyond its programs: the rig file mercmac flashed to
    it (`path`, read today as `rig`) and its newest flash there (`record`). `rig` is None when
    no controller holds a build flashed as part of a rig, or when that file no longer matches
    the chain (`why`): wires, box and joystick cannot be read from the controllers."""

    rig: "Rig | None" = None
    record: history.Record | None = None
    path: str = ""
    why: str = ""


def recorded_wiring(members: list[Pulled]) -> Wiring:
    """The rig file the history says was flashed to these controllers, when it still matches
    what they hold: it reads and checks without errors, and each of its controllers answered
    at its address under its name and holds what its program builds to today. Controllers
    the rig does not name may answer too (they get no wire)."""
    recorded = [m.record for m in members if m.record is not None and m.record.rig]
    if not recorded:
        return Wiring()
    newest = max(recorded, key=lambda r: r.when)
    paths = sorted({r.rig for r in recorded})
    if len(paths) > 1:
        return Wiring(None, newest, newest.rig, f"the chain holds builds of {len(paths)} rig "
                                                f"files ({', '.join(paths)})")
    rig, why = _still_matching(newest.rig, members)
    return Wiring(rig, newest, newest.rig, why)


def _still_matching(path: str, members: list[Pulled]) -> tuple["Rig | None", str]:
    """The rig file at PATH, read as every command reads a rig, and '' when the chain holds
    what it says; else None and why not."""
    from mercmac.errors import MercmacError
    from mercmac.rig.open import ProgramsUnread, RigRefused, RigUnreadable, accept

    try:
        accepted = accept(path)
    except RigUnreadable as e:  # gone, moved, no longer a regular file
        return None, f"it cannot be read ({e.why})"
    except ProgramsUnread:
        return None, "a program it names cannot be read"
    except RigRefused:
        return None, "`mercmac check` finds errors in it now"
    except MercmacError as e:  # a settings file above it that `check` refuses
        return None, e.message
    by_address = {m.address: m for m in members}
    for c in accepted.rig.controllers:
        m = by_address.get(c.address)
        if m is None:
            return None, f"its {c.name} at address {c.address} did not answer"
        if m.record is None or (m.record.rig, m.record.controller) != (path, c.name) \
                or m.name != c.name:
            return None, f"its {c.name} (address {c.address}) holds no build flashed from it"
        if not history.builds_to(accepted.programs[c.name].program, m.pulled.macros):
            return None, (f"{os.path.basename(c.program)} no longer builds to what {c.name} "
                          "holds")
    return accepted.rig, ""


def rig_name(members: list[Pulled], folder: Path) -> str:
    """The rig's name as the history has it, when the records agree on one that is a name
    (a history file may say '../x'); else one made from the folder's name."""
    from mercmac.rig.load import is_name
    from mercmac.rig.model import name_from

    names = {m.record.rig_name for m in members if m.record and m.record.rig_name}
    if len(names) == 1 and is_name(said := names.pop()):
        return said
    return name_from(folder.name)


def rig_text(name: str, members: list[Pulled], port: str, wiring: Wiring = Wiring()) -> str:
    """A rig file for the pulled controllers (keys as mercmac.rig.load reads them); the wires,
    box and joystick of the rig flashed to them when it still matches (`wiring`), else what a
    controller cannot tell is said in a comment. Paths and the port are escaped (TOML refuses
    control characters in a comment, and a newline would end it)."""
    import datetime as _dt
    import json

    from mercmac import __version__
    from mercmac.names import printable

    when = _dt.datetime.now().astimezone().isoformat(timespec="seconds")
    head = [f"# read by mercmac {__version__} from {printable(port)} on {when}: the "
            f"controllers that answered a scan"]
    if wiring.rig is None:
        head += ["# Wires cannot be read from controllers (nor which one has the C-170.PB box,",
                 "# nor the joystick's branches): add them, e.g. wires = [\"x.out1 -> y.in1\"]"]
        if wiring.why:
            head.append(f"# (the rig flashed on {wiring_date(wiring)}, {printable(wiring.path)}, "
                        f"no longer matches: {printable(wiring.why)})")
        head += [f"name = {json.dumps(name)}", "wires = []"]  # a JSON string: a TOML string
    else:
        head += [f"# {given_back(wiring.rig)} from the rig flashed on {wiring_date(wiring)}: "
                 f"{printable(wiring.path)}", f"name = {json.dumps(name)}",
                 *_wiring_lines(wiring.rig)]
    for m in members:
        model = json.dumps(m.model) if m.model else '"?"  # VE named no model mercmac knows'
        head += ["", f"[controllers.{m.name}]", f"address = {m.address}", f"model = {model}",
                 f"program = {json.dumps(m.name + '.mcm')}"]
    return "\n".join(head) + "\n"


def wiring_date(wiring: Wiring) -> str:
    """When the recorded rig was last flashed to the chain: '2026-11-22 10:41'."""
    return wiring.record.when.strftime("%Y-%m-%d %H:%M")


def given_back(rig: "Rig") -> str:
    """'wires, box and joystick': what a pulled rig file takes from the rig flashed, as far
    as that rig has them."""
    parts = [part for part, has in (("wires", rig.wires), ("box", rig.box),
                                    ("joystick", rig.joystick)) if has]
    if not parts:
        return "no wires"
    return parts[0] if len(parts) == 1 else f"{', '.join(parts[:-1])} and {parts[-1]}"


def _wiring_lines(rig: "Rig") -> list[str]:
    """The box, the wires and the [joystick] table of `rig` as its file states them."""
    import json

    lines = []
    if rig.box is not None:
        lines += [f"box = {json.dumps(rig.box)}",
                  f"box_buttons = [{', '.join(map(str, rig.box_buttons))}]"]
    wires = [f"  {json.dumps(str(w))}," for w in rig.wires]
    lines += ["wires = [", *wires, "]"] if wires else ["wires = []"]
    if rig.joystick:
        lines += ["", "[joystick]"] + [f"{branch} = {json.dumps(controller)}"
                                       for branch, controller in rig.joystick.items()]
    return lines
