"""One line end for every tool (docs/cli.md): LF, CRLF and a lone CR end a line
alike in check, build, fmt and the highlighter, mixed freely, with the same lines and columns."""
from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import mercmac
from helpers.budgets import budget
from helpers.cli import cli
from helpers.compiling import compile_text
from helpers.paths import EXAMPLE_FILES
from mercmac.fmt import FormatError, format_text, load
from mercmac.highlight import McmLexer
from helpers.programs import programs

EXAMPLE_TEXTS = [load(p.read_bytes())[0] for p in EXAMPLE_FILES]
# A file that once went wrong: the `//` comment ran to the next LF and hid the rest of the file.
CR_ONLY = b"macro a @20 { MR 5 }   // c\rautostart { call a }\r[MC05] MR 9\r"
# Where the mercmac under test lives: a child process started there imports the same one.
PACKAGE_ROOT = Path(mercmac.__file__).resolve().parent.parent
ENDS = st.sampled_from(["\n", "\r\n", "\r"])


def split_lines(text: str, keepends: bool = False) -> list[str]:
    """The test's own oracle of the line ends in docs/cli.md (not mercmac's)."""
    if keepends:
        return re.findall(r"[^\r\n]*(?:\r\n|\r|\n)", text)
    return re.split(r"\r\n|\r|\n", text)


def outcome(text: str):
    """What a file builds to and what is reported where: MD lines, (rule, line, column)."""
    result = compile_text(text)
    md = result.program.md_lines() if result.program is not None else None
    return md, sorted((d.rule.name, d.span.line, d.span.column) for d in result.report.items)


def with_ends(text: str, data) -> str:
    """TEXT with each of its line ends drawn from LF, CRLF and CR."""
    lines = split_lines(text)
    ends = data.draw(st.lists(ENDS, min_size=len(lines) - 1, max_size=len(lines) - 1))
    for i in range(1, len(ends)):
        if ends[i - 1] == "\r" and not lines[i] and ends[i] == "\n":
            ends[i] = "\r\n"  # CR, an empty line, LF would be one CRLF: one line end
    return "".join(line + end for line, end in zip(lines, ends)) + lines[-1]


MUTATIONS = st.sampled_from(["", "MR5000 ", "}", "{", "when 1 { ", "XX9,", "// note ", "@"])


@st.composite
def files(draw):
    """An example, a generated program, or either with a few broken lines (diagnostics)."""
    text = draw(st.one_of(st.sampled_from(EXAMPLE_TEXTS), programs()))
    lines = split_lines(text)
    for _ in range(draw(st.integers(0, 2))):
        at = draw(st.integers(0, len(lines) - 1))
        lines[at] = draw(MUTATIONS) + lines[at]
    return "\n".join(lines)


@pytest.mark.slow
@settings(max_examples=budget(150), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(files(), st.data())
def test_any_mix_of_line_ends_builds_the_same_and_reports_the_same_places(text, data):
    mixed = with_ends(text, data)
    assert outcome(mixed) == outcome(text)
    try:
        formatted = format_text(mixed)
    except FormatError:
        with pytest.raises(FormatError):
            format_text(text)
        return
    assert outcome(formatted)[0] == outcome(text)[0]
    assert format_text(formatted) == formatted


def test_a_cr_only_file_builds_whole(tmp_path):
    path = tmp_path / "cr.mcm"
    path.write_bytes(CR_ONLY)
    lf = tmp_path / "lf.mcm"
    lf.write_bytes(CR_ONLY.replace(b"\r", b"\n"))
    built = [subprocess.run([sys.executable, "-m", "mercmac", "build", str(p)], cwd=PACKAGE_ROOT,
                            capture_output=True, text=True, timeout=60) for p in (path, lf)]
    assert built[0].returncode == 0, built[0].stderr
    assert built[0].stdout == built[1].stdout == "MD5,MR9\nMD20,MR5\nMD0,EM20\n"
    checked = [json.loads(cli("check", "--format", "json", p).output)["diagnostics"]
               for p in (path, lf)]
    assert [(d["rule"], d["line"], d["column"]) for d in checked[0]] == \
        [(d["rule"], d["line"], d["column"]) for d in checked[1]] == [("unreachable-macro", 3, 1)]


def test_a_lone_cr_in_a_comment_ends_it():
    text = "macro a { MR 5 }   // c\rautostart { call a }\n"
    assert outcome(text) == outcome(text.replace("\r", "\n"))
    assert outcome(text)[0] == ["MD1,MR5", "MD0,EM1"]


def test_fmt_keeps_a_cr_only_file_cr_only(tmp_path):
    path = tmp_path / "cr.mcm"
    path.write_bytes(b"macro a {mr5}   // c\rautostart {call a}\r")
    assert cli("fmt", path).exit_code == 0
    assert path.read_bytes() == b"macro a { MR 5 }   // c\rautostart { call a }\r"


@pytest.mark.parametrize("text, end", [
    ("[MC00] em1\r[MC01] tp\r", "\r"),
    ("\r[MC00] em1\r\n[MC01] tp\r\n", "\r\n"),  # the most common: a stray CR does not
    ("[MC00] em1\r[MC01] tp\r\n[MC02] tp\r\n", "\r\n"),  # turn the file around
])
def test_fmt_writes_the_files_own_line_end(text, end):
    formatted = format_text(text)
    assert split_lines(formatted, keepends=True)[0].endswith(end)
    assert formatted.count(end) == len(split_lines(formatted)) - 1


def test_the_highlighter_ends_lines_at_a_lone_cr():
    tokens = list(McmLexer().get_tokens_unprocessed("MR 5 // c\rautostart { }\r[MC01] TP\r"))
    assert not [t for t in tokens if "Error" in str(t[1])]
    assert ("Token.Keyword.Declaration", "autostart") in [(str(k), v) for _, k, v in tokens]
