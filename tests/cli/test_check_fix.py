"""`mercmac check --fix` and `--diff`: the safe fixes are data on the diagnostics
(mercmac.diagnostics.Fix), applied to real files through the real CLI, in-process and as
a process; a file is written whole, byte for byte but for its fixes, or not at all."""
from __future__ import annotations

import json
import os
import stat

import pytest

from mercmac.compiler import fixing
from mercmac.diagnostics import Fix
from mercmac.source import Span
from helpers.cli import cli, mercmac_process
from helpers.files import leftovers

# One of each fix: a mnemonic (unsafe: another command), a const, a keyword written as a
# command (`cal`), a macro name, and a keyword the parser stops at (`whne`); `LED 1` has a
# hint and a fix that is only displayed (`CN`).
BROKEN = """\
// jog box
const FAST = 5000
macro scan { MRR 5, SV FASTT }
macro jog { cal scan, call scna, LED 1 }
autostart { call jog }
macro idle { whne 1 { TP } }
"""
FIXED = """\
// jog box
const FAST = 5000
macro scan { MR 5, SV FAST }
macro jog { call scan, call scan, LED 1 }
autostart { call jog }
macro idle { when 1 { TP } }
"""
CLEAN = "macro a { MR 5 }\nautostart { call a }\n"


def _write(path, text: str, *, end: str = "\n", encoding: str = "utf-8", bom: bytes = b""):
    path.write_bytes(bom + text.replace("\n", end).encode(encoding))
    return path


# -- in-process (click's CliRunner) ------------------------------------------------------------

def test_fix_makes_the_safe_fixes_and_says_which_it_made_and_which_it_did_not(tmp_path):
    f = _write(tmp_path / "jog.mcm", BROKEN)
    result = cli("check", "--fix", f)
    assert f.read_text(encoding="utf-8") == FIXED.replace("MR 5", "MRR 5")
    assert result.stderr.splitlines() == [
        f"fixed {f} (4 fixes):",
        "  3:24: undefined-name: Replace with 'FAST'",
        "  4:13: unknown-command: Replace with 'call'",
        "  4:28: undefined-name: Replace with 'scan'",
        "  6:14: syntax: Replace with 'when'",
        "1 file fixed (4 fixes)",
        "1 unsafe fix not made: each is a guess that may change what the program does "
        "(another command, one of several names); `--unsafe-fixes` makes them, "
        "`--diff --unsafe-fixes` shows them",
    ]
    # what remains is reported as `check` reports it, and makes the exit code
    assert result.exit_code == 1
    assert "unknown command 'LED'" in result.stdout and "unknown command 'MRR'" in result.stdout
    assert result.stdout.rstrip().endswith("2 errors, 0 warnings, 1 info in 1 file.")


def test_unsafe_fixes_makes_the_guesses_too_and_labels_them(tmp_path):
    f = _write(tmp_path / "jog.mcm", BROKEN)
    result = cli("check", "--fix", "--unsafe-fixes", f)
    assert f.read_text(encoding="utf-8") == FIXED
    assert "  3:14: unknown-command: Replace with 'MR' (unsafe)" in result.stderr.splitlines()
    assert "unsafe fix not made" not in result.stderr
    assert "MRR" not in result.stdout and result.exit_code == 1  # LED 1 is never fixed


@pytest.mark.parametrize("written", ["XM 1, WG 2", "MQ 5000", "MS 100"])
def test_a_command_guessed_by_its_spelling_is_never_a_safe_fix(tmp_path, written):
    """`XM 1` (a condition? a call?) became `EM 1`, `WG 2` a 2 ms wait, `MQ 5000` a filter
    setting: another command changes what the program does, so --fix leaves it."""
    text = f"target C-863\nautostart {{\n    {written}\n}}\n"
    f = _write(tmp_path / "t.mcm", text)
    result = cli("check", "--fix", f)
    assert f.read_text() == text and result.exit_code == 1
    assert "unsafe fix" in result.stderr and "--unsafe-fixes" in result.stderr


def test_unsafe_fixes_alone_is_a_usage_error(tmp_path):
    f = _write(tmp_path / "a.mcm", CLEAN)
    result = cli("check", "--unsafe-fixes", f)
    assert result.exit_code == 2 and "--unsafe-fixes goes with --fix or --diff" in result.stderr


def test_a_file_fixed_clean_exits_0_and_later_checks_find_nothing(tmp_path):
    f = _write(tmp_path / "a.mcm", "macro scan { MR 5 }\nautostart { call scna }\n")
    assert cli("check", "--fix", f).exit_code == 0
    again = cli("check", f)
    assert again.exit_code == 0 and again.stdout == "No problems found in 1 file.\n"


