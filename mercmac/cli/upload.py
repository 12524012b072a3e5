"""`mercmac flash`, `pull`, `ports`, `scan` and `emulate`: thin click commands
(docs/uploader.md, docs/cli.md).

The serial library, rich and the uploader are imported inside the command
bodies so that `mercmac check` starts fast.
"""
from __future__ import annotations

import sys
from pathlib import Path

import click

from mercmac.cli.common import MODEL_CHOICE, FiniteFloat, UsageError, run_guarded
from mercmac.emulator.faults import EmptySlot, Framing  # two enums: light to import
from mercmac.errors import (EXIT_FAILED, EXIT_OK, InputError, MercmacError, exit_code_for,
                            signal_of)

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
                        show_default=True,
                        help="Seconds to wait for each reply; given, also the wait at each "
                             "address when looking for controllers (default 0.3 there).")


def looks_like_program(text: str) -> bool:
    """A `.mcm` name, or an existing regular file: not a port (devices are not regular files)."""
    if text.lower().endswith((".mcm", ".rig.toml")):
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
    from mercmac.names import printable
    from mercmac.upload import ports as chooser

    chosen = chooser.resolve(check_port_arg(port, option, command))
    if chosen.how:
        click.echo(f"port: {printable(chosen.port)} ({chosen.how})", err=True)
    return chosen.port


def _timing(timeout: float):
    """The Timing of this command's --timeout; given on the command line (not defaulted),
    it is also the wait at each address of a search (pull --rig, flash without --address)."""
    from mercmac.upload.transport import Timing

    context = click.get_current_context(silent=True)
    given = context is not None and context.get_parameter_source("timeout") in (
        click.core.ParameterSource.COMMANDLINE, click.core.ParameterSource.ENVIRONMENT)
    return Timing.waiting(timeout, searching_too=given)


@click.command()
@click.argument("port", required=False, metavar="[PORT]")
@click.argument("file", required=False, metavar="FILE",
                type=click.Path(dir_okay=False, allow_dash=True))
@_PORT_OPTION
@_FIND_ADDRESS
@_BAUD
@click.option("--dry-run", is_flag=True, help="Read back and show the exact bytes; write nothing.")
@click.option("--backup", type=click.Path(writable=True), callback=file_name,
              help="Where to save what the controller holds (default: a timestamped file "
                   "in the per-user data directory). For a rig: a folder (FOLDER/RIG-NAME.mcm "
                   "each) or a prefix (PREFIX-NAME.mcm each).")
@click.option("--erase-unused", is_flag=True, help="Remove stored macros the file does not define.")
@click.option("--reset", is_flag=True, help="Send RT afterwards so that macro 0 starts.")
@click.option("--force", is_flag=True, help="Flash even if the controller is not the file's target.")
@click.option("--target", type=MODEL_CHOICE, help="Controller model; overrides the file's `target`.")
@click.option("--only", multiple=True, callback=lambda ctx, param, v: only_names(v),
              metavar="NAME,..", help="For a rig: flash only these controllers (names from "
                                      "the rig file): comma-separated or repeated.")
@_TIMEOUT
def flash(port, file, port_option, address, baud, dry_run, backup, erase_unused, reset, force,
          target, only, timeout) -> None:
    """Upload FILE to the controller on PORT: back up, write what differs, verify.

    PORT is anything pyserial opens: COM3, /dev/ttyUSB0, a pty path,
    socket://host:port. Without it: -p PORT, $MERCMAC_PORT, or the only likely
    Mercury port. Exit 0 only when every written macro reads back right.
    FILE may be a rig (NAME.rig.toml): every controller at its address, in one run.
    """
    def work() -> int:
        from mercmac.render import upload as view
        from mercmac.upload import flasher

        given, path = split_flash_args(port, file, port_option)
        _rig_flash_options(path, only, force=force, target=target)
        where = _port(given, port_option, "flash")
        options = flasher.FlashOptions(erase_unused, dry_run, reset, backup)
        shown = view.FlashShown(where)
        try:
            return _flash(where, path, shown, options, baud, timeout, address=address,
                          target=target, force=force, only=only)
        except KeyboardInterrupt as e:
            if shown.done is None:
                raise
            from mercmac.upload.errors import FlashInterrupted

            raise FlashInterrupted("interrupted while showing the result; "
                                   f"{view.completed_text(shown.done)}", by=e) from None

    run_guarded(work)


