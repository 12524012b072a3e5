"""The README as tests read it: its indented code blocks, its commands, the tour's program."""
from __future__ import annotations

import re

from helpers.paths import ROOT

README = (ROOT / "README.md").read_text(encoding="utf-8")


def code_lines() -> list[str]:
    """The lines of the README's indented code blocks (fenced ones are other languages)."""
    lines, fenced, previous_blank = [], False, True
    in_block = False
    for line in README.splitlines():
        if line.startswith("```"):
            fenced = not fenced
            continue
        if fenced:
            continue
        if line.startswith("    ") and (in_block or previous_blank):
            in_block = True
            lines.append(line[4:])
        elif line.strip():
            in_block = False
        previous_blank = not line.strip()
    return lines


def commands() -> list[str]:
    """Each `mercmac ...` command line, without its trailing `# comment`."""
    found = []
    for line in code_lines():
        if line.startswith("mercmac "):
            found.append(re.split(r"\s+#\s", line, maxsplit=1)[0].strip())
    return found


def tour_program() -> str:
    """The tour's program: the code block that follows "Save this one as `prog.mcm`"."""
    after = README.split("Save this one as `prog.mcm`", 1)[1].split("\n\n", 1)[1]
    block = []
    for line in after.splitlines():
        if line and not line.startswith("    "):
            break
        block.append(line[4:])
    return "\n".join(block).strip() + "\n"
