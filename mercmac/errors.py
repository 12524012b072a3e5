"""The library's errors: what went wrong, in words the user can act on (docs/cli.md).

Each kind carries the exit code a command ends with; `mercmac.cli.common.run_guarded` is
the one place that turns them into a message and that code. The library raises these
kinds (or its own subclasses of them) and never a command-line error: `cli.common.UsageError`
is the CLI's own, for options that do not go together.

    MercmacError    a check, simulation or upload that failed              exit 1
    InputError      an option or setting value, a file that cannot be      exit 2
                    read or written (docs/cli.md, "Exit codes": usage/IO)
    SettingsError   a rule selection, model or settings file checking      exit 2
                    cannot take (config, suppress, the editor's settings)
    Interrupted     a signal cut the work short (Ctrl-C, SIGTERM or        exit 128+N
                    SIGHUP); the message says how far                      (130, 143, 129)

SIGTERM and SIGHUP reach the library as `Signalled`, a KeyboardInterrupt: whatever tidies
up after Ctrl-C (a flash's report, a simulation cut short) does the same for them (docs/cli.md).
"""
from __future__ import annotations

import contextlib
import signal
from typing import Iterator

EXIT_OK = 0
EXIT_FAILED = 1  # diagnostics with errors, a failed simulation expectation or upload
EXIT_USAGE = 2  # bad options, unreadable files
EXIT_INTERRUPTED = 130  # 128 + SIGINT, as shells report a Ctrl-C
STOPPING = tuple(getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP")
                 if hasattr(signal, name))  # the signals a command answers (no SIGHUP on Windows)


def exit_code_for(signum: int) -> int:
    """128 + N: the exit code shells give a command that signal N ended."""
    return 128 + signum


class Signalled(KeyboardInterrupt):
    """SIGTERM or SIGHUP during a command, raised where Ctrl-C's KeyboardInterrupt would be."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


@contextlib.contextmanager
def held_signals() -> Iterator[None]:
    """Ctrl-C, SIGTERM and SIGHUP wait inside (POSIX), and come right after: for steps a
    second signal must not cut in half (a file overwritten in place and its restore, a port's
    close, which would leave pyserial holding a descriptor it already gave back)."""
    if not hasattr(signal, "pthread_sigmask"):
        yield
        return
    before = signal.pthread_sigmask(signal.SIG_BLOCK, set(STOPPING))
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, before)


def signal_of(interrupt: BaseException) -> int:
    """The signal an interrupt stands for: SIGINT for Ctrl-C's plain KeyboardInterrupt."""
    return getattr(interrupt, "signum", signal.SIGINT)


def interrupt(signum: int) -> KeyboardInterrupt:
    """The exception signal SIGNUM raises in a command: KeyboardInterrupt for Ctrl-C."""
    return KeyboardInterrupt() if signum == signal.SIGINT else Signalled(signum)


def how(signum: int) -> str:
    """The signal as messages name it: 'Ctrl-C', 'SIGTERM', 'SIGHUP'."""
    return "Ctrl-C" if signum == signal.SIGINT else signal.Signals(signum).name


def interrupted(signum: int) -> str:
    """What a command that a signal stopped says: 'interrupted', 'interrupted (SIGTERM)'."""
    return "interrupted" if signum == signal.SIGINT else f"interrupted ({how(signum)})"


class MercmacError(Exception):
    """A failure the user can act on; the CLI prints it without a traceback."""

    exit_code = EXIT_FAILED

    def __init__(self, message: str, *, hint: str | None = None):
        super().__init__(message)
        self.message = message
        self.hint = hint


class InputError(MercmacError):
    """Input the work cannot use: an option or setting value, a file it cannot read or write."""

    exit_code = EXIT_USAGE


class SettingsError(InputError):
    """Rules, a model or a settings file that checking cannot take; the message names where."""


class Interrupted(MercmacError):
    """A signal stopped the work; the message says where things stand. `by`: the
    KeyboardInterrupt it came as (or the Interrupted that reported it first), which sets
    the exit code, 128+N; none: Ctrl-C."""

    exit_code = EXIT_INTERRUPTED

    def __init__(self, message: str, *, hint: str | None = None,
                 by: BaseException | None = None):
        super().__init__(message, hint=hint)
        self.signum = signal.SIGINT if by is None else signal_of(by)
        self.exit_code = exit_code_for(self.signum)
