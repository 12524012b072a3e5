"""A sign before a const in a command's argument, as before a number: `MR -FAR` (MS176E §6.4
MR takes signed distances; the manual's Example 4 has `MR-9999999`). The compiler, fmt, the
AST printer, the language server's names and the highlighter all read it."""
from __future__ import annotations

import pytest
from pygments.token import Name, Operator

from helpers.compiling import compile_text, program_of, rules
from helpers.formatting import assert_formats_safely
from mercmac.compiler import ast
from mercmac.compiler.ast_builder import parse_module
from mercmac.compiler.fixing import Made, apply
from mercmac.diagnostics import Report
from mercmac.fmt import printer
from mercmac.highlight import McmLexer
from mercmac.lsp import symbols
from mercmac.source import Source

FAR = "const FAR = 9999999\n"


@pytest.mark.parametrize("written, stored", [
    ("MR -FAR", "MR-9999999"), ("MR - FAR", "MR-9999999"), ("MR-FAR", "MR-9999999"),
    ("MR +FAR", "MR9999999"), ("MR FAR", "MR9999999"), ("MA -FAR", "MA-9999999"),
])
def test_a_signed_const_lowers_to_the_signed_number(written, stored):
    program = program_of(f"{FAR}autostart {{ {written} }}\n")
    assert program.macros[0].line == stored


def test_a_negative_const_negated_is_positive():
    assert program_of("const BACK = -5\nautostart { MR -BACK }\n").macros[0].line == "MR5"


@pytest.mark.parametrize("text", [
    "const HUGE = 1073741824\nautostart { MA -HUGE }\n",  # MS176E §6.4 MA: +/-1,073,741,823
    "const ONE = 1\nautostart { CN -ONE }\n",  # outputs 1-4
    "const ONE = 1\nautostart { EM -ONE }\n",  # macros 1-31
])
def test_a_signed_const_is_range_checked_as_its_number(text):
    assert rules(text) == ["argument-range"]


def test_the_range_error_marks_the_signed_name():
    [found] = compile_text("const HUGE = 1073741824\nautostart { MA -HUGE }\n").report.items
    assert found.message.startswith("MA-1073741824 is out of range")
    assert (found.span.column, found.span.end_column) == (16, 21)  # `-HUGE`


def test_a_misspelt_signed_const_is_fixed_without_losing_its_sign():
    text = f"{FAR}autostart {{ MR -FRA }}\n"
    result = compile_text(text)
    assert [d.rule.name for d in result.report.items] == ["undefined-name"]
    fixed, _ = apply(text, [Made(d.fix, d) for d in result.report.items])
    assert fixed == f"{FAR}autostart {{ MR -FAR }}\n"


@pytest.mark.parametrize("text", ["when -FAR { TP }", "repeat -FAR { TP }"])
def test_only_a_commands_argument_takes_a_sign_before_a_name(text):
    assert rules(f"{FAR}autostart {{ {text} }}\n") == ["syntax"]


def test_fmt_writes_it_as_a_signed_number_is_written():
    text = f"{FAR}autostart {{ MR  -   FAR, MR+FAR, MR -5 }}\n"
    assert assert_formats_safely(text) == f"{FAR}autostart {{ MR -FAR, MR +FAR, MR -5 }}\n"


def test_the_ast_printer_writes_the_sign():
    module = parse_module(f"{FAR}autostart {{ MR -FAR, MR FAR }}\n", Report("a.mcm")).tree
    printed = printer.module(module.items)
    assert "MR -FAR, MR FAR" in printed
    again = parse_module(printed, Report("a.mcm")).tree
    [command, _] = again.items[-1].body
    assert command.value == ast.Name("FAR", command.value.span, "-")


def test_the_language_server_finds_and_renames_the_name_not_its_sign():
    text = f"{FAR}autostart {{ MR -  FAR, MR FAR }}\n"
    source = Source("a.mcm", text)
    items = parse_module(text, Report("a.mcm")).tree.items
    found = [u for u in symbols.uses(items, source) if u.kind == "const"]
    assert [source.line(u.span.line)[u.span.column - 1:u.span.end_column - 1] for u in found] \
        == ["FAR", "FAR", "FAR"]
    assert len(symbols.same(found, symbols.use_at(found, 2, 19))) == 3  # on `FAR` of `-  FAR`


def test_the_highlighter_shows_the_sign_and_the_const():
    text = f"{FAR}autostart {{ MR -FAR }}\n"
    tokens = [(k, v) for k, v in McmLexer().get_tokens(text) if v.strip()]
    assert (Operator, "-") in tokens and tokens.count((Name.Constant, "FAR")) == 2


def test_a_raw_block_says_why_it_takes_no_signed_name():
    """A raw block is a stored line, numbers only (MS176E §3.8.6): `-FAR` is named as a name,
    not as a stray '-'."""
    [found] = compile_text(f"{FAR}[MC01] MR-FAR\n").report.items
    assert found.rule.name == "bad-argument"
    assert found.message == "MR takes a distance, found '-FAR' (a raw block takes numbers only)"
