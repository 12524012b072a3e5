"""The library's errors: what went wrong, in words the user can act on (SPEC §5).

Each kind carries the exit code a command ends with; `mercmac.cli.common.run_guarded` is
the one place that turns them into a message and that code. The library raises these
kinds (or its own subclasses of them) and never a command-line error: `cli.common.UsageError`
is the CLI's own, for options that do not go together.

    MercmacError    a check, simulation or upload that failed              exit 1
    InputError      an option or setting value, a file that cannot be      exit 2
                    read or written (SPEC §5: usage/IO)
    SettingsError   a rule selection, model or settings file checking      exit 2
                    cannot take (config, suppress, the editor's settings)
    Interrupted     Ctrl-C cut the work short; the message says how far    exit 130
"""
from __future__ import annotations

EXIT_OK = 0
EXIT_FAILED = 1  # diagnostics with errors, a failed simulation expectation or upload
EXIT_USAGE = 2  # bad options, unreadable files
EXIT_INTERRUPTED = 130  # 128 + SIGINT, as shells report a Ctrl-C


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
    """Ctrl-C stopped the work; the message says where things stand."""

    exit_code = EXIT_INTERRUPTED
