"""What every command shares: option types, the command line's own UsageError, and the one
place that turns the library's errors (mercmac.errors) into a message and an exit code."""
from __future__ import annotations

import math
import signal
import sys
import threading
from typing import Callable

import click

from mercmac.commands import MODELS
from mercmac.errors import (EXIT_FAILED, EXIT_USAGE, STOPPING, InputError, MercmacError,
                            exit_code_for, interrupt, interrupted, signal_of)

MODEL_CHOICE = click.Choice(MODELS, case_sensitive=False)


class UsageError(InputError):
    """Options that do not go together, or a value the command line cannot take (exit 2);
    the library's own errors (mercmac.errors) are worded where they arise."""


class FiniteFloat(click.ParamType):
    """A float option that refuses nan and inf (float() takes them), optionally within bounds."""

    name = "number"

    def __init__(self, min: float | None = None, max: float | None = None, *,
                 min_open: bool = False):
        self.min, self.max, self.min_open = min, max, min_open

    def convert(self, value, param, ctx) -> float:
        shown = repr(value) if len(repr(value)) <= 40 else f"{repr(value)[:30]}...'"
        try:
            number = float(value)
        except (TypeError, ValueError):
            self.fail(f"{shown} is not a number", param, ctx)
        if math.isnan(number) or math.isinf(number):  # float() takes 'nan', 'inf', '1e999'
            self.fail(f"{shown} is not a finite number", param, ctx)
        low_ok = self.min is None or (number > self.min if self.min_open else number >= self.min)
        if not low_ok or (self.max is not None and number > self.max):
            self.fail(f"{shown} is out of range: use a number {self._range()}", param, ctx)
        return number

    def _range(self) -> str:
        low = high = None
        if self.min is not None:
            low = f"{'above' if self.min_open else 'at least'} {self.min:g}"
        if self.max is not None:
            high = f"at most {self.max:g}"
        return " and ".join(filter(None, (low, high)))


def run_guarded(work: Callable[[], int]) -> None:
    """Run a command body; exit with its code, or with a message and no traceback."""
    previous = _catch_signals()
    failure: BaseException | None = None
    try:
        try:
            code = work()
        finally:
            # The outcome is decided: a further signal must not cut its report short, nor
            # land in the interpreter's shutdown ("Exception ignored in threading._shutdown").
            _hold_signals(previous)
    except (MercmacError, KeyboardInterrupt, OSError) as e:
        failure = e  # a signal that came while holding still has the report in its context
    try:
        _hold_signals(previous)
        if failure is not None:
            code = _tell(failure)
    finally:
        if not _owns_process():  # a test runner or a host program keeps its handlers
            _release_signals(previous)
    sys.exit(code)


def _tell(e: BaseException) -> int:
    """Say why the command stopped; its exit code."""
    if isinstance(e, KeyboardInterrupt):
        e = _report_cut_short(e) or e
    if isinstance(e, MercmacError):
        say(e.message, e.hint)
        return e.exit_code
    if isinstance(e, KeyboardInterrupt):
        say(interrupted(signal_of(e)))
        return exit_code_for(signal_of(e))
    if isinstance(e, BrokenPipeError):  # `mercmac sim ... | head`: the reader has gone, so stop quietly
        _silence_stdout()
        return EXIT_FAILED
    from mercmac.names import printable
    from mercmac.outfile import reason

    name = f"{printable(str(e.filename))}: " if getattr(e, "filename", None) else ""
    say(f"{name}{reason(e)}")
    return EXIT_USAGE


def _report_cut_short(interrupt: KeyboardInterrupt) -> MercmacError | None:
    """The report on its way when this signal came (a second one, during the tidy-up)."""
    seen = interrupt.__context__
    while seen is not None and not isinstance(seen, MercmacError):
        seen = seen.__context__
    return seen


def _catch_signals() -> dict | None:
    """While the work runs, Ctrl-C raises KeyboardInterrupt and SIGTERM or SIGHUP raise
    Signalled, so that whatever tidies up after Ctrl-C answers all three alike (docs/cli.md).
    A signal the process ignores (started by `nohup`, or with `&`) stays ignored. The handlers
    before, by signal number, to put back; None off the main thread, where they are not
    ours to change."""
    if threading.current_thread() is not threading.main_thread():
        return None
    previous = {}
    for signum in STOPPING:
        handler = signal.getsignal(signum)
        if handler not in (signal.SIG_IGN, None):  # None: set outside Python, not ours
            previous[signum] = handler
            signal.signal(signum, _raise_interrupt)
    return previous


def _raise_interrupt(signum: int, frame) -> None:
    raise interrupt(signum)


def _hold_signals(previous: dict | None) -> None:
    """Ignore the signals the command caught, from now on."""
    for signum in previous or ():
        signal.signal(signum, signal.SIG_IGN)


def _release_signals(previous: dict | None) -> None:
    for signum, handler in (previous or {}).items():
        signal.signal(signum, handler)


_program = False  # True once the entry point (mercmac.__main__) runs: the process is ours


def run_as_program() -> None:
    """The command line is the program running (mercmac.__main__): its signal handlers stay
    held after a command, until the process ends."""
    global _program
    _program = True


def _owns_process() -> bool:
    """Whether mercmac's command line is the program running, not a test calling it."""
    ctx = click.get_current_context(silent=True)
    program = getattr(sys.modules.get("__main__"), "main", None)
    return _program or (ctx is not None and program is ctx.find_root().command)


def _silence_stdout() -> None:
    """Point stdout at /dev/null so that the interpreter's final flush cannot fail too."""
    import os

    try:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    except (OSError, ValueError):
        pass


def say(message: str, hint: str | None = None) -> None:
    """The message on standard error, each of its lines escaped: a message quotes file
    names, ports and option values, which may hold any character (mercmac/names.py);
    nothing if standard error is gone (a hung-up terminal)."""
    try:
        click.echo(f"mercmac: {_escaped(message)}", err=True)
        if hint:
            click.echo(f"  hint: {_escaped(hint)}", err=True)
    except OSError:
        pass


def _escaped(text: str) -> str:
    from mercmac.names import printable

    return "\n".join(printable(line) for line in text.split("\n"))


def opened(accept: Callable[[], object], stream=None):
    """`accept()` (rig.open: a rig file, or a lone program as a rig of one), or None after
    showing `check`'s findings on stderr (or `stream`): the rig or the program has errors,
    and the command exits 1, as `sim FILE` with errors does. A program that cannot be read
    is shown alike, then raised (exit 2, as for any file)."""
    from mercmac.render.report import write_findings
    from mercmac.rig.open import ProgramsUnread, RigRefused

    try:
        return accept()
    except RigRefused as e:
        write_findings(e.findings, stream)
        if isinstance(e, ProgramsUnread):
            raise
        return None
