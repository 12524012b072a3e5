"""All text that mercmac shows people or programs is rendered in this package.

rich is imported only here, and only when the output is a terminal: plain
output (pipes, files, CI) is written without it, which keeps `mercmac check`
fast to start.
"""
