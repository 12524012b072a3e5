"""`mercmac fmt` keeps trailing comments of consecutive lines in one column:
the README's programs and every example are already in the one layout."""
from __future__ import annotations

import re

import pytest
from markdown_it import MarkdownIt

from helpers.cli import cli
from helpers.formatting import assert_formats_safely
from helpers.paths import EXAMPLES, ROOT
from helpers.readme import README
from mercmac.fmt import format_text

# A code block is a .mcm program when its first line starts what a .mcm file holds: a
# comment, `target`, `const`, `macro`, `autostart` or a raw `[MCnn]` block. The README's
# other blocks are shell commands, TOML and YAML (`[tool.mercmac]` is no `[MC`).
MCM_START = re.compile(r"(//|target\b|const\b|macro\b|autostart\b|\[[ \t]*MC)", re.IGNORECASE)


def readme_programs() -> list[str]:
    """The .mcm programs among the README's code blocks (indented, or fenced as `mcm`),
    read by a CommonMark parser."""
    blocks = [t.content for t in MarkdownIt("commonmark").parse(README)
              if t.type == "code_block" or (t.type == "fence" and t.info.strip() == "mcm")]
    return [b for b in blocks if MCM_START.match(b)]


PROGRAMS = readme_programs()


def test_the_readme_programs_are_found():
    assert any("macro jog" in p for p in PROGRAMS)  # the tour
    assert any("mercmac: ignore" in p for p in PROGRAMS)  # the suppression comments
    assert not any("[tool.mercmac]" in p or p.startswith("mercmac ") for p in PROGRAMS)


@pytest.mark.parametrize("program", PROGRAMS, ids=lambda p: p.splitlines()[0][:30])
def test_readme_programs_are_in_the_one_layout(program):
    assert format_text(program) == program


def test_every_example_is_fmt_check_clean():
    paths = sorted((ROOT / "examples").rglob("*.mcm"))
    assert len(paths) >= len(list(EXAMPLES.glob("*.mcm"))) > 0
    result = cli("fmt", "--check", *paths)
    assert result.exit_code == 0, result.output


@pytest.mark.parametrize("text, expected", [
    # aligned by hand: kept, three spaces after the longest code
    ("macro a {\n    MR 1       // one\n    MR 1000    // two\n}\n",
     "macro a {\n    MR 1      // one\n    MR 1000   // two\n}\n"),
    # collapsed by an old fmt: aligned again
    ("macro a {\n    MR 1   // one\n    MR 1000   // two\n}\n",
     "macro a {\n    MR 1      // one\n    MR 1000   // two\n}\n"),
    # lines of different depth align: a block's opening line and its statements
    ("macro a {\n    every 20ms {   // poll\n        when 1 { MR 1 }   // go\n    }\n}\n",
     "macro a {\n    every 20ms {          // poll\n        when 1 { MR 1 }   // go\n    }\n}\n"),
    # raw blocks align like the rest
    ("[MC01] EM2,EM3,EM4   // a\n[MC02] TP   // b\n",
     "[MC01] EM2,EM3,EM4   // a\n[MC02] TP            // b\n"),
])
def test_a_run_of_commented_lines_is_aligned(text, expected):
    assert assert_formats_safely(text) == expected


@pytest.mark.parametrize("text", [
    "macro a {\n    MR 1   // one\n\n    MR 1000   // two\n}\n",  # a blank line
    "macro a {\n    MR 1   // one\n    // alone\n    MR 1000   // two\n}\n",  # a comment line
    "macro a {\n    MR 1   // one\n    TP\n    MR 1000   // two\n}\n",  # a line without one
])
def test_what_ends_a_run(text):
    assert assert_formats_safely(text) == text


def test_aligned_comments_keep_the_file_line_ends():
    text = "[MC01] EM2,EM3   // a\r\n[MC02] TP   // b\r\n"
    assert format_text(text) == "[MC01] EM2,EM3   // a\r\n[MC02] TP        // b\r\n"


def test_a_very_long_line_is_not_aligned_with_its_neighbours():
    """Padding many short lines to one huge line would multiply the file (hostile input)."""
    long = "[MC01] " + ",".join(["MR1"] * 40)  # 166 characters of code
    text = f"[MC02] TP   // a\n{long}   // b\n[MC03] TT   // c\n[MC04] TT,TP   // d\n"
    assert assert_formats_safely(text) == (
        f"[MC02] TP   // a\n{long}   // b\n[MC03] TT      // c\n[MC04] TT,TP   // d\n")
