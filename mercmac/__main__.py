"""`mercmac` and `python -m mercmac`: the first code of the program (pyproject's entry point).

It imports almost nothing before it catches signals: the command line takes a while to
import, and Ctrl-C, SIGTERM or SIGHUP in that while must end it as cleanly as later, in
one line and exit 128+N, not with a traceback. Once a command runs, `cli.common.run_guarded`
answers signals itself (a flash says what the controller holds).
"""


class _Stopped(BaseException):
    """A signal before or after a command's work. Not a KeyboardInterrupt, which click
    would answer with 'Aborted!' and exit 1."""


_answered: list[int] = []  # the signal being answered; a second one changes nothing


def main() -> None:
    """Run the command line; a signal at start-up ends it with one line and exit 128+N."""
    try:
        try:
            _catch_signals()
            from mercmac.cli import main as command_line
            from mercmac.cli.common import run_as_program

            run_as_program()
            command_line(prog_name="mercmac")
        finally:
            _answered.append(0)  # from here a signal is ignored: the outcome is decided
    except (KeyboardInterrupt, _Stopped) as e:  # KeyboardInterrupt: before the handlers were set
        _stopped(e.args[0] if isinstance(e, _Stopped) else None)


def _catch_signals() -> None:
    """SIGINT, SIGTERM and SIGHUP raise _Stopped, except one the process ignores (nohup, &)."""
    import signal

    for name in ("SIGINT", "SIGTERM", "SIGHUP"):  # no SIGHUP on Windows
        signum = getattr(signal, name, None)
        if signum is not None and signal.getsignal(signum) not in (signal.SIG_IGN, None):
            signal.signal(signum, _stop)


def _stop(signum: int, frame) -> None:
    if not _answered:
        _answered.append(signum)
        raise _Stopped(signum)


def _stopped(signum: int | None) -> None:
    """Say which signal stopped the program, and exit with 128 + its number."""
    import signal
    import sys

    from mercmac.errors import exit_code_for, interrupted

    signum = signum or signal.SIGINT
    try:
        sys.stderr.write(f"mercmac: {interrupted(signum)}\n")
        sys.stderr.flush()
    except (AttributeError, OSError):  # no standard error, or gone with a hung-up terminal
        pass
    sys.exit(exit_code_for(signum))


if __name__ == "__main__":
    main()