def _flash(port: str, path: str, shown, options, baud: int, timeout: float, **asked) -> int:
    """Flash the program file or rig PATH (upload.chain), shown by SHOWN; then the dry run's
    bytes and the summary. `asked`: --address, --target, --force, --only."""
    from mercmac.render import upload as view
    from mercmac.render.console import write_lines
    from mercmac.upload import backup as backups
    from mercmac.upload import chain

    try:
        flash = chain.flash_chain(port, path, baud=baud, timing=_timing(timeout),
                                  options=options, watch=shown, **asked)
    except backups.BackupError as e:
        raise _unwritable(e) from None
    if options.dry_run:
        write_lines(view.dry_run_lines(flash, baud))
    write_lines(view.flash_summary(flash, port))
    return EXIT_OK


def only_names(values: tuple[str, ...]) -> list[str] | None:
    """`--only x,y` or `--only x --only y` (as `check --select`): every name, each once;
    None when not given."""
    if not values:
        return None
    names = []
    for value in values:
        names += [n.strip() for n in value.split(",")]
        if not all(names):
            raise click.BadParameter(f"{value!r} has an empty name: give names such as x,y")
    return list(dict.fromkeys(names))


def _rig_flash_options(file: str, only, *, force: bool, target) -> None:
    """UsageError for options that do not go with a rig (or without one)."""
    from mercmac.rig import is_rig_path

    if not is_rig_path(file):
        if only is not None:
            raise UsageError("--only chooses controllers of a rig; FILE is no rig file",
                             hint="mercmac flash [PORT] NAME.rig.toml --only x,y")
        return
    given = click.get_current_context().get_parameter_source
    default = click.core.ParameterSource.DEFAULT
    for name, used in (("--address", given("address") is not default), ("--force", force),
                       ("--target", target is not None)):
        if used:
            raise UsageError(f"{name} does not go with a rig: the rig file gives each "
                             f"controller's address and model", hint=f"edit {file}")


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
@click.option("--rig", "rig_dir", type=click.Path(file_okay=False), callback=file_name,
              help="Scan the chain and write a rig folder: DIR/NAME.rig.toml and a .mcm per "
                   "controller that answers (names from `mercmac history` when known).")
@click.option("--force", is_flag=True, help="With --rig: replace files DIR holds already.")
def pull(port, port_option, output, address, baud, timeout, raw, rig_dir, force) -> None:
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

        if rig_dir is not None:
            folder = rig_folder(rig_dir, output=output, address=address)
            port = _port(port, port_option, "pull")
            return pull_rig(port, folder, baud, timeout,
                            lambda m: (m.pulled.text, "stored macros") if raw or not m.record
                            else (m.record.source, "recorded source"), force=force)
        if force:
            raise UsageError("--force goes with --rig: it replaces files the rig folder holds",
                             hint="`pull -o FILE` replaces FILE without it")
        port = _port(port, port_option, "pull")
        to_file = output and output != "-"
        if to_file:
            _check_output(Path(output))  # refused before reading, which stops a running macro
        pulled = survey.pull_file(port, address=address, baud=baud, timing=_timing(timeout),
                                  searching=view.looking_for_address)
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


def rig_folder(rig_dir: str, *, output: str | None, address: int | None) -> Path:
    """The folder `--rig DIR` writes to, refused before a controller is read (reading stops a
    running macro) when it cannot be made or written; UsageError for options that do not go
    with it."""
    from mercmac import outfile

    for name, used in (("-o", output is not None), ("--address", address is not None)):
        if used:
            raise UsageError(f"{name} does not go with --rig: the rig folder gets a file per "
                             f"controller that answers", hint="mercmac pull [PORT] --rig DIR")
    folder = Path(rig_dir).absolute()
    try:
        return outfile.writable_folder(folder, doing=f"--rig {rig_dir}")  # made when written
    except outfile.OutputError as e:
        raise UsageError(e.message, hint="give a folder that can be written (it is made if "
                                         "missing)") from None


