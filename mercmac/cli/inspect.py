"""`mercmac decompile`, `describe` and `history`: what a file or a controller holds (docs/cli.md).

The macros come from a .mcm file (raw `[MCnn]` blocks such as a pull or a backup, or
a program) or from the controller on --port. A controller that holds exactly a
program mercmac flashed gets that source back (mercmac.upload.history); a file is
read for what it holds: the history names what controllers hold, not files.
"""
from __future__ import annotations

import sys
from dataclasses import dataclass, field, replace

import click

from mercmac.cli.common import UsageError, run_guarded
from mercmac.cli.upload import (_ADDRESS, _BAUD, _TIMEOUT, _timing, file_name, history_records,
                                one_port, recalled)
from mercmac.errors import EXIT_FAILED, EXIT_OK

_SOURCE = [
    click.argument("file", required=False, type=click.Path(dir_okay=False, allow_dash=True)),
    click.option("--port", multiple=True, callback=one_port,
                 help="Read the controller on this port instead of a file."),
    _ADDRESS, _BAUD, _TIMEOUT,  # the uploader's own options, used with --port
]


def _from_file_or_port(command):
    for decorate in reversed(_SOURCE):
        command = decorate(command)
    return command


class _Refused(Exception):
    """The file has errors; they are shown already (exit 1)."""


@dataclass(frozen=True, slots=True)
class Macros:
    """What was read, and from where."""

    macros: dict[int, str]
    model: str | None
    origin: str  # the file, or 'PORT, address N'
    port: str | None = None
    address: int | None = None
    names: dict[int, str] = field(default_factory=dict)  # the source's, by slot (Program.names)


def _read(file: str | None, port: str | None, address: int, baud: int, timeout: float) -> Macros:
    """The macros of FILE or of the controller on PORT; UsageError for neither or both."""
    if (file is None) == (port is None):
        raise UsageError("give a FILE or --port PORT" if file is None else
                         "give a FILE or --port PORT, not both",
                         hint="FILE is a .mcm file, such as one `mercmac pull` wrote")
    if file is not None:
        return _read_file(file)
    from mercmac.upload import survey

    pulled = survey.pull_file(port, address=address, baud=baud, timing=_timing(timeout))
    return Macros(pulled.macros, pulled.identity.version.model, f"{port}, address {address}",
                  port, address)


def _read_file(file: str) -> Macros:
    from mercmac.compiler import compile_file
    from mercmac.render import report as render

    compilation = compile_file(file)  # OSError: exit 2 with the reason
    if render.write_errors(compilation) or compilation.program is None:
        raise _Refused()
    program = compilation.program
    macros = {m.slot: m.line for m in program.macros.values()}
    return Macros(macros, program.target, compilation.source.name, names=program.names())


def _recorded(read: Macros, instead: str):
    """The history record whose source gives back what the controller on --port holds,
    said on standard error; else None (a record whose source no longer builds to it is
    said too). None for a file: it is read for what it holds, whatever was flashed."""
    from mercmac.render.history import label
    from mercmac.names import printable

    if read.port is None:
        return None
    found = recalled(read.macros, read.port, read.address, instead)
    if found:
        click.echo(f"mercmac: {printable(read.origin)} holds {label(found)}", err=True)
    return found


def _named(read: Macros) -> Macros:
    """With the names of the recorded source that builds to what the controller holds."""
    from mercmac.upload import history

    found = _recorded(read, "described with made-up names instead")
    program = history.built(found).program if found else None
    return replace(read, names=program.names()) if program else read


def _library():
    """mercmac.decompile, or UsageError when this installation has none."""
    try:
        from mercmac import decompile
    except ImportError:
        raise UsageError("this mercmac has no decompiler (mercmac.decompile is missing)",
                         hint="reinstall mercmac") from None
    return decompile


def _write(text: str, output: str | None) -> None:
    if output and output != "-":
        from mercmac import outfile

        outfile.write_text(output, text)  # whole or not at all; OutputError: exit 2
    else:
        click.echo(text, nl=False)