def test_a_fix_that_brings_out_another_is_made_in_a_second_pass(tmp_path):
    f = _write(tmp_path / "a.mcm", "macro scan { MR 5 }\nautostart { cal scna }\n")
    result = cli("check", "--fix", f)
    assert f.read_text() == "macro scan { MR 5 }\nautostart { call scan }\n"
    assert result.stderr.splitlines()[1:3] == ["  2:13: unknown-command: Replace with 'call'",
                                               "  2:18: undefined-name: Replace with 'scan'"]
    assert result.exit_code == 0


def test_a_keyword_that_would_need_a_block_is_said_but_not_written(tmp_path):
    text = "macro a { whn 1 }\n"
    f = _write(tmp_path / "a.mcm", text)
    result = cli("check", "--fix", f)
    assert f.read_text() == text
    assert "did you mean 'when'?" in result.stdout and result.exit_code == 1
    assert result.stderr.strip() == "1 file left unchanged"


def test_a_suppressed_finding_is_not_fixed(tmp_path):
    text = "macro a { MRR 5 } // mercmac: ignore[unknown-command]\n"
    f = _write(tmp_path / "a.mcm", text)
    assert cli("check", "--fix", f).exit_code == 0
    assert f.read_text() == text


def test_a_file_with_nothing_to_fix_is_not_written(tmp_path):
    f = _write(tmp_path / "a.mcm", "macro a { MR 5 }\nautostart { LED 1 }\n")
    before = os.stat(f)
    result = cli("check", "--fix", f)
    assert os.stat(f).st_mtime_ns == before.st_mtime_ns and os.stat(f).st_ino == before.st_ino
    assert result.stderr.strip() == "1 file left unchanged"
    assert result.exit_code == 1 and "unknown command 'LED'" in result.stdout


@pytest.mark.parametrize("end", ["\n", "\r\n", "\r"], ids=["LF", "CRLF", "CR"])
def test_the_target_goes_below_the_leading_comments_with_the_files_line_end(tmp_path, end):
    text = "// a jog box\n// for the bench\n\nmacro a { MR 5 }\n"
    f = _write(tmp_path / "a.mcm", text, end=end)
    result = cli("check", "--fix", "--target", "c-863", f)
    assert f.read_bytes() == text.replace("\nmacro", "\ntarget C-863\nmacro").replace(
        "\n", end).encode()
    assert "  4:1: Add `target C-863`" in result.stderr.splitlines()
    assert result.exit_code == 0


@pytest.mark.parametrize("text, fixed", [
    ("// only a comment", "// only a comment\ntarget C-663\n"),
    ("// only a comment\n", "// only a comment\ntarget C-663\n"),
    ("", "target C-663\n"),
])
def test_the_target_of_a_file_with_no_code_goes_on_a_line_of_its_own(tmp_path, text, fixed):
    f = _write(tmp_path / "a.mcm", text)
    cli("check", "--fix", "--target", "C-663", f)
    assert f.read_text() == fixed


def test_no_target_is_added_without_a_model_chosen_nor_to_a_file_that_names_one(tmp_path):
    bare = _write(tmp_path / "bare.mcm", CLEAN)
    named = _write(tmp_path / "named.mcm", "macro a { MR 5 }  target C-663\n")
    for result in (cli("check", "--fix", bare), cli("check", "--fix", "--target", "C-863", named)):
        assert result.exit_code == 0 and result.stderr == "1 file left unchanged\n"
    assert bare.read_text() == CLEAN and "C-863" not in named.read_text()


def test_the_settings_model_is_the_target_added(tmp_path):
    (tmp_path / "mercmac.toml").write_text('target = "C-863"\n')
    f = _write(tmp_path / "a.mcm", CLEAN)
    cli("check", "--fix", f)
    assert f.read_text() == "target C-863\n" + CLEAN


def test_diff_prints_the_fixes_and_writes_nothing(tmp_path):
    f = _write(tmp_path / "jog.mcm", BROKEN)
    before = os.stat(f)
    result = cli("check", "--diff", "--unsafe-fixes", f)
    assert f.read_text() == BROKEN and os.stat(f).st_mtime_ns == before.st_mtime_ns
    assert result.exit_code == 1  # a file would change, as `fmt --diff` says it
    assert result.stdout.startswith(f"--- {f}\n+++ {f}\n@@")
    changed = result.stdout.splitlines()
    assert "-macro scan { MRR 5, SV FASTT }" in changed
    assert "+macro scan { MR 5, SV FAST }" in changed
    assert "unknown command" not in result.stdout  # the diff is the output
    assert f"would fix {f} (5 fixes):" in result.stderr
    assert result.stderr.splitlines()[-1] == "1 file would be fixed (5 fixes)"
    assert leftovers(tmp_path) == []