def pull_rig(port: str, folder: Path, baud: int, timeout: float, text_of, *,
             force: bool = False) -> int:
    """Scan PORT, read every controller, write FOLDER/NAME.rig.toml and NAME.mcm for each;
    `text_of(member)`: a controller's .mcm text (stored macros, source, decompiled) and
    what it is, for the table. The rig file has the wires, box and joystick of the rig
    flashed to the chain when that file still matches it (upload.rig.recorded_wiring). Every
    file is checked before the first is written; one that is there already is replaced only
    with FORCE (docs/rigs.md), a symlink never."""
    from mercmac import outfile
    from mercmac.render import upload as view
    from mercmac.render.console import write_lines
    from mercmac.upload import rig

    with view.AddressProgress(sys.stderr) as shown:
        members = rig.pull_rig(port, baud=baud, timing=_timing(timeout),
                               records=history_records(), on_address=shown)
    name = rig.rig_name(members, folder)
    made = [text_of(m) for m in members]
    texts = {f"{m.name}.mcm": text for m, (text, _) in zip(members, made)}
    wiring = rig.recorded_wiring(members)  # read before DIR's own rig file may be replaced
    texts[f"{name}.rig.toml"] = rig.rig_text(name, members, port, wiring)
    try:
        outfile.fill(folder, texts, replace=force)
    except outfile.Occupied as e:
        raise UsageError(f"--rig {folder}: it holds {_listed(e.paths)} already; nothing was "
                         f"written", hint="--force replaces them (your edits in them are lost)") \
            from None
    rig_file = folder / f"{name}.rig.toml"
    write_lines(view.pulled_rig_lines(members, port, rig_file, [how for _, how in made],
                                      _checked(rig_file), wiring), sys.stderr)
    return EXIT_OK


def _checked(rig_file: Path) -> list | str:
    """What `check` finds in the rig just written, read back as every command reads a rig
    (rig.open): its diagnostics, so that the table says whether the folder checks clean (a
    controller whose VE names no model mercmac knows has none in the rig file); or why it
    could not be checked (a settings file above the folder that `check` refuses): the pull
    itself is done."""
    from mercmac.rig.open import open_rig

    try:
        return [d for found in open_rig(str(rig_file)).findings for d in found.diagnostics]
    except MercmacError as e:
        return e.message


def _listed(paths: list[Path]) -> str:
    """'x.mcm, y.mcm and r.rig.toml': the files a folder holds already, by name."""
    names = [p.name for p in paths]
    return names[0] if len(names) == 1 else f"{', '.join(names[:-1])} and {names[-1]}"


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
    return UsageError(str(e), hint=getattr(e, "hint", None)
                      or "give the path of a file to create or replace")


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


def address_list(ctx, param, value: str | None) -> tuple[int, ...] | None:
    """`--addresses 0,1,2`: distinct addresses 0-15 (DIP switches 1-4, MS176E §3.1.3)."""
    if value is None:
        return None
    try:
        addresses = tuple(int(part, 10) for part in value.split(","))
    except ValueError:
        raise click.BadParameter(f"{value!r} is not a comma-separated list of numbers "
                                 "(e.g. 0,1,2)") from None
    if bad := [a for a in addresses if not 0 <= a <= 15]:
        raise click.BadParameter(f"address {bad[0]} is not 0-15 (MS176E §3.1.3)")
    if len(set(addresses)) != len(addresses):
        raise click.BadParameter(f"{value!r} names an address twice: each controller of a "
                                 "chain has its own (MS176E §3.1)")
    return addresses


@click.command()
@click.option("--target", type=MODEL_CHOICE, default="C-863", show_default=True,
              help="Model the virtual controller reports (every one, with --addresses).")
@_ADDRESS
@click.option("--addresses", callback=address_list, metavar="0,1,..",
              help="Serve a daisy chain instead: a controller at each address, all on the one "
                   "pty; only the selected one answers, every one runs its macros (MS176E §3.2).")
@click.option("--rig", "rig_path", type=click.Path(dir_okay=False), metavar="RIG.rig.toml",
              help="Serve the rig's chain: each controller at its address with its model, "
                   "empty, and the rig's wires live between them (the box is not plugged in).")