def _not_the_input(file: str | None, output: str | None) -> None:
    """UsageError when OUTPUT is FILE (the same file by any name): the decompiled source
    would replace the program the user wrote, its comments and names with it."""
    import os

    if not file or not output or "-" in (file, output):
        return
    try:
        same = os.path.samefile(file, output)
    except (OSError, ValueError):
        return  # one of them does not exist (yet): reading or writing says what is wrong
    if same:
        raise UsageError(f"-o {output} is the input file {file}: the decompiled source would "
                         f"replace it, and its comments would be lost",
                         hint="give another output file, or --force to replace the input")


def _guarded(work) -> None:
    def guarded() -> int:
        try:
            return work()
        except _Refused:
            return EXIT_FAILED

    run_guarded(guarded)


@click.command()
@_from_file_or_port
@click.option("-o", "--output", type=click.Path(dir_okay=False, allow_dash=True),
              callback=file_name, help="Write the source to this file instead of standard output.")
@click.option("--force", is_flag=True, help="Write the source even over FILE itself; with "
                                             "--rig, replace files DIR holds already.")
@click.option("--rig", "rig_dir", type=click.Path(file_okay=False), callback=file_name,
              help="With --port: scan the chain and write a rig folder, DIR/NAME.rig.toml and "
                   "each controller's source (as `pull --rig`): the recorded one when "
                   "`mercmac history` knows its build, else decompiled.")
def decompile(file, port, address, baud, timeout, output, force, rig_dir) -> None:
    """Turn raw macros back into high-level source that builds to exactly the same macros.

    FILE is a .mcm file of `[MCnn]` blocks (a pull, a backup); --port reads the
    controller instead. A controller that holds exactly a program `mercmac flash`
    wrote gives back that source, with its names and comments; a FILE is always
    decompiled from what it holds.
    Exit 1 when FILE has errors or nothing answers, 2 when FILE or the port cannot
    be opened.
    """
    def work() -> int:
        if rig_dir is not None:
            return _decompile_rig(file, port, output, rig_dir, baud, timeout, force)
        if not force:
            _not_the_input(file, output)  # refused before a port is read
        read = _read(file, port, address, baud, timeout)
        found = _recorded(read, "decompiled instead")
        if found:
            text = found.source
        else:
            text = _library().decompile(read.macros, model=read.model, origin=read.origin)
        _write(text if text.endswith("\n") or not text else text + "\n", output)
        return EXIT_OK

    _guarded(work)


def _decompile_rig(file, port, output, rig_dir: str, baud: int, timeout: float,
                   force: bool) -> int:
    """`decompile --port PORT --rig DIR`: `pull --rig` with decompiled sources (a program
    mercmac flashed comes back as its recorded source)."""
    from mercmac.cli.upload import pull_rig, rig_folder

    if file is not None or port is None:
        raise UsageError("--rig reads a chain: give --port PORT and no FILE",
                         hint="mercmac decompile --port PORT --rig DIR")
    given = click.get_current_context().get_parameter_source("address")
    folder = rig_folder(rig_dir, output=output,
                        address=None if given is click.core.ParameterSource.DEFAULT else 0)

    def text_of(m):
        if m.record:
            return m.record.source, "recorded source"
        text = _library().decompile(m.pulled.macros, model=m.model,
                                    origin=f"{port}, address {m.address}")
        return (text if text.endswith("\n") or not text else text + "\n"), "decompiled"

    return pull_rig(port, folder, baud, timeout, text_of, force=force)


@click.command()
@_from_file_or_port
@click.option("--format", "fmt", type=click.Choice(["text", "markdown", "json"]), default="text",
              show_default=True, help="text for people, markdown for documents, json for programs.")
@click.option("--graph", type=click.Path(dir_okay=False), callback=file_name,
              help="Also write the call graph: FILE.dot as Graphviz text, FILE.svg drawn by "
                   "Graphviz's `dot` (which must be installed).")