def test_diff_of_files_with_nothing_to_fix_is_empty_and_exits_0(tmp_path):
    f = _write(tmp_path / "a.mcm", "autostart { LED 1 }\n")
    result = cli("check", "--diff", f)
    assert result.stdout == "" and result.exit_code == 0


def test_diff_reads_standard_input_and_fix_refuses_it():
    result = cli("check", "--diff", "--unsafe-fixes", "-", input="macro a { MRR 5 }\n")
    assert "+macro a { MR 5 }" in result.stdout and result.exit_code == 1
    refused = cli("check", "--fix", "-", input="macro a { MRR 5 }\n")
    assert refused.exit_code == 2 and refused.stdout == ""
    assert "standard input" in refused.stderr and "--diff" in refused.stderr


def test_json_output_stays_json_and_holds_what_remains(tmp_path):
    f = _write(tmp_path / "jog.mcm", BROKEN)
    result = cli("check", "--fix", "--output-format", "json", f)
    remaining = json.loads(result.stdout)["diagnostics"]
    assert [(d["rule"], d["line"]) for d in remaining] == [("unknown-command", 3),
                                                           ("unknown-command", 4),
                                                           ("unreachable-macro", 6)]
    assert [d.get("fix", {}).get("applicability") for d in remaining] == [
        "unsafe", "display-only", None]
    assert "fixed" in result.stderr


def test_each_file_of_a_folder_is_fixed_and_counted(tmp_path):
    _write(tmp_path / "a.mcm", BROKEN)
    _write(tmp_path / "b.mcm", CLEAN)
    result = cli("check", "--fix", "--unsafe-fixes", tmp_path)
    assert (tmp_path / "a.mcm").read_text() == FIXED and (tmp_path / "b.mcm").read_text() == CLEAN
    assert result.stderr.splitlines()[-1] == "1 file fixed (5 fixes), 1 file left unchanged"


# -- files that cannot be fixed ------------------------------------------------------------------

def test_a_read_only_file_is_left_as_it_was_and_its_problems_reported(tmp_path):
    f = _write(tmp_path / "jog.mcm", BROKEN)
    f.chmod(0o444)  # refused by its mode, even as root (mercmac.outfile)
    result = cli("check", "--fix", f)
    assert f.read_text() == BROKEN and stat.S_IMODE(f.stat().st_mode) == 0o444
    assert leftovers(tmp_path) == []
    assert result.exit_code == 2
    assert "read-only; not fixed" in result.stderr and "1 file not fixed" in result.stderr
    assert "unknown command 'MRR'" in result.stdout  # the file as it still is


def test_undecodable_bytes_are_named_and_the_file_left_as_it_was(tmp_path):
    # 0x81 is neither UTF-8 nor Windows-1252: writing the text back would lose it
    data = b"// caf\x81\nmacro a { MRR 5 }\n"
    f = tmp_path / "a.mcm"
    f.write_bytes(data)
    result = cli("check", "--fix", "--unsafe-fixes", f)
    assert f.read_bytes() == data and result.exit_code == 2
    assert "byte 0x81 at line 1, column 7" in result.stderr and "not fixed" in result.stderr
    assert "unknown command 'MRR'" in result.stdout


def test_undecodable_bytes_do_not_matter_when_there_is_nothing_to_fix(tmp_path):
    data = b"// caf\x81\nmacro a { MR 5 }\n"
    f = tmp_path / "a.mcm"
    f.write_bytes(data)
    result = cli("check", "--fix", f)
    assert f.read_bytes() == data and result.exit_code == 0


# -- overlapping fixes (the library) ---------------------------------------------------------------

def test_a_fix_that_overlaps_one_made_before_it_is_left_for_the_next_pass():
    text = "macro a { MRR 5 }\n"
    first = Fix(Span(1, 11, 1, 14), "MR", "Replace with 'MR'")
    inside = Fix(Span(1, 12, 1, 16), "X", "Replace with 'X'")
    fixed, made = fixing.apply(text, [fixing.Made(inside, None), fixing.Made(first, None)])
    assert fixed == "macro a { MR 5 }\n" and [m.fix for m in made] == [first]


