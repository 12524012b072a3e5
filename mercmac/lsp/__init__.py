"""The language server (`mercmac lsp`, extra `lsp`): the checker's findings in an editor.

`server` speaks LSP over stdio (pygls, imported only there) and publishes what
`mercmac check` reports (mercmac.compiler.checking); `recheck` re-checks a document on
every change, `settings` reads the editor's workspace settings, `document` keeps the
editor's lines and converts positions, `symbols` finds what stands where, `completion`
what may stand at the cursor, `framing` reads the messages.
"""
