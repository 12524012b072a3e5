"""`mercmac flash`, `pull`, `ports`, `scan` and `emulate`: thin click commands (SPEC §4, §5).

The serial library, rich and the uploader are imported inside the command
bodies so that `mercmac check` starts fast.
"""
from __future__ import annotations

import sys
from pathlib import Path

import click

from mercmac.cli.common import MODEL_CHOICE, FiniteFloat, UsageError, run_guarded
from mercmac.emulator.faults import EmptySlot, Framing  # two enums: light to import
from mercmac.errors import EXIT_FAILED, EXIT_INTERRUPTED, EXIT_OK

_ADDRESS = click.option("--address", type=click.IntRange(0, 15), default=0, show_default=True,
                        help="Controller address, DIP switches 1-4 (MS176E §3.1.3).")
# flash and pull: no --address looks for the controller (survey.reach)
_FIND_ADDRESS = click.option("--address", type=click.IntRange(0, 15), default=None,
                             help="Controller address, DIP switches 1-4 (MS176E §3.1.3). "
                                  "Default: 0 if a controller answers there, else the only "
                                  "address that answers (1-15 searched, about 5 s).")
def one_port(ctx, param, values: tuple):
    """An option given at most once (multiple=True collects them): `-p A -p B` is refused,
    where click would silently keep B."""
    if len(values) > 1:
        shown = ", ".join(repr(v) for v in values)
        raise click.BadParameter(f"given {len(values)} times ({shown}): give the port once")
    return values[0] if values else None


def file_name(ctx, param, value: str | None):
    """A file name option: '' is refused (it names no file, and would write nothing)."""
    if value == "":
        raise click.BadParameter("an empty file name: give the path of a file")
    return value


_PORT_OPTION = click.option("-p", "--port", "port_option", metavar="PORT", multiple=True,
                            callback=one_port,
                            help="The port, as PORT; default: $MERCMAC_PORT, else the only PI USB "
                                 "device (vendor 0x1A72), else the only serial port.")
_BAUD = click.option("--baud", type=click.IntRange(300, 921_600), default=9600, show_default=True,
                     help="Baud rate, DIP switches 5-6.")
_TIMEOUT = click.option("--timeout", type=FiniteFloat(0.05, 60), default=1.0,
                        show_default=True, help="Seconds to wait for each reply.")


def looks_like_program(text: str) -> bool:
    """A `.mcm` name, or an existing regular file: not a port (devices are not regular files)."""
    if text.lower().endswith(".mcm"):
        return True
    try:
        return Path(text).is_file()
    except (OSError, ValueError):
        return False


def split_flash_args(first: str | None, second: str | None, option: str | None,
                     command: str = "flash") -> tuple[str | None, str]:
    """(PORT or None, FILE) from `flash [PORT] FILE` (also `flash FILE PORT`); refuses a swapped pair or a missing FILE."""
    if second is None:
        if first is None:
            raise UsageError("no program file given",
                             hint=f"mercmac {command} [PORT] FILE.mcm")
        return None, first  # one argument: the file; the port comes from -p, the environment or a search
    if looks_like_program(first) and not looks_like_program(second):
        raise UsageError(f"{first!r} is a program file where the port goes: the arguments are swapped",
                         hint=f"mercmac {command} {second} {first}  (PORT first, then FILE)")
    if option is not None and option != first:
        raise UsageError(f"two ports given: {first!r} and -p/--port {option!r}",
                         hint=f"give the port once: mercmac {command} {first} {second}")
    return first, second


def check_port_arg(port: str | None, option: str | None, command: str) -> str | None:
    """The PORT of `pull`/`scan [PORT]`; a program file there, or two ports, is refused."""
    if port is not None and looks_like_program(port):
        raise UsageError(f"{port!r} is a program file where the port goes",
                         hint=f"mercmac {command} PORT (`mercmac ports` lists them)")
    if port is not None and option is not None and option != port:
        raise UsageError(f"two ports given: {port!r} and -p/--port {option!r}",
                         hint=f"give the port once: mercmac {command} {port}")
    return port if port is not None else option


