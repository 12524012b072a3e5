"""What `mercmac check` reports for one source: the one function that `check` and the
language server both call, so that an editor shows what `check` says.

    source --compile--> every finding --rules chosen, comments read--> what is reported

What applies to a file (a Choice) is the user's Options (`--select`, `--ignore`,
`--target`, or an editor's workspace settings) laid key by key over the settings found
upward from the file (mercmac.config); `// mercmac: ignore[...]` comments turn rules
off on their line (mercmac.suppress).
"""
from __future__ import annotations

from typing import Callable, Iterable, NamedTuple

from mercmac import config, suppress
from mercmac.compiler import Compilation
from mercmac.diagnostics import Diagnostic, Report
from mercmac.source import Source, Span, read_source


class Options(NamedTuple):
    """What the user chose beside the file, as rule codes; None where the settings decide."""

    target: str | None = None
    select: frozenset[str] | None = None
    ignore: frozenset[str] | None = None


class Choice(NamedTuple):
    """What applies to one file: the codes of the rules reported, and the model."""

    rules: frozenset[str]
    target: str | None


class Findings(NamedTuple):
    """One check: the compilation, and the diagnostics it reports (sorted as found)."""

    compilation: Compilation
    diagnostics: list[Diagnostic]


def options(target: str | None = None, select: Iterable[str] | None = None,
            ignore: Iterable[str] | None = None,
            names: tuple[str, str] = ("--select", "--ignore")) -> Options:
    """Options from rules named by codes or names; a SettingsError names the option (`names`)."""
    return Options(target.upper() if target else None,
                   None if select is None else suppress.selection(select, names[0]),
                   None if ignore is None else suppress.rule_set(ignore, names[1]))


def choice_for(path: str | None, chosen: Options = Options()) -> Choice:
    """The rules and model for the file at `path` ('-': standard input; None: a document
    that is no file, which has no settings file)."""
    settings = config.settings_for(path) if path else config.Settings()
    where = f"in {settings.path}" if settings.path else ""
    select, ignore = chosen.select, chosen.ignore
    if select is None and settings.select is not None:
        select = suppress.selection(settings.select, f"select {where}")
    if ignore is None:
        ignore = suppress.rule_set(settings.ignore or (), f"ignore {where}")
    return Choice(suppress.chosen(select, ignore), chosen.target or settings.target)


def check_file(path: str, chosen: Options = Options()) -> Findings:
    """What `check` reports on the file at PATH ('-': standard input) under its settings and
    `chosen`; OSError when it cannot be read."""
    source = read_source(path)
    return check(source, choice_for(path, chosen))


def check(source: Source, choice: Choice,
          compiler: Callable[[Source, str | None], Compilation] | None = None) -> Findings:
    """The diagnostics `check` reports on `source`; `compiler(source, target)` compiles
    (compile_source; the language server passes its incremental re-checker)."""
    compilation = _guarded(compiler or _compile, source, choice.target)
    return Findings(compilation,
                    suppress.kept(compilation.report.items, choice.rules, compilation.source))


def _compile(source: Source, target: str | None) -> Compilation:
    from mercmac.compiler import compile_source
    from mercmac.compiler.parse import paused_gc

    with paused_gc():
        return compile_source(source, target=target)


def _guarded(compiler, source: Source, target: str | None) -> Compilation:
    """Compile one file; a compiler bug becomes an error on that file, and the others go on."""
    try:
        return compiler(source, target)
    except Exception as e:  # last resort: never a traceback, never lose the other files
        report = Report(source.name)
        try:
            detail = f"{type(e).__name__}: {e}"
        except Exception:  # an exception whose text cannot be made
            detail = type(e).__name__
        detail = detail if len(detail) <= 200 else detail[:200] + "..."
        report.add("syntax", Span(1, 1, 1, 2), "internal", detail=detail)
        return Compilation(source, report, None)
