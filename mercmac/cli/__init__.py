"""The `mercmac` command: a thin click layer over the importable API (docs/cli.md).

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
        "lsp": ("mercmac.cli.lsp", "lsp"),
        "decompile": ("mercmac.cli.inspect", "decompile"),
        "describe": ("mercmac.cli.inspect", "describe"),
        "history": ("mercmac.cli.inspect", "history"),
        "examples": ("mercmac.cli.scaffold", "examples"),
        "new": ("mercmac.cli.scaffold", "new"),
    }

    # Words people try for a command, and the command they mean (`mercmac simulate`).
    SYNONYMS = {"simulate": "sim", "simulation": "sim", "upload": "flash", "write": "flash",
                "program": "flash", "download": "pull", "read": "pull", "lint": "check",
                "format": "fmt", "compile": "build", "mnemonics": "commands"}

    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted([*super().list_commands(ctx), *self.LAZY])

    def parse_args(self, ctx: click.Context, args: list[str]) -> list[str]:
        if not args and not ctx.resilient_parsing:  # bare `mercmac`: the help, no error
            click.echo(ctx.get_help())
            ctx.exit(EXIT_OK)
        return super().parse_args(ctx, args)

    def resolve_command(self, ctx: click.Context, args: list[str]):
        name = args[0]
        if not name.startswith("-") and not ctx.resilient_parsing \
                and self.get_command(ctx, name) is None:
            raise click.UsageError(f"No such command {name!r}.{self._meant(ctx, name)}", ctx=ctx)
        return super().resolve_command(ctx, args)

    def _meant(self, ctx: click.Context, name: str) -> str:
        """' Did you mean 'sim'?' for a synonym or a misspelling of a command; else ''."""
        from mercmac.suggest import did_you_mean, question

        synonym = self.SYNONYMS.get(name.lower())
        said = question(synonym) if synonym else (
            did_you_mean(name, self.list_commands(ctx)) if len(name) <= 40 else "")
        return f" {said[:1].upper()}{said[1:]}" if said else ""  # a sentence, as click's own

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


FORMATS = ["text", "json", "github", "sarif", "concise"]


@main.command()
@click.argument("files", nargs=-1, required=True, type=click.Path(allow_dash=True))
@click.option("--target", type=MODEL_CHOICE, help="Controller model; overrides the file's `target`.")
@click.option("--output-format", "--format", "fmt", type=click.Choice(FORMATS), default="text",
              show_default=True, help="text or concise for people; json or sarif for programs; "
                                      "github for annotations in GitHub Actions.")
@click.option("--select", multiple=True, metavar="RULES",
              help="Report only these rules: codes or names, comma-separated or repeated.")
@click.option("--ignore", multiple=True, metavar="RULES",
              help="Never report these rules: codes or names, comma-separated or repeated.")
@click.option("--statistics", is_flag=True,
              help="Count the diagnostics of each rule instead of showing them.")
@click.option("--warnings-as-errors", is_flag=True, help="Exit 1 on warnings too.")
@click.option("--max-diagnostics", "limit", type=click.IntRange(min=0), metavar="N",
              help="Show at most N diagnostics per file, errors first; 0 shows all. Default: "
                   "200 in text and concise (a closing line counts the rest), 10000 in the "
                   "others (JSON then "
                   'adds "truncated": {FILE: count left out}). The summary counts them all.')
@click.option("--fix", is_flag=True,
              help="Apply the safe fixes (a misspelled keyword; a macro or const name with one "
                   "candidate; a missing `target` when --target or the settings name the "
                   "model), then report what remains.")
@click.option("--unsafe-fixes", "unsafe", is_flag=True,
              help="With --fix or --diff, apply the unsafe fixes too: guesses such as another "
                   "command for an unknown one, or the nearest of several names.")
@click.option("--diff", is_flag=True,
              help="Print the fixes as a unified diff and write nothing; exit 1 if a file "
                   "would change.")
def check(files: tuple[str, ...], target: str | None, fmt: str, select: tuple[str, ...],
          ignore: tuple[str, ...], statistics: bool, warnings_as_errors: bool,
          limit: int | None, fix: bool, unsafe: bool, diff: bool) -> None:
    """Check .mcm files, or every .mcm file below a folder, against the firmware's rules.

    A rig file (NAME.rig.toml: several controllers on one chain, README "Rigs") is checked
    as a whole: the file itself, the rig rules (MR...), and each program with its
    controller's model.

    Settings (target, select, ignore) come from `[tool.mercmac]` in pyproject.toml or
    from mercmac.toml, found upward from each file; options override them.
    `// mercmac: ignore[RULE, ...]` on a line turns those rules off there.

    --fix rewrites each file with its safe fixes, whole or not at all (its encoding,
    byte-order mark and line ends kept), says on standard error which fixes it made in
    which file, and reports the problems that remain. A safe fix surely keeps what the
    program means; a guess (`XM 1` -> `EM 1`: another command) is unsafe and waits for
    --unsafe-fixes. The JSON and SARIF outputs give each fix with its applicability.

    Exit 0 when no errors are found, 1 when there are errors (or warnings, with
    --warnings-as-errors), 2 when a file cannot be read (or fixed) or an option or
    setting is wrong.
    """
    def work() -> int:
        from mercmac.compiler import checking
        from mercmac.diagnostics import Severity

        chosen = checking.options(target, select or None, ignore or None)
        fixes = _fixes(files, fix, diff, unsafe)
        paths, unreadable = _expand(files)
        results, found = [], []
        for f in paths:
            try:
                checked, unread = _check_file(f, chosen, fixes)
            except OSError as e:
                from mercmac.names import printable
                from mercmac.outfile import reason

                say(f"cannot read {printable(f)}: {reason(e)}")
                unreadable += 1
                continue
            results += [findings.compilation for findings in checked]
            found += [d for findings in checked for d in findings.diagnostics]
            unreadable += unread
        if not results:
            return EXIT_USAGE
        if fixes is not None:
            fixes.summary()
        if diff:  # the diff is the output
            return EXIT_USAGE if unreadable else fixes.diff_exit_code()
        from mercmac.compiler.parse import paused_gc

        with paused_gc():  # each collection would rescan every diagnostic (1 MB: 250,000)
            _show(found, results, fmt, statistics, limit)
        if unreadable or (fixes is not None and fixes.refused):
            return EXIT_USAGE
        failing = {Severity.ERROR, Severity.WARNING} if warnings_as_errors else {Severity.ERROR}
        return EXIT_FAILED if any(d.severity in failing for d in found) else EXIT_OK

    run_guarded(work)


def _expand(arguments: tuple[str, ...]) -> tuple[list[str], int]:
    """The files the arguments name (mercmac.files); each skipped file or folder and each
    folder without .mcm files said, and counted: they make the exit code 2."""
    from mercmac.files import named_files
    from mercmac.names import printable

    named = named_files(arguments)
    for path, why in named.skipped:
        say(f"skipped {printable(path)}: {why}")
    for folder in named.empty:
        say(f"no .mcm files in {printable(folder)}")
    return named.files, len(named.skipped) + len(named.empty)


def _fixes(files: tuple[str, ...], fix: bool, diff: bool, unsafe: bool):
    """The fixing of this run (mercmac.cli.fixes), or None when it only checks."""
    from mercmac.cli.common import UsageError

    if not (fix or diff):
        if unsafe:
            raise UsageError("--unsafe-fixes goes with --fix or --diff: it adds the unsafe "
                             "fixes to those they make",
                             hint="mercmac check --diff --unsafe-fixes FILE shows them")
        return None
    if "-" in files and not diff:
        raise UsageError("--fix writes the fixed files back, and standard input is no file",
                         hint="use --diff to see its fixes")
    from mercmac.cli.fixes import Fixes

    return Fixes(diff, unsafe)


def _check_file(path: str, chosen, fixes=None) -> tuple[list, int]:
    """What `check` reports on one file, as Findings per file checked, and how many programs
    it names could not be read (each makes the exit code 2): the language server's check
    (mercmac.compiler.checking), after the file is fixed when `fixes` (--fix, --diff); for a
    rig file its own findings and its programs' (mercmac.rig.open); OSError when it cannot
    be read."""
    from mercmac.compiler import checking
    from mercmac.errors import SettingsError
    from mercmac.names import printable
    from mercmac.rig import is_rig_path

    try:
        if is_rig_path(path):
            return _check_rig(path, chosen, fixes)
        return [fixes.file(path, chosen) if fixes is not None
                else checking.check_file(path, chosen)], 0
    except SettingsError as e:  # it names a settings file, whose path may hold any character
        raise SettingsError(printable(e.message), hint=e.hint) from None


def _check_rig(path: str, chosen, fixes) -> tuple[list, int]:
    """A rig file's findings and its programs' (mercmac.rig.open); --fix takes .mcm files.
    A rig file that cannot be read is said as any file is (no findings, one unread)."""
    from mercmac.cli.common import UsageError
    from mercmac.names import printable
    from mercmac.rig.open import RigUnreadable, open_rig

    if fixes is not None:
        raise UsageError(f"--fix and --diff take .mcm files, and {printable(path)} is a rig file",
                         hint="give the rig's programs to fix them")
    try:
        opened = open_rig(path, chosen)
    except RigUnreadable as e:
        say(e.message)
        return [], 1
    return opened.findings, opened.unread


def _show(found, results, fmt: str, statistics: bool, limit: int | None) -> None:
    """Write the diagnostics (or their counts) in the chosen format."""
    from mercmac.render import report as render

    cap = (render.MAX_TEXT if fmt in ("text", "concise") else render.MAX_JSON) if limit is None else limit
    if statistics and fmt == "json":
        click.echo(render.statistics_json(found))
    elif statistics:
        render.write_statistics(found, len(results))
    elif fmt == "json":
        click.echo(render.to_json(found, cap))
    elif fmt == "sarif":
        click.echo(render.to_sarif(found, cap))
    elif fmt == "github":
        click.echo(render.to_github(found, cap), nl=False)
    elif fmt == "concise":
        render.write_concise(found, len(results), limit=cap)
    else:
        render.write_text(found, {r.source.name: r.source for r in results}, len(results),
                          limit=cap)


@main.command()
@click.argument("file", type=click.Path(dir_okay=False, allow_dash=True))
@click.option("-o", "--output", type=click.Path(dir_okay=False, allow_dash=True),
              help="Write the MD lines to this file instead of standard output.")
@click.option("--target", type=MODEL_CHOICE, help="Controller model; overrides the file's `target`.")
def build(file: str, output: str | None, target: str | None) -> None:
    """Print the MD lines that go to the controller: slot order, macro 0 last.

    Refuses (exit 1, diagnostics on standard error) when the file has errors;
    warnings are shown on standard error and the build goes on. FILE is one program:
    a rig file is refused (exit 2), naming its programs to build one by one.
    """
    def work() -> int:
        from mercmac.compiler import compile_file
        from mercmac.render import report as render
        from mercmac.rig import is_rig_path

        if is_rig_path(file):
            _refuse_rig_build(file)
        result = compile_file(file, target=target)
        if render.write_errors(result):
            return EXIT_FAILED
        render.write_warnings(result)  # on standard error: the MD lines stay clean
        text = "".join(line + "\n" for line in result.program.md_lines())
        if output and output != "-":
            from mercmac import outfile

            outfile.write_text(output, text, encoding="ascii")  # whole or not at all; OutputError: 2
        else:
            click.echo(text, nl=False)
        return EXIT_OK

    run_guarded(work)


def _refuse_rig_build(path: str) -> None:
    """UsageError: `build` writes one controller's MD lines to one output, and a rig has a
    program per controller (`flash RIG` writes them all); the hint names the programs."""
    import shlex

    from mercmac.cli.common import UsageError
    from mercmac.names import printable
    from mercmac.rig.load import read_rig

    try:
        rig = read_rig(path).rig
    except OSError:  # named, not read: the refusal does not depend on the file
        rig = None
    builds = [f"mercmac build {shlex.quote(_shorter(c.program))}" for c in rig.controllers] \
        if rig is not None else []
    hint = (f"build its programs one by one: {'; '.join(builds)}" if builds
            else f"`mercmac check {path}` says what is wrong with the rig")
    raise UsageError(f"build takes one program (a .mcm file), and {printable(path)} is a rig "
                     "file", hint=printable(hint))


def _shorter(path: str) -> str:
    """PATH relative to the working folder when that is shorter (a rig's programs are
    absolute paths)."""
    import os

    try:
        relative = os.path.relpath(path)
    except ValueError:  # another drive (Windows)
        return path
    return relative if len(relative) < len(path) else path


@main.command()
@click.argument("key", required=False)
def explain(key: str | None) -> None:
    """Explain a rule by code (MM011) or name (nested-call), a native command by its
    mnemonic (MR, cn) or a keyword of the language (when); list the rules without one
    (`mercmac commands` lists the commands)."""
    def work() -> int:
        from mercmac.render.explain import write_explanation, write_rule_list

        if key is None:
            write_rule_list()
        else:
            write_explanation(key)
        return EXIT_OK

    run_guarded(work)


@main.command("commands")
@click.argument("words", nargs=-1)
@click.option("--model", type=MODEL_CHOICE, help="Only the commands this model knows.")
def commands_command(words: tuple[str, ...], model: str | None) -> None:
    """List the controller's native commands (MS176E §6), or those that WORDS describe:
    `mercmac commands led`, `mercmac commands wait`, `mercmac commands velocity`.

    A word matches a mnemonic, a word of a command's description (or its start), or a
    word people write for a command (`sleep`: WA); the best matches come first.
    `mercmac explain MR` tells one command. Exit 0 when commands are listed, 1 when no
    command matches (as grep does).
    """
    def work() -> int:
        from mercmac.commands import search
        from mercmac.compiler import guesses
        from mercmac.render.commands import write_list
        from mercmac.names import printable

        found = search(words, model, guesses.POINTS_TO)
        # a word no description has (`sleep`): say what people mean by it
        said = [f"{w}: {guesses.hint(w)}" for w in words if guesses.hint(w) and not search([w])]
        if not found:
            say(f"no command{' of the ' + model if model else ''} mentions "
                f"'{printable(' '.join(words))}'", "; ".join(said) or
                "`mercmac commands` lists them all")
            return EXIT_FAILED
        write_list(found, said)
        return EXIT_OK

    run_guarded(work)


@main.command("fmt")
@click.argument("files", nargs=-1, required=True, type=click.Path(allow_dash=True))
@click.option("--check", is_flag=True, help="Change nothing; exit 1 when a file would change.")
@click.option("--diff", is_flag=True, help="Change nothing; print what would change as a unified "
                                           "diff and exit 1 when a file would change.")
def fmt_command(files: tuple[str, ...], check: bool, diff: bool) -> None:
    """Write .mcm files (or every .mcm below a folder) in the one canonical layout;
    the build never changes.

    A rig file (`NAME.rig.toml`) stands for the programs of its controllers; the rig
    file itself is left as written.

    `-` formats standard input to standard output. Exit 0 when done (or, with
    --check/--diff, when nothing would change), 1 when a file would change,
    2 when a file cannot be read, written or parsed (it is left as it was).
    """
    def work() -> int:
        from mercmac.cli.fmt import format_files

        paths, passed_over = _expand(files)
        code = format_files(tuple(paths), check=check, diff=diff) if paths else EXIT_USAGE
        return EXIT_USAGE if passed_over else code

    run_guarded(work)