def _port(port: str | None, option: str | None, command: str) -> str:
    """The port to open (mercmac.upload.ports); says on stderr how it was found if not given."""
    from mercmac.upload import ports as chooser

    chosen = chooser.resolve(check_port_arg(port, option, command))
    if chosen.how:
        click.echo(f"port: {chosen.port} ({chosen.how})", err=True)
    return chosen.port


def _timing(timeout: float):
    from mercmac.upload.transport import Timing

    return Timing.waiting(timeout)


@click.command()
@click.argument("port", required=False, metavar="[PORT]")
@click.argument("file", required=False, metavar="FILE",
                type=click.Path(dir_okay=False, allow_dash=True))
@_PORT_OPTION
@_FIND_ADDRESS
@_BAUD
@click.option("--dry-run", is_flag=True, help="Read back and show the exact bytes; write nothing.")
@click.option("--backup", type=click.Path(dir_okay=False, writable=True), callback=file_name,
              help="Where to save what the controller holds (default: a timestamped file "
                   "in the per-user data directory).")
@click.option("--erase-unused", is_flag=True, help="Remove stored macros the file does not define.")
@click.option("--reset", is_flag=True, help="Send RT afterwards so that macro 0 starts.")
@click.option("--force", is_flag=True, help="Flash even if the controller is not the file's target.")
@click.option("--target", type=MODEL_CHOICE, help="Controller model; overrides the file's `target`.")
@_TIMEOUT
def flash(port, file, port_option, address, baud, dry_run, backup, erase_unused, reset, force,
          target, timeout) -> None:
    """Upload FILE to the controller on PORT: back up, write what differs, verify.

    PORT is anything pyserial opens: COM3, /dev/ttyUSB0, a pty path,
    socket://host:port. Without it: -p PORT, $MERCMAC_PORT, or the only likely
    Mercury port. Exit 0 only when every written macro reads back right.
    """
    def work() -> int:
        nonlocal port, file
        from mercmac.render import upload as view
        from mercmac.render.console import write_lines
        from mercmac.upload import backup as backups
        from mercmac.upload import flasher

        given, file = split_flash_args(port, file, port_option)
        port = _port(given, port_option, "flash")
        options = flasher.FlashOptions(erase_unused, dry_run, reset, Path(backup) if backup else None)
        try:
            result = flasher.flash_file(port, file, address=address, baud=baud,
                                        timing=_timing(timeout), options=options, target=target,
                                        force=force, watch=_watch(port, address, finished))
            address_used = result.identity.address
        except backups.BackupError as e:
            raise _unwritable(e) from None
        if dry_run:
            write_lines(view.dry_run_lines(result, address_used, baud))
        write_lines(view.flash_summary(result, port))
        return EXIT_OK

    finished = [None]  # the flash once it is complete: a Ctrl-C after that still says so
    run_guarded(lambda: _reporting_completion(work, finished))


def _reporting_completion(work, finished) -> int:
    """Run `work`; a Ctrl-C once the flash is complete (closing, printing) says what was done."""
    try:
        return work()
    except KeyboardInterrupt:
        if finished[0] is None:
            raise
        from mercmac.render.upload import completed_text
        from mercmac.upload.errors import FlashInterrupted

        raise FlashInterrupted(f"interrupted while showing the result; {completed_text(finished[0])}") \
            from None


def _watch(port: str, address: int | None, finished: list):
    """What `flash` shows while flashing: diagnostics, who answered, a progress bar."""
    from contextlib import contextmanager

    from mercmac.render import report as render
    from mercmac.render import upload as view
    from mercmac.render.console import write_lines
    from mercmac.upload import flasher

    searched = [False]  # no --address, nothing at 0: addresses 1-15 were searched

    class Shown(flasher.Watch):
        def refused(self, compilation) -> None:
            render.write_errors(compilation)  # on standard error, before the refusal

        def compiled(self, compilation) -> None:
            render.write_warnings(compilation)  # on standard error; the flash goes on

        @contextmanager
        def searching(self):
            with _searching() as shown:
                def probing(n: int) -> None:
                    searched[0] = True
                    shown(n)
                yield probing

        def identified(self, identity, warning) -> None:
            write_lines(view.identity_lines(port, identity.address, identity, warning,
                                            searched=searched[0]))

        @contextmanager
        def writing(self):
            with view.FlashProgress() as progress:
                yield progress

        def finished(self, result) -> None:
            finished[0] = result  # a Ctrl-C from here on still says what was done

    return Shown()


