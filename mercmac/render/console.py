"""Where text goes: a styled line model, written plain or through rich."""
from __future__ import annotations

import os
import sys
from typing import IO, Iterable

# A line is a list of (text, style) pieces; style is a rich style string or "".
Piece = tuple[str, str]
Line = list[Piece]


def use_colour(stream: IO[str]) -> bool:
    """Colour only on a terminal, and never when NO_COLOR is set (no-color.org)."""
    if os.environ.get("NO_COLOR"):
        return False
    if os.environ.get("FORCE_COLOR"):
        return True
    isatty = getattr(stream, "isatty", None)
    return bool(isatty and isatty())


def rich_console(stream: IO[str] | None = None, *, colour: bool | None = None):
    """A rich Console on a stream; imported lazily because rich is slow to import."""
    from rich.console import Console

    stream = stream or sys.stdout
    colour = use_colour(stream) if colour is None else colour
    return Console(file=stream, no_color=not colour, highlight=False,
                   force_terminal=colour or None, soft_wrap=True, emoji=False)


def write_lines(lines: Iterable[Line], stream: IO[str] | None = None) -> None:
    """Write styled lines: through rich on a colour terminal, as plain text otherwise."""
    stream = stream or sys.stdout
    if not use_colour(stream):
        for line in lines:
            stream.write("".join(text for text, _ in line) + "\n")
        stream.flush()
        return
    from rich.text import Text

    console = rich_console(stream, colour=True)
    for line in lines:
        console.print(Text.assemble(*line), overflow="ignore", crop=False)


def table(header: tuple[str, ...], rows: list[tuple[str, ...]], style_of=lambda row: "") -> list[Line]:
    """Left-aligned columns; the same Lines in plain text and through rich."""
    widths = [max(len(str(c)) for c in col) for col in zip(header, *rows)]
    fmt = lambda row: "  ".join(f"{str(c):<{w}}" for c, w in zip(row, widths)).rstrip()  # noqa: E731
    return [[(fmt(header), "bold")]] + [[(fmt(row), style_of(row))] for row in rows]
