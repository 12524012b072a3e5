"""`decompile` and `describe` under hostile names and options.

A file name with a line end stays inside the `// Read from` comment; `-o` naming the
input is refused without --force; an empty `--graph` or `-o` and a port given twice are
refused; one macro is "1 macro".
"""
from __future__ import annotations

import os

import pytest

from helpers.cli import cli
from helpers.compiling import compile_text

RAW = "[MC05] MR5,WS100\n"


def _built(source: str) -> list[str]:
    result = compile_text(source)
    assert result.program is not None, [d.message for d in result.report.items]
    return result.program.md_lines()


@pytest.mark.parametrize("end", ["\n", "\r", "\r\n"])  # mercmac's line ends (source.LINE_END)
def test_a_name_with_a_line_end_does_not_inject_code(tmp_path, end):
    path = tmp_path / f"x{end}[MC07] MR999{end}.mcm"
    path.write_text(RAW)
    result = cli("decompile", path)
    assert result.exit_code == 0, result.output
    assert _built(result.stdout) == ["MD5,MR5,WS100"]
    (comment,) = [line for line in result.stdout.split("\n") if "Read from" in line]
    assert "MR999" in comment and comment.startswith("// Read from ")


def test_output_naming_the_input_is_refused_without_force(tmp_path):
    path = tmp_path / "x.mcm"
    path.write_text("// my notes\n" + RAW)
    os.link(path, tmp_path / "hard.mcm")
    (tmp_path / "soft.mcm").symlink_to(path)
    for output in (path, tmp_path / "hard.mcm", tmp_path / "soft.mcm", tmp_path / "." / "x.mcm"):
        result = cli("decompile", path, "-o", output)
        assert result.exit_code == 2 and "is the input file" in result.output, output
        assert "--force" in result.output
    assert path.read_text() == "// my notes\n" + RAW
    forced = cli("decompile", path, "-o", path, "--force")
    assert forced.exit_code == 0 and "Decompiled by mercmac" in path.read_text()
    assert cli("decompile", path, "-o", tmp_path / "y.mcm").exit_code == 0  # another file: fine
    assert _built((tmp_path / "y.mcm").read_text()) == ["MD5,MR5,WS100"]


@pytest.mark.parametrize("args", [["describe", "--graph", ""], ["decompile", "-o", ""]])
def test_an_empty_file_name_is_refused(tmp_path, args):
    path = tmp_path / "x.mcm"
    path.write_text(RAW)
    result = cli(*args[:1], path, *args[1:])
    assert result.exit_code == 2 and "an empty file name" in result.output, result.output
    assert result.stdout == ""  # nothing decompiled or described to standard output instead


@pytest.mark.parametrize("command", ["decompile", "describe"])
def test_a_port_given_twice_is_refused(command):
    result = cli(command, "--port", "/dev/a", "--port", "/dev/b")
    assert result.exit_code == 2 and "give the port once" in result.output, result.output


def test_one_macro_is_one_macro(tmp_path):
    path = tmp_path / "x.mcm"
    path.write_text(RAW)
    result = cli("describe", path)
    assert result.exit_code == 0 and result.stdout.startswith("1 macro for "), result.output
