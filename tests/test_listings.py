"""Macro listings: one reader of `[MCnn]`, `MDn,` and TM lines, one header pattern.

`mercmac.mdtext.listed` reads every line that names a macro by its slot, `RAW_HEADER` is the
one pattern of a raw block's header, `slot_name` and `tm_line` write a slot's name. The
compiler, fmt, highlighting, the decompiler's file reader and the uploader's TM parser go
through them, so they agree on every spelling: the differential tests below read the same
lines through each; the structure tests find no second pattern or writer in the package.
"""
from __future__ import annotations

import ast
import re
import warnings
from pathlib import Path

import pytest

import mercmac
from mercmac import mdtext
from mercmac.compiler.ast_builder import parse_module
from mercmac.decompile import read_macros
from mercmac.diagnostics import Report
from mercmac.fmt import format_text
from mercmac.highlight import McmLexer
from mercmac.mdtext import RAW_HEADER, Form, listed, slot_name, tm_line
from mercmac.upload import protocol

PACKAGE = Path(mercmac.__file__).parent

# What MMCRun and the manual write (MS176E §3.8.6), with blanks and signs as the grammar allows.
RAW_LINES = [f"[{a}{mc}{a}{sign}{digits}{a}]" for a in ("", " ", "\t ") for mc in ("MC", "mc", "Mc")
             for sign in ("", "+", "-", "+ ") for digits in ("5", "05", "005", "31", "0")]
MD_LINES = [f"{md}{a}{sign}{digits}{a}," for md in ("MD", "md") for a in ("", " ", "\t")
            for sign in ("", "+", "- ") for digits in ("5", "09", "31")]
TM_LINES = [f"{mc}{a}{digits}" for mc in ("MC", "mc") for a in ("", " ")
            for digits in ("005", "5", "05", "031", "000")]


@pytest.mark.parametrize("line, form, slot, header, body", [
    ("[MC05] BF,DP200", Form.RAW, 5, 6, " BF,DP200"),
    ("[ mc + 5 ]TP // x", Form.RAW, 5, 10, "TP // x"),
    ("[MC-3] TP", Form.RAW, -3, 6, " TP"),  # read, and refused by the compiler's slot check
    ("[MC" + "9" * 19 + "] TP", Form.RAW, None, 23, " TP"),  # no number: more than 18 digits
    ("MD5,MR5000,WS100", Form.MD, 5, 4, "MR5000,WS100"),
    ("md 5", Form.MD, 5, 4, ""),  # an empty definition
    ("MC001 MR55555", Form.TM, 1, 6, "MR55555"),
    ("MC000", Form.TM, 0, 5, ""),  # an empty slot as a bare header (docs/uploader.md)
    ("MC5 TP", Form.TM, 5, 4, "TP"),
])
def test_a_listing_line_is_read_as_its_form_slot_and_body(line, form, slot, header, body):
    assert listed(line) == (form, slot, header, body)


@pytest.mark.parametrize("line", ["MC0005 TP", "MC5TP", "MDx,TP", "MD5X,TP", "[MC] TP", "TP",
                                  "", "[MC5 TP", "MCx", "MC٣ TP", "MD٣,TP"])
def test_a_line_without_a_header_is_no_listing(line):
    assert listed(line) is None


def test_the_raw_header_is_grammar_larks():
    grammar = (PACKAGE / "grammar.lark").read_text(encoding="utf-8")
    raw_line = re.search(r"^RAW_LINE: /(.*)/i$", grammar, re.MULTILINE).group(1)
    assert raw_line == RAW_HEADER.replace("(?i:MC)", "MC") + r"[^\n]*"


@pytest.mark.parametrize("slot", [0, 5, 31])
def test_what_mdtext_writes_it_reads_back(slot):
    assert listed(tm_line(slot, "TP")) == (Form.TM, slot, 6, "TP")
    assert listed(tm_line(slot)) == (Form.TM, slot, 5, "")
    assert listed(f"[{slot_name(slot)}] TP") == (Form.RAW, slot, 6, " TP")
    assert listed(mdtext.md(slot, "TP")).slot == slot


