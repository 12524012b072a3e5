"""`mercmac check`, `build` and `explain` through click's runner and as a real process."""
from __future__ import annotations

import json
import os
import subprocess
import sys

from click.testing import CliRunner

from helpers.cli import cli
from helpers.paths import EXAMPLE3, EXAMPLE4, FOUR_MODES, ROOT
from mercmac.cli import main

EX4 = str(EXAMPLE4)
EX3 = str(EXAMPLE3)
FOUR = str(FOUR_MODES)


def test_check_clean_file_exits_0():
    r = cli("check", FOUR)
    assert r.exit_code == 0 and "No problems found in 1 file." in r.output


def test_check_with_errors_exits_1_errors_first_and_a_count():
    r = cli("check", EX3, EX4)
    assert r.exit_code == 1
    lines = [l for l in r.output.splitlines() if "[MM" in l]
    severities = [l.split(": ")[1].split("[")[0] for l in lines]
    assert severities == sorted(severities, key=["error", "warning", "info"].index)
    assert r.output.rstrip().endswith("3 errors, 3 warnings, 7 infos in 2 files.")


def test_check_unreadable_file_exits_2(tmp_path):
    r = cli("check", str(tmp_path / "missing.mcm"))
    assert r.exit_code == 2 and "cannot read" in r.output


def test_check_json_is_spec_shaped():
    r = cli("check", "--format", "json", EX3)
    data = json.loads(r.output)
    assert r.exit_code == 1
    first = data["diagnostics"][0]
    assert set(first) == {"rule", "code", "severity", "file", "line", "column", "end_line",
                          "end_column", "message"}
    assert [(d["rule"], d["line"]) for d in data["diagnostics"]] == [
        ("duplicate-slot", 7), ("syntax", 7), ("duplicate-slot", 8)]


def test_check_target_option_overrides_file(tmp_path):
    prog = tmp_path / "p.mcm"
    prog.write_text("target C-863\n[MC01] DP200\n")
    assert cli("check", str(prog)).exit_code == 0
    r = cli("check", "--target", "C-663", str(prog))
    assert r.exit_code == 1 and "model-unsupported" in r.output


def test_build_prints_md_lines_macro_0_last():
    r = cli("build", EX4)
    lines = r.stdout.splitlines()
    assert r.exit_code == 0 and lines[-1] == "MD0,EM9,EM10" and lines[0].startswith("MD9,BF,DP200")
    assert len(lines) == 23


def test_build_shows_warnings_on_stderr_and_goes_on():
    """Example 4 has three nested-call warnings: shown, and the MD lines still printed."""
    r = cli("build", EX4)
    assert r.exit_code == 0 and r.stderr.count("warning[MM011 nested-call]") == 3
    assert "warning" not in r.stdout and r.stdout.startswith("MD9,")


def test_build_writes_output_file(tmp_path):
    out = tmp_path / "prog.md"
    r = cli("build", FOUR, "-o", str(out))
    assert r.exit_code == 0 and r.output == ""
    assert out.read_text().splitlines()[-1].startswith("MD0,")


def test_build_refuses_on_errors():
    r = CliRunner(mix_stderr=False).invoke(main, ["build", EX3]) if "mix_stderr" in CliRunner.__init__.__code__.co_varnames else CliRunner().invoke(main, ["build", EX3])
    assert r.exit_code == 1 and "MD" not in r.stdout
    assert "duplicate-slot" in r.stderr


def test_explain_by_code_and_name():
    by_code, by_name = cli("explain", "MM011"), cli("explain", "nested-call")
    assert by_code.exit_code == 0 and by_code.output == by_name.output
    assert "§3.8.4" in by_code.output


def test_explain_unknown_rule_exits_2():
    r = cli("explain", "no-such-rule")
    assert r.exit_code == 2 and "no rule" in r.output


def _process(*args, env=None):
    return subprocess.run([sys.executable, "-m", "mercmac", *args], capture_output=True,
                          text=True, cwd=ROOT, env={**os.environ, **(env or {})}, timeout=60)


def test_real_process_check_and_build():
    p = _process("check", EX4)
    assert p.returncode == 0 and "nested-call" in p.stdout and "\x1b[" not in p.stdout
    p = _process("build", EX3)
    assert p.returncode == 1 and p.stdout == "" and "EM takes a macro number 1-31" in p.stderr


def test_colour_only_when_forced_and_never_with_no_color():
    assert "\x1b[" in _process("check", EX4, env={"FORCE_COLOR": "1"}).stdout
    assert "\x1b[" not in _process("check", EX4, env={"FORCE_COLOR": "1", "NO_COLOR": "1"}).stdout


def test_usage_errors_exit_2():
    assert _process("check").returncode == 2
    assert _process("check", "--target", "C-999", EX4).returncode == 2
