"""`mercmac lsp`: start the language server, which needs the optional extra `lsp`."""
from __future__ import annotations

import sys

import click

from mercmac.cli.common import run_guarded, say
from mercmac.errors import EXIT_OK, EXIT_USAGE

MISSING = "the language server needs the lsp extra: pip install 'mercmac[lsp]'"
# Said when a person, not an editor, started it: otherwise it just sits there.
IN_A_TERMINAL = ("lsp is a language server: it waits for an editor to talk to it over "
                 "stdin/stdout (see README, Editors). Ctrl-C quits.")


@click.command()
@click.option("--stdio", is_flag=True,
              help="Talk over standard input and output: the only way it talks, and what "
                   "editors' clients (vscode-languageclient, pygls) ask for.")
def lsp(stdio: bool) -> None:
    """Run the language server over stdio (diagnostics, hover, completion, rename, ...)."""
    def work() -> int:
        try:
            from mercmac.lsp.server import main
        except ImportError as e:
            if e.name and e.name.split(".")[0] in ("pygls", "lsprotocol", "cattrs", "attrs"):
                say(MISSING)
                return EXIT_USAGE
            raise
        if sys.stdin is not None and sys.stdin.isatty():
            say(IN_A_TERMINAL)
        main(say)
        return EXIT_OK

    run_guarded(work)
