"""The uploader's text: identification, progress, the flash summary, dry runs, pull, scan, ports.

Plain lines when the output is not a terminal (logs, CI); a rich progress bar
and colour on a terminal (render/console.py decides, NO_COLOR honoured). A program file's
flash is shown as one controller's (its slots); a rig's with a row per controller.
"""
from __future__ import annotations

import os
import sys
from contextlib import ExitStack, contextmanager, nullcontext
from typing import IO

from mercmac.mdtext import slot_name
from mercmac.names import printable
from mercmac.render.console import Line, rich_console, table, use_colour, write_lines
from mercmac.render.sim import plural
from mercmac.timespec import format_clock
from mercmac.upload.chain import Watch
from mercmac.upload.flasher import Event, EventKind

_FATE_STYLE = {"written": "bold green", "erased": "bold yellow", "re-written last": "green",
               "unchanged": "dim", "kept (not in file)": "yellow"}
# a dry run writes nothing: its table says what a flash would do to each slot
_WOULD = {"written": "would be written", "erased": "would be erased",
          "re-written last": "would be removed first, written back last",
          "unchanged": "unchanged", "kept (not in file)": "kept (not in file)"}
_WOULD_TALLY = {"written": "write {n}", "erased": "erase {n}", "re-written last": "write back {n} last",
                "unchanged": "leave {n} unchanged", "kept (not in file)": "keep {n} not in the file"}


def identity_lines(port: str, address: int, identity, warning: str | None = None, *,
                   searched: bool = False, name: str = "controller") -> list[Line]:
    """'C-863, firmware 2.30, at address 0 on /dev/ttyUSB0' and what we had to do;
    `searched`: no --address was given and the address was found by a search; `name`: the
    controller's name in a rig. The port, like every name from outside, is shown escaped
    (mercmac/names.py): it may hold any character."""
    v = identity.version
    lines: list[Line] = [[(f"{name}: ", "bold"), (f"{v.name}, firmware {v.firmware}", "cyan"),
                          (f", at address {address} on {printable(port)}", "")]]
    if searched:
        lines.append([("note: ", "bold"), (f"no --address given and nothing at 0: address {address} "
                                           f"is the only one that answers", "")])
    if identity.stopped_macro:
        lines.append([("note: ", "bold yellow"), ("a macro was running; it was stopped", "")])
    if warning:
        lines.append([("warning: ", "bold yellow"), (warning, "")])
    return lines


class FlashProgress:
    """Receives flasher events: a rich progress bar on a terminal, one line each otherwise."""

    def __init__(self, stream: IO[str] | None = None):
        self.stream = stream or sys.stdout
        self._progress = self._task = None
        self._started: tuple[float, int] | None = None  # (time, bytes sent) at the first step
        self._gone = False  # the stream cannot be written any more

    def __enter__(self) -> "FlashProgress":
        if use_colour(self.stream):
            from rich.progress import BarColumn, Progress, TextColumn

            # no refresh thread: it would keep redrawing the bar over the message of a
            # Ctrl-C that cut `stop` short; the bar is redrawn on each event instead.
            # The bar counts bytes (commands and read-backs): a rate and the time left follow.
            self._progress = Progress(TextColumn("[bold]{task.description:<28}"), BarColumn(),
                                      TextColumn("{task.fields[steps]}"),
                                      TextColumn("[dim]{task.fields[rate]}"),
                                      console=rich_console(self.stream),
                                      transient=True, auto_refresh=False)
            self._progress.start()
        return self

    def __exit__(self, *exc) -> None:
        if self._progress and not self._gone:
            self._drawing(self._progress.stop)

    def _drawing(self, draw, *args) -> None:
        """Draw, unless the stream is gone: a hung-up terminal (SIGHUP follows) or a pipe
        whose reader left. The flash goes on undrawn, and its report (on standard error,
        perhaps a file) is not replaced by this error."""
        try:
            draw(*args)
        except OSError:
            self._gone = True

    def _rate(self, event) -> str:
        """Bytes per second since the first step, and the time left at that rate."""
        import time

        now = time.monotonic()
        if self._started is None:
            self._started = (now, event.sent)
        start, sent0 = self._started
        return _rate_text(event.sent - sent0, event.size - sent0, now - start)

    def __call__(self, event: Event) -> None:
        if not self._gone:
            self._drawing(self._show, event)

    def _show(self, event: Event) -> None:
        if self._progress is None:
            if event.kind != EventKind.STEP:  # a log line says what was done, not what begins
                write_lines([_event_line(event)], self.stream)
            return
        match event.kind:
            case EventKind.STEP | EventKind.VERIFIED:
                self._advance(event)
            case _:
                from rich.text import Text

                self._progress.console.print(Text.assemble(*_event_line(event)))

    def _advance(self, event: Event) -> None:
        """The bar moves on: the step, the steps done and the rate."""
        steps, rate = f"{event.done}/{event.total}", self._rate(event)
        if self._task is None:
            self._task = self._progress.add_task(event.text, total=event.size or event.total,
                                                 steps=steps, rate=rate)
        self._progress.update(self._task, description=event.text, steps=steps, rate=rate,
                              completed=event.sent if event.size else event.done, refresh=True)


