"""The README as tests read it: its indented code blocks, its commands, the tour's program."""
from __future__ import annotations

import re
import shutil
from pathlib import Path

from helpers.paths import EXAMPLE4, ROOT

README = (ROOT / "README.md").read_text(encoding="utf-8")


def setup_commands() -> list[str]:
    """The README's opening commands: the install line, then the test command CI runs."""
    return [line.strip() for line in README.splitlines()[:6] if line.startswith("    ")]


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


def _all_commands() -> list[str]:
    return [re.split(r"\s+#\s", line, maxsplit=1)[0].strip() for line in code_lines()
            if line.startswith("mercmac ")]


def commands() -> list[str]:
    """Each `mercmac ...` command line that ends by itself, without its trailing `# comment`."""
    return [c for c in _all_commands() if not serves(c)]


def served_commands() -> list[str]:
    """The README's commands that serve until Ctrl-C (`sim --web`): run as processes."""
    return [c for c in _all_commands() if serves(c)]


def serves(command: str) -> bool:
    return " --web" in f" {command} "


def tour_program() -> str:
    """The tour's program: the code block that follows "Save this one as `prog.mcm`"."""
    after = README.split("Save this one as `prog.mcm`", 1)[1].split("\n\n", 1)[1]
    block = []
    for line in after.splitlines():
        if line and not line.startswith("    "):
            break
        block.append(line[4:])
    return "\n".join(block).strip() + "\n"


HARDWARE_PORTS = ("/dev/ttyUSB0", "COM3")  # replaced by a virtual controller's pty

# What the text around each command promises: (pattern of the command, exit code, phrases in
# its output). A command the table does not know must still run and exit 0.
PROMISES = [
    (r"check prog\.mcm$", 0, ["No problems found"]),
    (r"check --format json prog\.mcm$", 0, ['"diagnostics": []']),
    (r"check --target C-663 prog\.mcm$", 0, ["No problems found"]),
    (r"check --max-diagnostics 0 big\.mcm$", 1, ["250 errors"]),
    (r"explain nested-call$", 0, ["nested-call", "§3.8.4"]),
    (r"explain$", 0, ["nested-call", "too-many-commands", "every-zero"]),
    (r"fmt prog\.mcm$", 0, []),
    (r"fmt --check --diff src/$", 1, ["--- ", "+++ ", "+    CN 1"]),
    (r"check src/macros$", 0, ["No problems found in 1 file"]),
    (r"check --output-format concise \.$", 0,
     ["manual-example4-four-modes.mcm:9:8: MM011 [nested-call]"]),
    (r"check --output-format github \.$", 0,
     ["::warning file=", "manual-example4-four-modes.mcm,line=9,col=8"]),
    (r"check --output-format sarif \. > mercmac\.sarif$", 0, []),
    (r"check --select nested-call,MM012 --ignore unreachable-macro \.$", 0, ["nested-call"]),
    (r"check --statistics \.$", 0, ["nested-call"]),
    (r"check --warnings-as-errors \.$", 1, ["3 warnings"]),
    (r"build prog\.mcm$", 0, ["MD0,XN1,SV70000,EM1"]),
    (r"build prog\.mcm -o prog\.md$", 0, []),
    (r"sim prog\.mcm ", 0, ["until 10 s", "button 1 pressed", "goto jog", "button 1 released",
                           "button 2 pressed", "move to", "still running jog"]),
    (r"ports$", 0, []),
    (r"scan PORT$", 0, ["C-863"]),
    (r"flash PORT prog\.mcm$", 0, ["verified"]),
    (r"pull PORT -o saved\.mcm$", 0, []),
    (r"new stage\.mcm$", 0, ["wrote the jog template for the C-863", "stage.mcm"]),
    (r"new scan\.mcm --template scan --target C-663$", 0, ["the scan template for the C-663"]),
    (r"new bench/xy\.rig\.toml$", 0, ["bench/xy.rig.toml", "bench/x.mcm", "bench/y.mcm"]),
    (r"examples$", 0, ["13 example files in examples:", "examples/rigs/raster/x.mcm"]),
]


def promise(command: str):
    """The exit code and the phrases of its output that the README's text promises."""
    rest = command.removeprefix("mercmac ")
    for pattern, code, phrases in PROMISES:
        if re.match(pattern, rest):
            return code, phrases
    return 0, []


def prepare(folder: Path, command: str, example4: Path = EXAMPLE4) -> None:
    """The files the command names, as the README's text describes them (Example 4 from
    EXAMPLE4: the repository's, or one `mercmac examples` wrote)."""
    (folder / "prog.mcm").write_text(tour_program(), encoding="utf-8")
    shutil.copy(example4, folder)
    if "big.mcm" in command:  # more than the 200 diagnostics shown by default
        body = "".join("    XY 1\n" for _ in range(250))
        (folder / "big.mcm").write_text(f"autostart {{\n{body}}}\n", encoding="utf-8")
    if "src/" in command:
        (folder / "src" / "macros").mkdir(parents=True)
        (folder / "src" / "macros" / "prog.mcm").write_text(tour_program(), encoding="utf-8")
        # a file written by hand, not in the one layout: fmt --check must see it
        (folder / "src" / "hand.mcm").write_text("autostart {\nCN 1\n}\n", encoding="utf-8")
