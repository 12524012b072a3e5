"""What `mercmac fmt` must keep (docs/cli.md, "Commands": it never changes what a file
builds to): the MD lines and the rules found, and the comments."""
from __future__ import annotations

import re

from helpers.compiling import compile_text
from mercmac.fmt import format_text

COMMENT = re.compile(r"//[^\n]*")


def build(text: str):
    """What the formatter must never change: the MD lines and the rules found."""
    result = compile_text(text)
    lines = result.program.md_lines() if result.program is not None else None
    return lines, sorted(d.rule.name for d in result.report.items)


def comments(text: str) -> list[str]:
    return [c.rstrip() for c in COMMENT.findall(text.replace("\r", ""))]


def assert_formats_safely(text: str) -> str:
    """Format `text`: once more changes nothing, and the build and the comments stay."""
    formatted = format_text(text)
    assert format_text(formatted) == formatted, formatted
    assert build(formatted) == build(text), (text, formatted)
    assert comments(formatted) == comments(text)
    return formatted
