"""What every command shares: option types and the one exception-to-exit-code place."""
from __future__ import annotations

import sys
from typing import Callable

import click

from mercmac.commands import MODELS
from mercmac.errors import EXIT_FAILED, EXIT_INTERRUPTED, EXIT_USAGE, MercmacError

MODEL_CHOICE = click.Choice(MODELS, case_sensitive=False)


def run_guarded(work: Callable[[], int]) -> None:
    """Run a command body; exit with its code, or with a message and no traceback."""
    try:
        code = work()
    except MercmacError as e:
        say(e.message, e.hint)
        code = e.exit_code
    except KeyboardInterrupt:
        say("interrupted")
        code = EXIT_INTERRUPTED
    except BrokenPipeError:  # `mercmac sim ... | head`: the reader has gone, so stop quietly
        _silence_stdout()
        code = EXIT_FAILED
    except OSError as e:
        name = f"{e.filename}: " if getattr(e, "filename", None) else ""
        say(f"{name}{e.strerror or e}")
        code = EXIT_USAGE
    sys.exit(code)


def _silence_stdout() -> None:
    """Point stdout at /dev/null so that the interpreter's final flush cannot fail too."""
    import os

    try:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    except (OSError, ValueError):
        pass


def say(message: str, hint: str | None = None) -> None:
    click.echo(f"mercmac: {message}", err=True)
    if hint:
        click.echo(f"  hint: {hint}", err=True)
