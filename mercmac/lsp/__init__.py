"""The language server (`mercmac lsp`, extra `lsp`): the checker's findings in an editor.

`recheck` re-checks a document on every change, `symbols` finds what stands where,
`server` speaks LSP over stdio (pygls, imported only there).
"""
