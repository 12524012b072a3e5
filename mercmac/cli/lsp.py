"""`mercmac lsp`: start the language server, which needs the optional extra `lsp`."""
from __future__ import annotations

import click

from mercmac.cli.common import run_guarded, say
from mercmac.errors import EXIT_OK, EXIT_USAGE

MISSING = "the language server needs the lsp extra: pip install 'mercmac[lsp]'"


@click.command()
def lsp() -> None:
    """Run the language server over stdio (diagnostics, hover, completion, rename, ...)."""
    def work() -> int:
        try:
            from mercmac.lsp.server import main
        except ImportError as e:
            if e.name and e.name.split(".")[0] in ("pygls", "lsprotocol", "cattrs", "attrs"):
                say(MISSING)
                return EXIT_USAGE
            raise
        main(say)
        return EXIT_OK

    run_guarded(work)