class AddressProgress:
    """'scanning: address 5 of 0-15' redrawn in place on a terminal; nothing elsewhere (logs)."""

    def __init__(self, stream: IO[str] | None = None, what: str = "scanning"):
        self.stream, self.what, self.shown = stream or sys.stderr, what, False
        isatty = getattr(self.stream, "isatty", None)
        self.live = bool(isatty and isatty()) or bool(os.environ.get("FORCE_COLOR"))

    def __enter__(self) -> "AddressProgress":
        return self

    def __exit__(self, *exc) -> None:
        if self.shown:
            self.stream.write("\r\x1b[K")  # the line goes away before the result is printed
            self.stream.flush()

    def __call__(self, address: int) -> None:
        if self.live:
            # \r and ESC [K (erase to end of line): the line is redrawn where it stands
            self.stream.write(f"\r\x1b[K{self.what}: address {address} of 0-15 ...")
            self.stream.flush()
            self.shown = True


class FlashShown(Watch):
    """What `flash` shows while it flashes a program file or a rig: diagnostics, who answered
    at each address, progress; it keeps the finished flash (a Ctrl-C while it is shown still
    says what was done) and whether the address was found by a search."""

    def __init__(self, port: str):
        self.port = port
        self.done = None  # the finished flash (upload.chain.Flash)
        self.searched = False  # no --address, nothing at 0: addresses 1-15 were searched
        self._probing: AddressProgress | None = None
        self._open: ExitStack | None = None  # what `flashing` closes: a program file's bar
        self._bar: FlashProgress | None = None

    def refused(self, findings) -> None:
        from mercmac.render.report import write_findings

        write_findings(findings, sys.stderr)  # as `check` shows them, before the refusal

    def compiled(self, compilation) -> None:
        from mercmac.render.report import write_warnings

        write_warnings(compilation)  # on standard error; the flash goes on

    @contextmanager
    def searching(self):
        with looking_for_address() as self._probing:
            yield self._probe

    def _probe(self, address: int) -> None:
        self.searched = True
        self._probing(address)

    def identified(self, part, warning) -> None:
        write_lines(identity_lines(self.port, part.address, part.identity, warning,
                                   searched=self.searched, name=part.name or "controller"))

    @contextmanager
    def flashing(self, flash):
        with ExitStack() as self._open:
            try:
                yield
            finally:
                self._bar = None  # the stack closes it

    @contextmanager
    def meeting(self, part):
        with self._progress(part) as progress:
            yield progress

    @contextmanager
    def writing(self, part):
        if part.name:  # a rig's controller: which one, and what it gets
            write_lines(rig_writing_lines(part))
        with self._progress(part) as progress:
            yield progress

    @contextmanager
    def resetting(self, flash):
        if flash.named:  # the rig's summary says RT went to each
            yield lambda event: None
            return
        with self._progress(flash.parts[0]) as progress:
            yield progress

    def _progress(self, part):
        """A bar for each controller of a rig and each phase; for a program file's controller
        one bar from its backup until the flash is finished (`flashing` closes it), so that a
        Ctrl-C while it closes finds the flash finished."""
        if part.name:
            return FlashProgress()
        if self._bar is None:
            self._bar = self._open.enter_context(FlashProgress())
        return nullcontext(self._bar)

    def finished(self, flash) -> None:
        self.done = flash  # a Ctrl-C from here on still says what was done


def looking_for_address() -> AddressProgress:
    """No --address: the address probed, while looking for the controller (survey.reach)."""
    return AddressProgress(sys.stderr, "no --address: looking for the controller")


def _rate_text(sent: int, size: int, seconds: float) -> str:
    """'38 B/s, 00:00:12 left' once some bytes went out; '' before (a line redrawn in place)."""
    if sent <= 0 or seconds <= 0:
        return ""
    rate = sent / seconds
    left = int(round((size - sent) / rate)) if size > sent else 0
    return f"{rate:,.0f} B/s, {format_clock(left * 1e6, places=0, fixed=True)} left"


