"""Errors that end a command with a message and an exit code (SPEC §5)."""
from __future__ import annotations

EXIT_OK = 0
EXIT_FAILED = 1  # diagnostics with errors, a failed simulation expectation or upload
EXIT_USAGE = 2  # bad options, unreadable files
EXIT_INTERRUPTED = 130


class MercmacError(Exception):
    """A failure the user can act on; the CLI prints it without a traceback."""

    exit_code = EXIT_FAILED

    def __init__(self, message: str, *, hint: str | None = None):
        super().__init__(message)
        self.message = message
        self.hint = hint


class UsageError(MercmacError):
    """Bad input from the command line or an unreadable file."""

    exit_code = EXIT_USAGE