@click.command()
@click.argument("port", required=False, metavar="[PORT]")
@_PORT_OPTION
@click.option("-o", "--output", type=click.Path(dir_okay=False, allow_dash=True),
              callback=file_name, help="Write the .mcm file here instead of standard output.")
@_FIND_ADDRESS
@_BAUD
@_TIMEOUT
@click.option("--raw", is_flag=True, help="The stored macros as [MCnn] lines, even when they "
                                          "match a flash in `mercmac history`.")
def pull(port, port_option, output, address, baud, timeout, raw) -> None:
    """Read every macro of the controller on PORT into a .mcm file.

    The file passes `mercmac check`, and `mercmac flash` puts back exactly
    these macros. When they are exactly a program `mercmac flash` wrote, that
    source comes back, names and comments included (--raw: the macros as stored).
    Reading stops a running macro (MS176E §3.8.3).
    """
    def work() -> int:
        nonlocal port, address
        from mercmac.render import upload as view
        from mercmac.render.console import write_lines
        from mercmac.upload import backup, survey

        port = _port(port, port_option, "pull")
        to_file = output and output != "-"
        if to_file:
            _check_output(Path(output))  # refused before reading, which stops a running macro
        pulled = survey.pull_file(port, address=address, baud=baud, timing=_timing(timeout),
                                  searching=_searching)
        address = pulled.identity.address
        text, found = pulled.text, None
        if not raw:  # a program mercmac flashed comes back as its source (upload.history)
            found = recalled(pulled.macros, port, address, "the stored macros are given back")
            text = found.source if found else text
        if to_file:
            try:
                backup.save(text, Path(output))
            except backup.BackupError as e:
                raise UsageError(str(e)) from None
        else:
            click.echo(text, nl=False)
        err = sys.stderr
        write_lines(view.identity_lines(port, address, pulled.identity), err)
        write_lines(view.pulled_lines(pulled, port, address, output if to_file else None), err)
        if found:
            from mercmac.render.history import label

            click.echo(f"the controller holds {label(found)}: that source is given back "
                       f"(--raw for the stored macros)", err=True)
        return EXIT_OK

    run_guarded(work)


def _searching():
    """No --address: the address probed, while looking for the controller (survey.reach)."""
    from mercmac.render import upload as view

    return view.AddressProgress(sys.stderr, "no --address: looking for the controller")


def history_records() -> list:
    """The flash history's records, newest first; each file that is no record is named on
    standard error, once (upload.history.read)."""
    from mercmac.render import history as view
    from mercmac.render.console import write_lines
    from mercmac.upload import history

    shelf = history.read()
    write_lines(view.skipped_lines(shelf.skipped), sys.stderr)
    return shelf.records


def recalled(macros: dict[int, str], port: str | None, address: int | None, instead: str):
    """The history record whose source gives back `macros` (upload.history.recall), or None;
    a record of exactly this build whose source no longer builds to it is said, with `instead`."""
    from mercmac.render import history as view
    from mercmac.render.console import write_lines
    from mercmac.upload import history

    found = history.recall(macros, history_records(), port=port, address=address)
    if found.stale:
        write_lines([[("warning: ", "bold yellow"), (view.stale_text(found, instead), "")]],
                    sys.stderr)
    return found.record


def _check_output(path) -> None:
    """UsageError (exit 2) unless PATH is a regular file or a new one that can be written."""
    from mercmac.upload import backup

    try:
        backup.check(path)
    except backup.BackupError as e:
        raise _unwritable(e) from None


def _unwritable(e: Exception) -> UsageError:
    """An output path that cannot be written (exit 2)."""
    return UsageError(str(e), hint="give the path of a file to create or replace")


@click.command()
def ports() -> None:
    """List serial ports; PI USB devices (vendor 0x1A72) are marked as likely Mercury."""
    def work() -> int:
        from mercmac.render import upload as view
        from mercmac.render.console import write_lines
        from mercmac.upload import survey

        write_lines(view.ports_lines(survey.list_ports()))
        return EXIT_OK

    run_guarded(work)


