"""`mercmac examples` and `mercmac new`: files to start from, the bundled examples
(mercmac.bundled) and the starting programs (mercmac.templates). Both write through
outfile.fill: every file checked before the first is written, no symlink followed."""
from __future__ import annotations

from pathlib import Path

import click

from mercmac.cli.common import MODEL_CHOICE, UsageError, run_guarded
from mercmac.errors import EXIT_OK
from mercmac.templates import RIG_TEMPLATES, TEMPLATES

EXAMPLES_DIR = "examples"  # as the README names them: `mercmac sim examples/macros/...` works
DEFAULT_MODEL = "C-863"  # as `sim` powers on by default


@click.command()
@click.argument("folder", default=EXAMPLES_DIR, required=False, type=click.Path())
@click.option("--force", is_flag=True,
              help="Replace example files FOLDER holds already (your edits in them are lost).")
def examples(folder: str, force: bool) -> None:
    """Copy the bundled examples into FOLDER (default: ./examples, the paths the README
    uses): programs in macros/, a rig in rigs/raster/, sim scenarios in scenarios/.

    A file FOLDER holds already is not replaced (nothing is written; exit 2) unless given
    --force; a symbolic link in FOLDER is never followed, even with --force.
    """
    def work() -> int:
        from mercmac import bundled, outfile

        try:
            written = outfile.fill_tree(folder, bundled.texts(), replace=force)
        except outfile.Occupied as e:
            raise UsageError(f"{folder} holds {_listed(e.paths)} already; nothing was "
                             f"written", hint="--force replaces them (your edits in them are "
                             "lost), or give another folder") from None
        _tell_written(written, f"{len(written)} example files in {folder}:")
        return EXIT_OK

    run_guarded(work)


@click.command()
@click.argument("file", type=click.Path(dir_okay=False))
@click.option("--target", type=MODEL_CHOICE, default=DEFAULT_MODEL, show_default=True,
              help="The controller model the program is for.")
@click.option("--template", type=click.Choice(sorted(TEMPLATES)),
              help="jog (the default for FILE.mcm): buttons jog a stage; scan: a stepped "
                   "scan with a trigger pulse; raster-rig (the default for NAME.rig.toml): "
                   "a rig of two controllers, NAME.rig.toml with x.mcm and y.mcm beside it.")
def new(file: str, target: str, template: str | None) -> None:
    """Write a commented starting program, FILE.mcm, that checks clean; or, with
    --template raster-rig, a rig: NAME.rig.toml and its programs in its folder.

    Its folder is made if missing. A file that is there already is never replaced
    (nothing is written; exit 2).
    """
    def work() -> int:
        from mercmac import outfile, templates

        chosen = template or _default_template(file)
        _suits(file, chosen)
        path = Path(file)
        texts = templates.files(chosen, path.name, target.upper())
        try:
            written = outfile.fill(path.parent, texts)
        except outfile.Occupied as e:
            raise UsageError(f"{_listed(e.paths)} there already; nothing was written",
                             hint="`mercmac new` replaces no file: give another name") from None
        _tell_written(written, f"the {chosen} template for the {target.upper()} "
                               f"({TEMPLATES[chosen][0]}):")
        _next_steps(file)
        return EXIT_OK

    run_guarded(work)


def _default_template(file: str) -> str:
    """raster-rig for a rig file's name, else jog."""
    from mercmac.rig import is_rig_path

    return "raster-rig" if is_rig_path(file) else "jog"


def _suits(file: str, template: str) -> None:
    """UsageError unless FILE's name fits TEMPLATE: a rig file for a rig, a .mcm file else."""
    from mercmac.names import printable
    from mercmac.rig import is_rig_path

    if template in RIG_TEMPLATES and not is_rig_path(file):
        raise UsageError(f"--template {template} writes a rig, and '{printable(file)}' is no "
                         f"rig file's name", hint="name it NAME.rig.toml")
    if template not in RIG_TEMPLATES and not file.lower().endswith(".mcm"):
        raise UsageError(f"--template {template} writes a program, and '{printable(file)}' "
                         f"does not end in .mcm", hint="name it NAME.mcm (a rig: NAME.rig.toml "
                                                       "with --template raster-rig)")


def _listed(paths: list[Path]) -> str:
    """'a.mcm, b.mcm and c.toml': the files there already."""
    from mercmac.names import printable

    names = [printable(str(p)) for p in paths]
    return names[0] if len(names) == 1 else f"{', '.join(names[:-1])} and {names[-1]}"


def _tell_written(paths: list[Path], what: str) -> None:
    """Which files were written (standard output), under a line that says what they are."""
    from mercmac.names import printable

    click.echo(f"wrote {printable(what)}")
    for path in paths:
        click.echo(f"  {printable(str(path))}")


def _next_steps(file: str) -> None:
    """The commands to try next, as the file's own comments give them."""
    import shlex

    from mercmac.names import printable

    shown = shlex.quote(printable(file))
    click.echo(f"next: mercmac check {shown}, then mercmac sim {shown} (its comments say "
               f"which buttons to press)")