def test_the_same_fix_twice_is_made_once_and_an_insertion_before_a_replacement_both():
    text = "whne 1 { TP }\n"
    word = Fix(Span(1, 1, 1, 5), "when", "Replace with 'when'")
    insert = Fix(Span(1, 1, 1, 1), "target C-863\n", "Add `target C-863`")
    made = [fixing.Made(f, None) for f in (word, insert, word)]
    assert fixing.apply(text, made)[0] == "target C-863\nwhen 1 { TP }\n"


# -- as a process: bytes kept as they were ---------------------------------------------------------

@pytest.mark.parametrize("encoding, bom, end", [
    ("utf-8", b"\xef\xbb\xbf", "\r\n"),
    ("cp1252", b"", "\r\n"),  # MMCRun's '(TM)' sign, 0x99 in Windows-1252
    ("utf-16-le", b"\xff\xfe", "\n"),
], ids=["utf-8-bom-crlf", "cp1252-crlf", "utf-16-bom"])
def test_a_process_fixes_the_words_and_keeps_every_other_byte(tmp_path, encoding, bom, end):
    text = "// MMCRun\u2122 export\n" + BROKEN.split("\n", 1)[1]
    f = _write(tmp_path / "jog.mcm", text, end=end, encoding=encoding, bom=bom)
    done = mercmac_process("check", "--fix", "--unsafe-fixes", "--target", "C-863", str(f),
                           cwd=tmp_path)
    expected = "// MMCRun\u2122 export\ntarget C-863\n" + FIXED.split("\n", 1)[1]
    assert f.read_bytes() == bom + expected.replace("\n", end).encode(encoding)
    assert done.returncode == 1, done.stderr
    assert "Add `target C-863`" in done.stderr and "1 file fixed (6 fixes)" in done.stderr


def test_a_process_diff_writes_nothing_and_applies_as_the_fix(tmp_path):
    f = _write(tmp_path / "jog.mcm", BROKEN)
    done = mercmac_process("check", "--diff", "--unsafe-fixes", str(f), cwd=tmp_path)
    assert done.returncode == 1 and f.read_text() == BROKEN
    hunk = done.stdout.splitlines()[3:]  # one hunk: the whole file
    assert [line[1:] for line in hunk if not line.startswith("-")] == FIXED.splitlines()


# -- the applicability in the outputs for programs ----------------------------------------------

def test_json_and_sarif_carry_each_fix_with_its_applicability(tmp_path):
    f = _write(tmp_path / "a.mcm", "macro scan { TP }\nautostart { call scna, XM 1 }\n")
    found = json.loads(cli("check", "--format", "json", f).stdout)["diagnostics"]
    (fixed, guessed) = [d for d in found if "fix" in d]
    assert fixed["fix"] == {"applicability": "safe", "message": "Replace with 'scan'",
                            "edits": [{"content": "scan", "line": 2, "column": 18,
                                       "end_line": 2, "end_column": 22}]}
    assert guessed["fix"]["applicability"] == "unsafe"
    results = json.loads(cli("check", "--format", "sarif", f).stdout)["runs"][0]["results"]
    (safe,), (unsafe,) = (r["fixes"] for r in results if "fixes" in r)
    assert safe["properties"] == {"applicability": "safe"}
    assert safe["artifactChanges"][0]["replacements"] == [{
        "deletedRegion": {"startLine": 2, "startColumn": 18, "endLine": 2, "endColumn": 22},
        "insertedContent": {"text": "scan"}}]
    assert unsafe["properties"] == {"applicability": "unsafe"}
    assert unsafe["description"] == {"text": "Replace with 'XF'"}


@pytest.mark.parametrize("text, applicability", [
    ("macro scan { TP }\nautostart { call scna }\n", "safe"),  # the one macro that near
    ("macro scan { TP }\nmacro scab { TP }\nautostart { call sca }\n", "unsafe"),  # two
    ("const FAST = 5\nconst FIST = 6\nautostart { SV FEST }\n", "unsafe"),
    ("const FAST = 5\nautostart { SV FST }\n", "safe"),
    ("autostart { whne 1 { TP } }\n", "safe"),
])
def test_a_name_or_keyword_is_safe_only_with_one_candidate(tmp_path, text, applicability):
    f = _write(tmp_path / "a.mcm", text)
    (fixable,) = [d for d in json.loads(cli("check", "--format", "json", f).stdout)["diagnostics"]
                  if "fix" in d]
    assert fixable["fix"]["applicability"] == applicability
