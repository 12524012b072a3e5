"""`mercmac fmt`: one canonical layout, idempotent, never a different build."""
from __future__ import annotations

import re

import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from helpers.budgets import budget
from helpers.formatting import assert_formats_safely
from helpers.paths import EXAMPLES, EXAMPLE_FILES
from mercmac.cli import main
from mercmac.fmt import FormatError, format_text, load
from helpers.programs import programs

# -- the layout ---------------------------------------------------------------------------------

@pytest.mark.parametrize("text, expected", [
    ("macro  a@20{mr5000,ws 10}\n", "macro a @20 { MR 5000, WS 10 }\n"),
    ("target c-863\nconst  FAST=+ 5\n", "target C-863\nconst FAST = +5\n"),
    ("autostart {\nwhen 1 and not  2{ mr -5 }  cp 1,\n  every 20 MS {call b}\n}\nmacro b {}\n",
     "autostart {\n    when 1 and not 2 { MR -5 } CP 1,\n    every 20ms { call b }\n}\n"
     "macro b { }\n"),
    ("macro a {\n  every 5ms {\n      MR 1\n      }\n   }\n",
     "macro a {\n    every 5ms {\n        MR 1\n    }\n}\n"),
    ("  [ mc 5 ]  bf, dp200 ,di,\n", "[MC05] BF,DP200,DI,\n"),
    ("[MC+6]em + 9,em10\n", "[MC06] EM+9,EM10\n"),  # MMCRun writes the sign: EM+9
    ("[MC18] xn4,  EMxx   // as printed\n", "[MC18] xn4,  EMxx   // as printed\n"),
    ("\n\n// head\n\n\n\n\n\n[MC00] EM1\n\n\n", "// head\n\n\n\n[MC00] EM1\n"),
    ("macro a { // why\n  // alone\n    MR 1      // trailing\n}\n",
     "macro a {   // why\n    // alone\n    MR 1   // trailing\n}\n"),
    ("", ""),
])
def test_the_canonical_layout(text, expected):
    assert format_text(text) == expected
    assert_formats_safely(text)


def test_crlf_files_stay_crlf_and_lf_files_stay_lf():
    assert format_text("[MC00] em1\r\nmacro a {mr1}\r\n") == "[MC00] EM1\r\nmacro a { MR 1 }\r\n"
    assert format_text("// c\r\n[MC00] em1   // d\r\n") == "// c\r\n[MC00] EM1   // d\r\n"
    assert format_text("[MC00] em1\n") == "[MC00] EM1\n"


@pytest.mark.parametrize("text", ["macro a { MR 1\n", "MR5000\n", "macro { }\n", "a\x00b\n"])
def test_a_file_that_does_not_parse_is_refused(text):
    with pytest.raises(FormatError):
        format_text(text)


def test_files_keep_their_encoding():
    mmcrun = "// Mercury\u2122 Macro File\r\n[MC00] em1\r\n".encode("cp1252")
    assert load(mmcrun) == ("// Mercury\u2122 Macro File\r\n[MC00] em1\r\n", "cp1252")
    assert load("\ufeff[MC00] EM1\n".encode("utf-8"))[1] == "utf-8-sig"


# -- the properties: on every example and on generated programs ---------------------------------

@pytest.mark.parametrize("path", EXAMPLE_FILES, ids=lambda p: p.name)
def test_examples_are_formatted_and_formatting_them_changes_nothing(path):
    text = load(path.read_bytes())[0]
    assert assert_formats_safely(text) == text


def _mess(draw, text: str) -> str:
    """The same program in another layout: blanks, case, line breaks and comments moved about."""
    out = []
    for token in re.findall(r"[A-Z]{2} (?=-?\d)|, |\n *|[^,\n]", text):
        if re.fullmatch(r"[A-Z]{2} ", token):  # `mr5000`, `Mr 5000`, `MR\t5000`
            word = draw(st.sampled_from([token[:2], token[:2].lower(), token[:2].capitalize()]))
            out.append(word + draw(st.sampled_from(["", " ", "\t"])))
            continue
        if token == ", ":
            token = draw(st.sampled_from([",", " , ", ", ", ",\n", ",   \n  "]))
        elif token.startswith("\n"):
            token = draw(st.sampled_from(["\n", "\n\n", "\n\t  ", "   // note\n", "\n// own\n"]))
        elif token == " ":
            token = draw(st.sampled_from([" ", "  ", "\t"]))
        out.append(token)
    return "".join(out).replace("MR -", "MR -" if draw(st.booleans()) else "MR- ")


@st.composite
def messy_programs(draw):
    text = draw(programs())
    return _mess(draw, text)


RAW_COMMANDS = st.sampled_from(["mr5", "MR -5", "em + 9", "Xn1", "WA 20", "DI", "rp", "cp 15",
                                "SV80000", "tp", "mr fast", "EMxx", "zz9"])