def describe(file, port, address, baud, timeout, fmt, graph) -> None:
    """Say what a program does: its macros, what calls what, inputs, outputs and moves.

    FILE is a .mcm file; --port reads the controller instead. Macros have the names
    the source gives them (on --port: the source `mercmac flash` recorded, when the
    controller holds exactly its build), else names made from what they do.
    A rig file (`NAME.rig.toml`) is described as a whole: each controller's program
    under its name and address, what each wire carries, and with --graph one picture
    with a cluster per controller and the wires between them.
    """
    def work() -> int:
        graph_kind = _graph_kind(graph) if graph is not None else None  # before the port is read
        library = _library()
        rig, programs = _described(file, port, address, baud, timeout)
        text = library.describe_rig(rig, programs, fmt)
        dot = library.rig_graph_dot(rig, programs) if graph is not None else None
        if graph is not None:
            _write_graph(dot, graph, graph_kind)
        click.echo(text, nl=not text.endswith("\n"))
        if graph is not None:
            from mercmac.names import printable

            click.echo(f"mercmac: call graph written to {printable(graph)}", err=True)
        return EXIT_OK

    _guarded(work)


def _described(file: str | None, port: str | None, address: int, baud: int, timeout: float):
    """The rig to describe and each controller's program as it would be stored
    (decompile.Stored, by controller name): a rig file's, or a lone program's or the
    controller's on --port as a rig of one. _Refused when `check` finds errors (shown as
    `check` shows them), as `sim` refuses them."""
    from mercmac.cli.common import opened
    from mercmac.decompile import Stored
    from mercmac.rig.model import Rig
    from mercmac.rig.open import open_any

    if port is not None or file is None:
        read = _named(_read(file, port, address, baud, timeout))
        rig = Rig.of_program(read.origin, read.model)
        return rig, {rig.controllers[0].name: Stored(read.macros, read.model, read.names)}
    accepted = opened(lambda: open_any(file))  # InputError (exit 2) when it cannot be read
    if accepted is None:
        raise _Refused()
    rig = accepted.rig
    # a rig's controller has its model; a lone program the one its `target` line names
    models = {c.name: c.model if not rig.lone else None for c in rig.controllers}
    return rig, {name: Stored({m.slot: m.line for m in c.program.macros.values()},
                              models[name] or c.program.target, c.program.names())
                 for name, c in accepted.programs.items()}


def _graph_kind(path: str) -> str:
    """'dot' or 'svg' from the name; UsageError for others, or svg without Graphviz."""
    import shutil

    kind = path.rsplit(".", 1)[-1].lower() if "." in path else ""
    if kind not in ("dot", "gv", "svg"):
        raise UsageError(f"--graph {path}: give a .dot or .svg file",
                         hint=".dot is Graphviz text; .svg is drawn by Graphviz's `dot`")
    if kind == "svg" and shutil.which("dot") is None:
        raise UsageError("--graph .svg needs Graphviz's `dot` program, which is not installed",
                         hint="install Graphviz (graphviz.org), or write a .dot file and draw "
                              "it elsewhere")
    return "svg" if kind == "svg" else "dot"


def _write_graph(dot: str, path: str, kind: str) -> None:
    from mercmac import outfile

    if kind == "dot":
        outfile.write_text(path, dot)
        return
    import shutil
    import subprocess

    try:
        drawn = subprocess.run([shutil.which("dot") or "dot", "-Tsvg"], input=dot.encode(),
                               capture_output=True, timeout=60, check=False)
    except (OSError, subprocess.SubprocessError) as e:
        raise UsageError(f"Graphviz's `dot` could not draw the call graph: {outfile.reason(e)}") \
            from None
    if drawn.returncode != 0:
        said = drawn.stderr.decode(errors="replace").strip()[:300]
        raise UsageError(f"Graphviz's `dot` could not draw the call graph: {said}")
    with outfile.replacing(path, binary=True) as f:
        f.write(drawn.stdout)


@click.command()
@click.option("--format", "fmt", type=click.Choice(["text", "json"]), default="text",
              show_default=True, help="A table for people, or JSON.")
def history(fmt) -> None:
    """List what `mercmac flash` wrote where, newest first.

    Records are kept in the per-user data directory (or $MERCMAC_DATA_DIR), beside
    the backups.
    """
    def work() -> int:
        from mercmac.render import history as view
        from mercmac.render.console import write_lines

        found = history_records()  # a file that is no record is named on standard error
        if fmt == "json":
            click.echo(view.to_json(found))
        else:
            write_lines(view.table_lines(found), sys.stdout)
        return EXIT_OK

    run_guarded(work)
