"""The `mercmac` command: a thin click layer over the importable API (SPEC §5).

Commands parse options and call the library; `run_guarded` is the one place
that turns exceptions into a message and an exit code.
"""
from __future__ import annotations

import click

from mercmac import __version__
from mercmac.cli.common import MODEL_CHOICE, run_guarded, say
from mercmac.errors import EXIT_FAILED, EXIT_OK, EXIT_USAGE


class _Commands(click.Group):
    """The group: compiler commands here, the simulator's and the uploader's imported
    only when used (click's lazy-loading pattern), to keep `check` quick to start."""

    LAZY = {
        "sim": ("mercmac.cli.sim", "sim"),
        "flash": ("mercmac.cli.upload", "flash"),
        "pull": ("mercmac.cli.upload", "pull"),
        "ports": ("mercmac.cli.upload", "ports"),
        "scan": ("mercmac.cli.upload", "scan"),
        "emulate": ("mercmac.cli.upload", "emulate"),
    }

    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted([*super().list_commands(ctx), *self.LAZY])

    def get_command(self, ctx: click.Context, name: str) -> click.Command | None:
        if name in self.LAZY:
            import importlib

            module, attribute = self.LAZY[name]
            return getattr(importlib.import_module(module), attribute)
        return super().get_command(ctx, name)


@click.group(cls=_Commands, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="mercmac")
def main() -> None:
    """Write, check, simulate and upload stand-alone macro programs for
    PI Mercury C-663 / C-863 controllers."""


@main.command()
@click.argument("files", nargs=-1, required=True, type=click.Path(dir_okay=False, allow_dash=True))
@click.option("--target", type=MODEL_CHOICE, help="Controller model; overrides the file's `target`.")
@click.option("--format", "fmt", type=click.Choice(["text", "json"]), default="text",
              show_default=True, help="Output for people or for programs.")
@click.option("--max-diagnostics", "limit", type=click.IntRange(min=0), metavar="N",
              help="Show at most N diagnostics per file, errors first; 0 shows all. Default: "
                   "200 in text (a closing line counts the rest), 10000 in JSON (which then "
                   'adds "truncated": {FILE: count left out}). The summary counts them all.')
def check(files: tuple[str, ...], target: str | None, fmt: str, limit: int | None) -> None:
    """Check .mcm files against the firmware's rules.

    Exit 0 when no errors are found, 1 when there are errors, 2 when a file
    cannot be read.
    """
    def work() -> int:
        from mercmac.render import report as render
        from mercmac.source import read_source

        results, unreadable = [], 0
        for f in files:
            try:
                source = read_source(f)
            except OSError as e:
                from mercmac.outfile import reason

                say(f"cannot read {f}: {reason(e)}")
                unreadable += 1
                continue
            results.append(_check_one(source, target))
        if not results:
            return EXIT_USAGE
        found = [d for r in results for d in r.report.items]
        if fmt == "json":
            click.echo(render.to_json(found, render.MAX_JSON if limit is None else limit))
        else:
            render.write_text(found, {r.source.name: r.source for r in results}, len(results),
                              limit=render.MAX_TEXT if limit is None else limit)
        if unreadable:
            return EXIT_USAGE
        return EXIT_FAILED if any(r.report.has_errors for r in results) else EXIT_OK

    run_guarded(work)


def _check_one(source, target: str | None):
    """Compile one file; a compiler bug becomes an error on that file, and the others go on."""
    from mercmac.compiler import Compilation, compile_source
    from mercmac.diagnostics import Report
    from mercmac.source import Span

    from mercmac.compiler.parse import paused_gc

    try:
        with paused_gc():
            return compile_source(source, target=target)
    except Exception as e:  # last resort (issue 7): never a traceback, never lose the other files
        report = Report(source.name)
        try:
            detail = f"{type(e).__name__}: {e}"
        except Exception:  # an exception whose text cannot be made
            detail = type(e).__name__
        detail = detail if len(detail) <= 200 else detail[:200] + "..."
        report.add("syntax", Span(1, 1, 1, 2), "internal", detail=detail)
        return Compilation(source, report, None)


@main.command()
@click.argument("file", type=click.Path(dir_okay=False, allow_dash=True))
@click.option("-o", "--output", type=click.Path(dir_okay=False, allow_dash=True),
              help="Write the MD lines to this file instead of standard output.")
@click.option("--target", type=MODEL_CHOICE, help="Controller model; overrides the file's `target`.")
def build(file: str, output: str | None, target: str | None) -> None:
    """Print the MD lines that go to the controller: slot order, macro 0 last.

    Refuses (exit 1, diagnostics on standard error) when the file has errors.
    """
    def work() -> int:
        from mercmac.compiler import compile_file
        from mercmac.render import report as render

        result = compile_file(file, target=target)
        if render.write_errors(result):
            return EXIT_FAILED
        text = "".join(line + "\n" for line in result.program.md_lines())
        if output and output != "-":
            from mercmac import outfile

            outfile.write_text(output, text, encoding="ascii")  # whole or not at all; OutputError: 2
        else:
            click.echo(text, nl=False)
        return EXIT_OK

    run_guarded(work)


@main.command()
@click.argument("key", required=False)
def explain(key: str | None) -> None:
    """Explain a rule by code (MM011) or name (nested-call); list them all without one."""
    def work() -> int:
        from mercmac.render.explain import write_explanation, write_rule_list

        if key is None:
            write_rule_list()
        else:
            write_explanation(key)
        return EXIT_OK

    run_guarded(work)