@click.option("--state", type=click.Path(),
              help="Keep the macros (flash memory) across runs: in this file; for a chain "
                   "(--addresses, --rig) in this folder, one ADDRESS.json (with --rig NAME.json) "
                   "per controller.")
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
def emulate(target, address, addresses, rig_path, state, firmware, tm_framing, empty_slot,
            log_file, pace, baud) -> None:
    """Serve a virtual controller on a pseudo-terminal and print the path to open.

    Try `mercmac flash PATH FILE` without hardware; Ctrl-C stops it (exit 130).
    With --addresses or --rig, a daisy chain on the one pty: Ctrl-A (0x01) and the address
    as one hex digit select a controller (MS176E §3.1.1, §3.1.3).
    """
    def work() -> int:
        from contextlib import nullcontext

        from mercmac.emulator.virtual import Faults
        from mercmac.emulator.ptyserver import PtyServer
        from mercmac.names import printable
        from mercmac.outfile import appending, reason

        faults = Faults(tm_framing=tm_framing, empty_slot=empty_slot, pace=pace, baud=baud)
        served = _virtual(target.upper(), address, addresses, rig_path, firmware=firmware,
                          faults=faults, state=Path(state) if state else None)
        # a device, FIFO or folder is refused here, before the pseudo-terminal exists
        with appending(log_file) if log_file else nullcontext() as log:
            try:
                server = PtyServer(served, log)
            except OSError as e:
                raise UsageError(f"cannot create a pseudo-terminal: {reason(e)}") from None
            kept = f", macros kept in {printable(state)}" if state else ""
            paced = f", paced at {baud} baud" if pace else ""
            logged = f", bytes logged to {printable(log_file)}" if log_file else ""
            click.echo(f"{_served(served, firmware, one=addresses is None and rig_path is None)}"
                       f"{kept}{paced}{logged}")
            click.echo(server.path)
            try:
                server.serve_forever()
            except KeyboardInterrupt as e:  # the only way it ends (128+N), as `scan` and `sim -i`
                return exit_code_for(signal_of(e))
            finally:
                server.close()
        return EXIT_OK

    run_guarded(work)


def _virtual(model: str, address: int, addresses: tuple[int, ...] | None, rig_path: str | None,
             **kw):
    """What `emulate` serves: a chain of one controller, a chain at --addresses, or a --rig's
    chain."""
    from mercmac.emulator import chain

    given = click.get_current_context().get_parameter_source
    chosen = [name for name, param in (("--addresses", "addresses"), ("--rig", "rig_path"),
                                       ("--address", "address"))
              if given(param) is not click.core.ParameterSource.DEFAULT]
    if len(chosen) > 1:
        raise UsageError(f"{' and '.join(chosen)} both given", hint="give one of them")
    if rig_path is not None:
        if given("target") is not click.core.ParameterSource.DEFAULT:
            raise UsageError("--target and --rig both given: the rig file names each "
                             "controller's model", hint="leave out --target")
        return chain.for_rig(_emulated_rig(rig_path), **kw)
    if addresses is not None:
        return chain.at_addresses(addresses, model, **kw)
    return chain.of_one(model, address, **kw)


def _emulated_rig(path: str):
    """The rig at PATH when `check` finds no errors in it (docs/rigs.md); else what `check`
    finds is shown as `check` shows it, and nothing is served (exit 1, as `sim RIG`)."""
    from mercmac.render.report import write_findings
    from mercmac.rig.open import ProgramsUnread, RigRefused, accept

    try:
        return accept(path).rig
    except RigRefused as e:
        write_findings(e.findings, sys.stderr)
        kind = InputError if isinstance(e, ProgramsUnread) else MercmacError  # exit 2 / 1
        raise kind(f"--rig: {e.message}; nothing is served", hint=e.hint) from None


def _served(chain, firmware: str, *, one: bool) -> str:
    """The first line `emulate` prints: what is served, at which addresses; `one`: the one
    controller of --address, not a chain (--addresses, --rig) however long."""
    if one:
        c = chain.controllers[0]
        return f"virtual {c.model} (firmware {firmware}) at address {c.address}"
    return f"virtual chain (firmware {firmware}): " + ", ".join(
        f"{c.model} at address {chain.label(c.address)}" for c in chain.controllers)
