"""Names from outside as each output shows them: a file name, a rig's or
a controller's name, a port, what the flash history recalls. Such a name may hold any
character a file system or an old record allows: an ESC sequence that clears the screen or
writes the clipboard (OSC 52), a CR or a newline that forges an output line, a bidirectional
override that shows text reversed, a `"]` that ends a label and starts a statement.

One function per output: `printable` for a terminal, a message or a one-line comment of a
file mercmac writes (every other output builds on it), `markdown` for inline markdown text,
`mermaid` for a mermaid `"..."` label, `dot` for a Graphviz `"..."` label. JSON needs none:
json.dumps escapes what it must. A foundation module: every layer that words a message
quoting a name (a path, a port) escapes it here.
"""
from __future__ import annotations

import re

# Characters that would act on the terminal or hide text: C0/C1 controls, DEL, line and
# paragraph separators, zero-width and bidirectional marks ("Trojan Source").
_HIDDEN = {c: f"\\x{c:02x}" for c in (*range(0x20), *range(0x7F, 0xA0))}
_HIDDEN |= {c: f"\\u{c:04x}" for c in (0x2028, 0x2029, *range(0x200B, 0x2010),
                                         *range(0x202A, 0x202F), *range(0x2066, 0x206A), 0xFEFF)}
_HIDDEN[0x09] = " "  # a tab shows as one space, so the caret stays under its column
# A file name that is not UTF-8 holds its bytes as lone surrogates (os.fsdecode's
# surrogateescape, U+DC80-U+DCFF for bytes 0x80-0xFF): shown as the byte, `\xff`; no
# stream can write a lone surrogate as UTF-8.
SURROGATES = {c: f"\\u{c:04x}" for c in range(0xD800, 0xE000)}
SURROGATES |= {0xDC00 + b: f"\\x{b:02x}" for b in range(0x80, 0x100)}
_HIDDEN |= SURROGATES

# What CommonMark would read as markup inside a line (§2.4: any ASCII punctuation may be
# escaped): code spans, emphasis (`_` only at the edge of a word: inside one it is a
# letter, §6.2), links, HTML, entities, a heading's closing `#`s (§4.2), and GFM's table
# cells and strikethrough. A line never starts with a name here, so no block markup.
_MARKUP = re.compile(r"[\\`*\[\]<>&#|~]|(?<!\w)_|_(?!\w)")
# Mermaid reads `#name;` and `#35;` as entities in a label: `"` would end the label, and
# `<`, `>` would be HTML (mermaid.js.org, "Entity codes to escape characters").
_MERMAID = str.maketrans({"#": "#35;", '"': "#quot;", "<": "#lt;", ">": "#gt;"})


def printable(text: str) -> str:
    """`text` with control and invisible characters escaped (`\\x1b`), safe for a terminal."""
    return text.translate(_HIDDEN)


def markdown(text: str) -> str:
    """`text` as inline markdown that shows it literally, on one line."""
    return _MARKUP.sub(lambda m: "\\" + m.group(), printable(text))


def mermaid(text: str) -> str:
    """`text` inside a mermaid `"..."` label, shown literally, on one line."""
    return printable(text).translate(_MERMAID)


def dot(text: str) -> str:
    """`text` inside a Graphviz `"..."` label, shown literally, on one line (a backslash
    would start an escString's `\\n` or `\\N`)."""
    return printable(text).replace("\\", "\\\\").replace('"', '\\"')