def _event_line(event: Event) -> Line:
    match event.kind:
        case EventKind.VERIFIED:
            return [(f"[{event.done}/{event.total}] ", "dim"), (event.text, "")]
        case EventKind.BACKUP:
            return [(f"backup of {plural(event.done, 'stored macro')}: {printable(event.text)}",
                     "bold")]
        case EventKind.RETRY | EventKind.REPAIR:
            return [(event.text, "bold yellow")]
        case _:
            return [(event.text, "")]


def flash_summary(flash, port: str) -> list[Line]:
    """A finished flash: a rig's controller table, or a program file's slot table; and the
    outcome."""
    if flash.named:
        return _rig_summary(flash, port)
    return _slot_summary(flash.parts[0].result)


def _slot_summary(result) -> list[Line]:
    """The slot table and the outcome line."""
    plan = result.plan
    dry = result.dry_run
    rows = [(slot_name(slot), _name(plan.names.get(slot), slot),
             _WOULD[fate.value] if dry else fate.value) for slot, fate in sorted(plan.fates.items())]
    styles = {(_WOULD[k] if dry else k): v for k, v in _FATE_STYLE.items()}
    lines = table(("slot", "macro", "a flash" if dry else "result"), rows,
                  style_of=lambda row: styles.get(row[2], ""))
    if dry:
        lines.append([("dry run: ", "bold yellow"), (f"nothing written; {_would(plan)}", "")])
        return lines + _kept_note(result)
    lines.append([("ok: ", "bold green"), (_outcome(plan), "")])
    if result.unrecorded:  # the flash stands; only `pull` giving back this source is lost
        lines.append([("warning: ", "bold yellow"),
                      (f"the flash could not be recorded in the history ({result.unrecorded}): "
                       f"`mercmac history` will not list it, nor `pull` give back this source",
                       "")])
    if result.retried or result.repaired:
        again = ", ".join(slot_name(s) for s in result.retried + result.repaired)
        lines.append([("note: ", "bold yellow"), (f"needed a second write: {again} (check the cable)", "")])
    lines.append([("backup: ", "bold"), (printable(str(result.backup)), "")])
    lines += _kept_note(result)
    if result.reset:
        lines.append([("reset: ", "bold"), ("RT sent, macro 0 is starting", "")])
    elif 0 in plan.after and not plan.changes_nothing:
        lines.append([("", ""), ("macro 0 runs at the next power-on (or use --reset)", "dim")])
    return lines


def _kept_note(result) -> list[Line]:
    """A flash without --erase-unused leaves the macros the file lacks: say so, and how to
    remove them (for a backup: how to restore it exactly)."""
    extra = result.left_over
    if not extra:
        return []
    slots = ", ".join(slot_name(s) for s in extra)
    kept = _kept(len(extra), result.dry_run)
    if not result.restoring:
        return [[("note: ", "bold yellow"),
                 (f"the controller also holds {slots}, which {kept} (not in the file): "
                  f"flash with --erase-unused to remove {'it' if len(extra) == 1 else 'them'}",
                  "")]]
    held = len(result.plan.after) - len(extra)
    return [[("note: ", "bold yellow"),
             (f"this backup holds {plural(held, 'macro')}; the controller also "
              f"holds {slots}, which {kept}: to "
              f"restore the backup exactly, flash it again with --erase-unused", "")]]


def _kept(n: int, dry_run: bool) -> str:
    return "would be kept" if dry_run else "was kept" if n == 1 else "were kept"


def completed_text(flash) -> str:
    """The outcome of a finished flash in plain words, for a Ctrl-C while it is being shown."""
    if flash.named:
        return "the rig flash had finished:\n" + "\n".join(
            f"  {p.name} (address {p.address}): {p.state.value}" for p in flash.parts)
    result = flash.parts[0].result
    if result.dry_run:
        return f"dry run complete, nothing was written; {_would(result.plan)}"
    reset = "; RT was sent, macro 0 is starting" if result.reset else ""
    return (f"the flash had finished: {_outcome(result.plan)}{reset}\n"
            f"  backup: {printable(str(result.backup))}")


def _outcome(plan) -> str:
    if plan.changes_nothing:
        return "nothing to write: the controller already holds this program"
    return f"flashed and verified: {_tally(plan)}"


def _tally(plan) -> str:
    """'2 written, 1 unchanged': how many slots met each fate."""
    counts: dict[str, int] = {}
    for fate in plan.fates.values():
        counts[fate.value] = counts.get(fate.value, 0) + 1
    return ", ".join(f"{n} {what}" for what, n in counts.items()) or "no macros"