@st.composite
def raw_files(draw):
    lines = []
    for _ in range(draw(st.integers(1, 5))):
        slot = draw(st.sampled_from(["00", "5", "+7", " 12 ", "031"]))
        commands = draw(st.lists(RAW_COMMANDS, min_size=0, max_size=6))
        sep = draw(st.sampled_from([",", ", ", " ,"]))
        tail = draw(st.sampled_from(["", ",", "   // c", " //x"]))
        lines.append(f"[MC{slot}] {sep.join(commands)}{tail}")
    return "\n".join(lines) + "\n"


@pytest.mark.slow
@settings(max_examples=budget(200), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(messy_programs())
def test_random_programs_format_idempotently_to_the_same_build(text):
    assert_formats_safely(text)


@settings(max_examples=budget(200), deadline=None)
@given(raw_files())
def test_random_raw_blocks_format_idempotently_to_the_same_build(text):
    assert_formats_safely(text)


NOISE = st.sampled_from(list("[]{},@=-+?0123456789 \t\nMCEWXNFRPSVTabcdefmnorstw/\r"))


@settings(max_examples=budget(200), deadline=None)
@given(st.sampled_from(EXAMPLE_FILES), st.data())
def test_mangled_examples_are_formatted_safely_or_refused(path, data):
    text = load(path.read_bytes())[0]
    at = data.draw(st.integers(0, len(text)))
    cut = data.draw(st.integers(0, 3))
    text = text[:at] + "".join(data.draw(st.lists(NOISE, max_size=4))) + text[at + cut:]
    try:
        assert_formats_safely(text)
    except FormatError:
        pass


# -- the command --------------------------------------------------------------------------------

def test_fmt_check_passes_on_every_example():
    result = CliRunner().invoke(main, ["fmt", "--check", *map(str, EXAMPLE_FILES)])
    assert result.exit_code == 0, result.output


@pytest.fixture
def messy(tmp_path):
    path = tmp_path / "a.mcm"
    path.write_bytes(b"macro a {mr5}\r\n[MC00] em+9\r\n")
    return path


def test_fmt_check_and_diff_exit_1_and_change_nothing(messy):
    before = messy.read_bytes()
    check = CliRunner().invoke(main, ["fmt", "--check", str(messy)])
    assert check.exit_code == 1 and "would reformat" in check.output
    diff = CliRunner().invoke(main, ["fmt", "--diff", str(messy)])
    assert diff.exit_code == 1
    assert "-macro a {mr5}" in diff.output and "+macro a { MR 5 }" in diff.output
    assert messy.read_bytes() == before


def test_fmt_rewrites_the_file_then_check_passes(messy):
    assert CliRunner().invoke(main, ["fmt", str(messy)]).exit_code == 0
    assert messy.read_bytes() == b"macro a { MR 5 }\r\n[MC00] EM+9\r\n"
    assert CliRunner().invoke(main, ["fmt", "--check", str(messy)]).exit_code == 0
    assert CliRunner().invoke(main, ["fmt", "--diff", str(messy)]).output.count("\n") == 1


def test_fmt_leaves_a_file_with_syntax_errors_alone_and_exits_2(tmp_path, messy):
    broken = tmp_path / "b.mcm"
    broken.write_text("macro a { mr5\n")
    result = CliRunner().invoke(main, ["fmt", str(broken), str(messy)])
    assert result.exit_code == 2 and "cannot format" in result.output
    assert broken.read_text() == "macro a { mr5\n"
    assert messy.read_text().startswith("macro a { MR 5 }")  # the other files are done


def test_fmt_reads_standard_input_and_writes_standard_output():
    result = CliRunner().invoke(main, ["fmt", "-"], input="autostart{tp}\n")
    assert result.exit_code == 0 and result.stdout == "autostart { TP }\n"
    check = CliRunner().invoke(main, ["fmt", "--check", "-"], input="autostart{tp}\n")
    assert check.exit_code == 1 and "autostart" not in check.stdout


def test_fmt_of_a_missing_file_exits_2(tmp_path):
    assert CliRunner().invoke(main, ["fmt", str(tmp_path / "none.mcm")]).exit_code == 2


def test_fmt_takes_a_folder_like_check(tmp_path):
    """A folder means every .mcm below it; a folder with none is a usage error (exit 2)."""
    assert CliRunner().invoke(main, ["fmt", "--check", str(EXAMPLES)]).exit_code == 0
    (tmp_path / "sub").mkdir()
    messy = tmp_path / "sub" / "a.mcm"
    messy.write_text("autostart{mr 5}\n", encoding="utf-8")
    result = CliRunner().invoke(main, ["fmt", str(tmp_path)])
    assert result.exit_code == 0 and messy.read_text(encoding="utf-8") == "autostart { MR 5 }\n"
    empty = tmp_path / "empty"
    empty.mkdir()
    assert CliRunner().invoke(main, ["fmt", str(empty)]).exit_code == 2