@click.command()
@click.argument("port", required=False, metavar="[PORT]")
@_PORT_OPTION
@_BAUD
@click.option("--timeout", type=FiniteFloat(0.05, 60), default=0.3, show_default=True,
              help="Seconds to wait at each address.")
@click.option("--stop", is_flag=True, help="Also identify controllers that run a macro (stops it).")
def scan(port, port_option, baud, timeout, stop) -> None:
    """Which addresses 0-15 answer on PORT, with model and firmware (daisy chains, MS176E §3.2).

    Probes with `%`, which does not stop a running macro; such controllers
    are listed without firmware unless --stop is given. Exit 1 if none answers.
    On a terminal, the address being probed is shown as the scan goes.
    """
    def work() -> int:
        nonlocal port
        from mercmac.render import upload as view
        from mercmac.render.console import write_lines
        from mercmac.upload import connect, survey

        port = _port(port, port_option, "scan")
        with connect.open_controller(port, 0, baud=baud, timing=_timing(timeout)) as c, \
                view.AddressProgress(sys.stderr) as shown:
            found = survey.scan(c.transport, stop=stop, on_address=shown)
        write_lines(view.scan_lines(found, port))
        return EXIT_OK if survey.answered(found) else EXIT_FAILED

    run_guarded(work)


@click.command()
@click.option("--target", type=MODEL_CHOICE, default="C-863", show_default=True,
              help="Model the virtual controller reports.")
@_ADDRESS
@click.option("--state", type=click.Path(dir_okay=False),
              help="Keep the macros (flash memory) in this file across runs.")
@click.option("--firmware", default="2.30", show_default=True,
              help="Firmware version VE reports; 1.xx drops lines typed slower than 20 ms a character.")
@click.option("--tm-framing", type=click.Choice([f.value for f in Framing]),
              default=Framing.ETX_PER_LINE.value,
              show_default=True, help="How a TM listing ends its lines (real controllers may do either).")
@click.option("--empty-slot", type=click.Choice([e.value for e in EmptySlot]),
              default=EmptySlot.EMPTY.value,
              show_default=True, help="TMn of an empty slot: an empty report or a bare MCnnn.")
@click.option("--log", "log_file", type=click.Path(dir_okay=False),
              help="Add every byte both ways to this file, timestamped, as it passes.")
@click.option("--pace", is_flag=True,
              help="Pace the link like real hardware: bytes at --baud, firmware 1.xx's 20 ms "
                   "character gap, characters lost while a move runs.")
@click.option("--baud", type=click.IntRange(300, 921_600), default=9600, show_default=True,
              help="Baud rate the link is paced at (with --pace).")
def emulate(target, address, state, firmware, tm_framing, empty_slot, log_file, pace,
            baud) -> None:
    """Serve a virtual controller on a pseudo-terminal and print the path to open.

    Try `mercmac flash PATH FILE` without hardware; Ctrl-C stops it (exit 130).
    """
    def work() -> int:
        from contextlib import nullcontext

        from mercmac.emulator.virtual import Faults, VirtualController
        from mercmac.emulator.ptyserver import PtyServer
        from mercmac.outfile import appending, reason

        faults = Faults(tm_framing=tm_framing, empty_slot=empty_slot, pace=pace, baud=baud)
        vc = VirtualController(target.upper(), address, firmware=firmware,
                               state=Path(state) if state else None, faults=faults)
        # a device, FIFO or folder is refused here, before the pseudo-terminal exists
        with appending(log_file) if log_file else nullcontext() as log:
            try:
                server = PtyServer(vc, log)
            except OSError as e:
                raise UsageError(f"cannot create a pseudo-terminal: {reason(e)}") from None
            kept = f", macros kept in {state}" if state else ""
            paced = f", paced at {baud} baud" if pace else ""
            logged = f", bytes logged to {log_file}" if log_file else ""
            click.echo(f"virtual {vc.model} (firmware {firmware}) at address {address}"
                       f"{kept}{paced}{logged}")
            click.echo(server.path)
            try:
                server.serve_forever()
            except KeyboardInterrupt:  # the only way it ends: 130, as `scan` and `sim -i` exit
                return EXIT_INTERRUPTED
            finally:
                server.close()
        return EXIT_OK

    run_guarded(work)

