"""`check --fix` and `check --diff`: each file fixed by the library (mercmac.compiler.fixing),
and what changed said per file on standard error, so that standard output keeps the
chosen format (the remaining diagnostics, or the diff)."""
from __future__ import annotations

import click

from mercmac.cli.common import say
from mercmac.compiler import fixing
from mercmac.compiler.checking import Findings, Options
from mercmac.diagnostics import UNSAFE
from mercmac.errors import EXIT_FAILED, EXIT_OK, EXIT_USAGE
from mercmac.render.sim import plural


class Fixes:
    """The files of one `check --fix` (or `--diff`, which writes nothing) and their count."""

    def __init__(self, diff: bool, unsafe: bool = False):
        self.diff, self.unsafe = diff, unsafe
        self.changed = self.unchanged = self.refused = self.fixes = self.held = 0

    def file(self, path: str, chosen: Options) -> Findings:
        """Fix one file (show its diff) and say what changed; what `check` reports of it
        now. OSError when it cannot be read."""
        from mercmac.names import printable

        done = fixing.fix_file(path, chosen, write=not self.diff, unsafe=self.unsafe)
        fixed, name = done.fixed, printable("<stdin>" if path == "-" else path)
        self.held += len(fixed.left(UNSAFE))
        if done.refused is not None:
            say(printable(done.refused.message), done.refused.hint)
            self.refused += 1
        elif not fixed.made:
            self.unchanged += 1
        else:
            if self.diff:
                from mercmac.cli.fmt import show_diff

                show_diff(fixed.before, fixed.after, name)
            self._tell(name, fixed.made)
        return done.findings

    def _tell(self, name: str, made: list[fixing.Made]) -> None:
        """'fixed a.mcm (2 fixes):', then each fix where it was made and what it did."""
        self.changed, self.fixes = self.changed + 1, self.fixes + len(made)
        verb = "would fix" if self.diff else "fixed"
        click.echo(f"{verb} {name} ({plural(len(made), 'fix', 'fixes')}):", err=True)
        for fix, diagnostic in made:
            rule = f"{diagnostic.rule.name}: " if diagnostic is not None else ""
            unsafe = " (unsafe)" if fix.applicability is UNSAFE else ""
            click.echo(f"  {fix.span}: {rule}{fix.title}{unsafe}", err=True)

    def summary(self) -> None:
        """fmt's closing line: '1 file fixed (3 fixes), 2 files left unchanged'."""
        verb = "would be fixed" if self.diff else "fixed"
        parts = [f"{plural(self.changed, 'file')} {verb} ({plural(self.fixes, 'fix', 'fixes')})"
                 if self.changed else "",
                 f"{plural(self.unchanged, 'file')} left unchanged" if self.unchanged else "",
                 f"{plural(self.refused, 'file')} not fixed" if self.refused else ""]
        click.echo(", ".join(p for p in parts if p), err=True)
        if self.held:
            click.echo(f"{plural(self.held, 'unsafe fix', 'unsafe fixes')} not made: each is a "
                       "guess that may change what the program does (another command, one of "
                       "several names); `--unsafe-fixes` makes them, `--diff --unsafe-fixes` "
                       "shows them", err=True)

    def diff_exit_code(self) -> int:
        """`--diff`, as `fmt --diff` and ruff's: 1 when a file would change, 2 when one could
        not be fixed, else 0; the diagnostics that would remain are not its business."""
        if self.refused:
            return EXIT_USAGE
        return EXIT_FAILED if self.changed else EXIT_OK