# -- every reader reads a line as mdtext.listed does ------------------------------------------

@pytest.mark.parametrize("head", RAW_LINES)
def test_every_reader_of_a_raw_block_reads_its_slot_as_listed(head):
    line = f"{head} TP"
    found = listed(line)
    assert found.form is Form.RAW and found.header == len(head)
    assert read_macros(line + "\n") == {found.slot: "TP"}  # decompile and describe FILE
    module = parse_module(line + "\n", Report("x.mcm")).tree  # the compiler
    assert [(i.slot, i.span.end_column - 1) for i in module.items] == [(found.slot, len(head))]
    labels = [text for _, kind, text in McmLexer().get_tokens_unprocessed(line)
              if str(kind) == "Token.Name.Label"]
    assert labels == [head]  # highlighting
    assert format_text(line + "\n") == f"[{slot_name(found.slot)}] TP\n"  # fmt


@pytest.mark.parametrize("head", MD_LINES)
def test_every_reader_of_a_definition_reads_its_slot_as_listed(head):
    line = f"{head}TP"
    found = listed(line)
    assert found.form is Form.MD and found.body == "TP"
    assert mdtext.split_md(line) == (found.slot, "TP")  # the emulator, history
    assert read_macros(line + "\n") == {found.slot: "TP"}


@pytest.mark.parametrize("head", TM_LINES)
def test_every_reader_of_a_tm_report_reads_its_slot_as_listed(head):
    line = f"{head} TP"
    found = listed(line)
    assert found.form is Form.TM
    assert protocol.parse_macro_line(line) == (found.slot, "TP")  # the uploader
    assert protocol.is_macro_report(f"{line}\r\n{head}")
    assert read_macros(line + "\n") == {found.slot: "TP"}


# -- one of each in the package -----------------------------------------------------------------

def _strings(path: Path):
    """(line, text) of the string constants of a module that are not docstrings."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    docstrings = {id(node.body[0].value) for node in ast.walk(tree)
                  if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef))
                  and node.body and isinstance(node.body[0], ast.Expr)}
    return [(node.lineno, node.value) for node in ast.walk(tree)
            if isinstance(node, ast.Constant) and isinstance(node.value, str)
            and id(node) not in docstrings]


MODULES = sorted(p for p in PACKAGE.rglob("*.py")
                 if p.name != "parser_tables.py" and p != PACKAGE / "mdtext.py")
# A pattern that reads each form's headers, and not the same text with other letters.
HEADERS = {"[MCnn]": (["[MC05]", "[ mc + 5 ]"], "[XY05]"), "MCnnn": (["MC005", "mc 5"], "XY005"),
           "MDn,": (["MD5,", "md 5 ,"], "XY5,")}


def _header_patterns(path: Path) -> list[str]:
    found = []
    for line, text in _strings(path):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # "possible nested set": not a pattern of ours
            try:
                pattern = re.compile(text, re.IGNORECASE)
            except (re.error, RecursionError, OverflowError):
                continue
        found += [f"{path.relative_to(PACKAGE)}:{line} reads {form}" for form, (yes, no) in
                  HEADERS.items() if all(map(pattern.fullmatch, yes)) and not pattern.fullmatch(no)]
    return found


def test_only_mdtext_holds_a_pattern_of_a_listing_header():
    assert [where for path in MODULES for where in _header_patterns(path)] == []


def test_only_mdtext_writes_a_slot_as_mcnn():
    written = re.compile(r"MC\{[^}]*:0\d+d\}")  # f"MC{slot:02d}", f"MC{slot:03d}"
    assert [f"{path.relative_to(PACKAGE)}: {m.group()}" for path in MODULES
            for m in written.finditer(path.read_text(encoding="utf-8"))] == []