def _would(plan) -> str:
    """'a flash would write 2, leave 1 unchanged': the plan in the conditional."""
    if plan.changes_nothing:
        return "a flash would write nothing: the controller already holds this program"
    counts: dict[str, int] = {}
    for fate in plan.fates.values():
        counts[fate.value] = counts.get(fate.value, 0) + 1
    return "a flash would " + ", ".join(_WOULD_TALLY[what].format(n=n) for what, n in counts.items())


def dry_run_lines(flash, baud: int) -> list[Line]:
    """Every byte a real flash would now send, selection codes included, and what for."""
    if flash.changes_nothing:
        held = ("every controller already holds its program" if flash.named
                else "the controller already holds this program")
        return [[("nothing to send: ", "bold"), (held, "")]]
    return wire_lines(flash.wire(), baud)


def wire_lines(wire: list[tuple[bytes, str]], baud: int) -> list[Line]:
    """The bytes of a dry run, one command a line with what it is for, and their time."""
    from mercmac.upload.protocol import show

    lines: list[Line] = [[("bytes a flash would send after the read-back:", "bold")]]
    for data, purpose in wire:
        lines.append([("  -> ", "dim"), (f"{show(data):<64}", "cyan"), (f" {purpose}", "dim")])
    total = sum(len(data) for data, _ in wire)
    lines.append([("", ""), (f"{total} bytes out, {total * 10 / baud:.2f} s at {baud} baud", "dim")])
    return lines


def pulled_lines(pulled, port: str, address: int, output: str | None) -> list[Line]:
    v = pulled.identity.version
    where = f" into {printable(output)}" if output else ""
    return [[("read ", ""), (plural(len(pulled.macros), "macro"), "bold"),
             (f" from the {v.name} (firmware {v.firmware}) at address {address} on "
              f"{printable(port)}{where}", "")]]


def scan_lines(found, port: str) -> list[Line]:
    if not found:
        return [[("no controller answered", "bold yellow"),
                 (f" on {printable(port)} at addresses 0-15", "")]]
    rows = [(str(f.address), f.model, f.version.firmware if f.version else "?", f.note)
            for f in found]
    lines = table(("address", "model", "firmware", "note"), rows)
    if not any(f.status for f in found):
        lines.append([("no controller answered like a Mercury", "bold yellow"),
                      (f" on {printable(port)}: garbled replies come from a baud rate other "
                       f"than the controllers' (check --baud)", "")])
    return lines


def ports_lines(ports) -> list[Line]:
    if not ports:
        return [[("no serial ports found", "bold yellow")]]
    # the device's name and description come from the system and the USB device itself
    rows = [(printable(p.device), f"{p.vid:04X}:{p.pid:04X}" if p.vid is not None else "-",
             printable(p.description), f"likely Mercury ({p.mercury})" if p.mercury else "")
            for p in ports]
    return table(("port", "usb id", "description", ""), rows,
                 style_of=lambda row: "bold green" if row[3] else "")


def _name(name: str | None, slot: int) -> str:
    tag = slot_name(slot)
    if not name or name == tag:
        return "-"
    return name.replace(f" ({tag})", "")


# -- rigs (mercmac.upload.chain, a Flash with names) ------------------------------------------

def _rig_summary(result, port: str) -> list[Line]:
    """A row per controller of the rig, and the outcome line."""
    rows = [(p.name, str(p.address), p.model,
             printable(os.path.basename(p.program)), _rig_cell(p, result.dry_run),
             printable(str(p.result.backup)) if p.result and p.result.backup else "-")
            for p in result.parts]
    rig = printable(result.rig.name)
    lines = table(("controller", "address", "model", "program", "a flash" if result.dry_run
                   else "result", "backup"), rows, style_of=_rig_style)
    chosen = [p for p in result.parts if p.result]
    which = (f"every controller of {rig}" if len(chosen) == len(result.parts)
             else f"each of the {plural(len(chosen), 'chosen controller')}")
    if result.dry_run:
        lines.append([("dry run: ", "bold yellow"), (f"nothing written to "
                                                     f"{plural(len(chosen), 'controller')} of "
                                                     f"{rig}", "")])
    elif result.changes_nothing:
        lines.append([("ok: ", "bold green"), (f"nothing to write: {which} already holds its "
                                               f"program", "")])
    else:
        lines.append([("ok: ", "bold green"), (f"{rig} on {printable(port)}: "
                                               f"{plural(len(chosen), 'controller')} verified", "")])
    lines += [[("warning: ", "bold yellow"), (f"{p.name}: the flash could not be recorded in the "
                                              f"history ({p.result.unrecorded})", "")]
              for p in chosen if p.result.unrecorded]
    if result.reset:
        lines.append([("reset: ", "bold"), ("RT sent to each, macro 0 is starting", "")])
    return lines


def rig_writing_lines(part) -> list[Line]:
    """'y (address 1): writing 2 macros', or that it holds its program already."""
    plan = part.result.plan
    what = ("nothing to write: it holds its program" if plan.changes_nothing
            else f"{plural(len(plan.steps), 'step')}, macro 0 last")
    return [[(f"{part.name} (address {part.address}): ", "bold"), (what, "")]]


def _rig_cell(part, dry_run: bool) -> str:
    """'written 3, unchanged 1' (or what a flash would do), else the controller's state."""
    if part.result is None:
        return part.state.value
    if dry_run:
        return _would(part.result.plan).removeprefix("a flash would ")
    if part.result.plan.changes_nothing:
        return "unchanged"
    return f"{part.state.value}: {_tally(part.result.plan)}"


def _rig_style(row) -> str:
    return "bold green" if row[4].startswith("flashed") else "dim" if row[4] == "unchanged" else ""


def pulled_rig_lines(members, port: str, rig_file, how: list[str],
                     found: list | str, wiring=None) -> list[Line]:
    """A row per controller read from the chain, what its file holds (`how`) and why, the rig
    file and where its wiring came from (`wiring`, upload.rig.Wiring), and what `check` finds
    in it as written (`found`: its diagnostics, or why it could not check it)."""
    rows = [(m.name, str(m.address), m.pulled.identity.version.name,
             plural(len(m.pulled.macros), "macro"), made) for m, made in zip(members, how)]
    lines = table(("controller", "address", "model", "holds", "written as"), rows)
    lines += _written_as(members, how)
    lines.append([("rig: ", "bold"), (f"{printable(str(rig_file))} ("
                                      f"{plural(len(members), 'controller')} on "
                                      f"{printable(port)}; {_wired(wiring)})", "")])
    return lines + [_checked_line(rig_file, found)]


def _written_as(members, how: list[str]) -> list[Line]:
    """Why each kind of file was written, naming the controllers: a recorded source is the
    one mercmac flashed, which builds to exactly what the controller holds (upload.history)."""
    kinds: dict[str, list] = {}
    for m, made in zip(members, how):
        kinds.setdefault(made, []).append(m)
    lines = []
    for made, these in kinds.items():
        names = ", ".join(m.name for m in these)
        if made == "recorded source":
            why = ("each holds a build the flash history records (`mercmac history`), so the "
                   "source flashed comes back, names and comments included: it builds to "
                   "exactly what the controller holds")
        elif any(m.record for m in these):  # stored macros although a flash is known: --raw
            why = "--raw: the macros as the controller stores them"
        else:
            holds = "it holds" if len(these) == 1 else "they hold"
            what = ("made from the stored macros, with made-up names" if made == "decompiled"
                    else "the macros as stored")
            why = f"no flash in the history left exactly what {holds}: {what}"
        lines.append([(f"{made} ", "bold"), (f"({printable(names)}): {why}", "")])
    return lines


def _wired(wiring) -> str:
    """Where the rig file's wires came from: the rig flashed to the chain, or nowhere."""
    from mercmac.upload.rig import given_back, wiring_date

    if wiring is None or wiring.rig is None:
        stale = (f"; the rig flashed on {wiring_date(wiring)}, {printable(wiring.path)}, no "
                 f"longer matches: {printable(wiring.why)}" if wiring is not None and wiring.why
                 else "")
        return f"wires cannot be read: add them{stale}"
    return (f"{given_back(wiring.rig)} from the rig flashed on {wiring_date(wiring)}: "
            f"{printable(wiring.path)}")



def _checked_line(rig_file, found: list) -> Line:
    """'check: clean', or what `mercmac check RIG` will say of the folder as written."""
    from mercmac.diagnostics import Severity

    if isinstance(found, str):
        return [("check: ", "bold"), (f"not run: {printable(found)}", "yellow")]
    counts = [sum(d.severity is s for d in found) for s in Severity]
    said = ", ".join(plural(n, str(s)) for n, s in zip(counts, Severity) if n)
    where = f"; `mercmac check {printable(str(rig_file))}` lists them"
    if not counts[Severity.ERROR] and not counts[Severity.WARNING]:
        return [("check: ", "bold"), ("clean", "green"), (f" ({said}{where})" if said else "", "")]
    return [("check: ", "bold"), (said, "bold red" if counts[Severity.ERROR] else "yellow"),
            (where, "")]
