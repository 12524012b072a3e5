"""Soft limits used as the manual intends (MS176E §4.4.2): a focus jog that runs to them is
a correct program. Every clamp is reported, and a program (a line's `expect[...]`), a
scenario (`allow_hazards`) or the command line (`--allow-hazard`) accepts a hazard rule:
shown as accepted, never counted by --fail-on-hazard (docs/simulator.md, "Hazards")."""
from __future__ import annotations

import json

import pytest

from helpers.cli import cli, mercmac_process

JOG = """\
target C-663
const FAR = 9999999
autostart {{
    JL -20000, JH 20000
    SV 5000
    goto jog
}}
macro jog {{
    every 20ms {{
        when 1 {{ MR FAR, WF 1, AB 1 }}{up}
        when 2 {{ MR -9999999, WF 2, AB 1 }}{down}
    }}
}}
"""
PRESSES = ["--buttons", "1@0-2s,2@3s-9s,1@9.5s-20s", "--until", "25s"]


def _jog(tmp_path, up: str = "", down: str = ""):
    path = tmp_path / "focus.mcm"
    path.write_text(JOG.format(up=up, down=down))
    return path


def _json(*args) -> dict:
    result = cli("sim", *args, "--format", "json")
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


def test_each_clamp_of_a_new_target_is_reported(tmp_path):
    """Button 1 twice: the second jog up clamps again, from another place, to another
    target; it used to be left out (one hazard per command for the whole run)."""
    run = _json(_jog(tmp_path), *PRESSES)
    clamps = [(h["t_ms"], h["line"]) for h in run["hazards"] if h["rule"] == "soft-limit-clamp"]
    assert [line for _, line in clamps] == [10, 11, 10]
    assert "accepted_hazards" not in run


def test_a_line_that_expects_the_clamp_accepts_it_there_only(tmp_path):
    path = _jog(tmp_path, up="  // mercmac: expect[soft-limit-clamp]")
    run = _json(path, *PRESSES)
    assert [h["line"] for h in run["hazards"]] == [11]
    assert [h["line"] for h in run["accepted_hazards"]] == [10, 10]
    text = cli("sim", path, *PRESSES, "--fail-on-hazard")
    assert text.exit_code == 1 and "1 hazard found (--fail-on-hazard)" in text.stderr
    assert "accepted soft-limit-clamp: target 9999999" in text.stdout
    assert "0 LED changes, 1 hazard, 2 accepted" in text.stdout


def test_both_lines_accepting_pass_fail_on_hazard(tmp_path):
    mark = "  // mercmac: expect[MH003]"
    result = cli("sim", _jog(tmp_path, up=mark, down=mark), *PRESSES, "--fail-on-hazard")
    assert result.exit_code == 0, result.output
    assert "0 hazards, 3 accepted" in result.stdout


def test_allow_hazard_accepts_a_rule_for_the_whole_run(tmp_path):
    result = cli("sim", _jog(tmp_path), *PRESSES, "--fail-on-hazard",
                 "--allow-hazard", "soft-limit-clamp")
    assert result.exit_code == 0 and "0 hazards, 3 accepted" in result.stdout


@pytest.mark.parametrize("rule", ["soft-limt-clamp", "MM011", ""])
def test_allow_hazard_names_only_hazard_rules(tmp_path, rule):
    result = cli("sim", _jog(tmp_path), "--allow-hazard", rule or "x,,y")
    assert result.exit_code == 2 and "--allow-hazard: no hazard rule" in result.stderr
    assert "MH003 soft-limit-clamp" in result.stderr and "Traceback" not in result.output


def test_a_scenario_accepts_a_hazard_rule(tmp_path):
    scenario = tmp_path / "jog.toml"
    scenario.write_text('until = "25s"\nallow_hazards = ["soft-limit-clamp"]\n'
                        '[[step]]\nat = "0ms"\npress = [1]\n[[step]]\nat = "2s"\nrelease = [1]\n')
    result = cli("sim", _jog(tmp_path), "--scenario", scenario, "--fail-on-hazard")
    assert result.exit_code == 0, result.output
    scenario.write_text('allow_hazards = ["soft-limits"]\n')
    refused = cli("sim", _jog(tmp_path), "--scenario", scenario)
    assert refused.exit_code == 2 and "allow_hazards: no hazard rule 'soft-limits'" in refused.stderr


@pytest.mark.parametrize("comment, message", [
    ("// mercmac: expect[soft-limit]", "no hazard rule 'soft-limit'"),
    ("// mercmac: expect[soft-limit-clamp", "write `// mercmac: expect[RULE, ...]`"),
    ("// mercmac: expect[nested-call]", "no hazard rule 'nested-call'"),
])
def test_check_reports_an_expect_comment_that_accepts_nothing(tmp_path, comment, message):
    result = cli("check", _jog(tmp_path, up="  " + comment))
    assert "MM034 invalid-suppression" in result.stdout and message in result.stdout


def test_a_process_with_the_comment_and_the_option(tmp_path):
    done = mercmac_process("sim", str(_jog(tmp_path, up="  // mercmac: expect[soft-limit-clamp]")),
                           *PRESSES, "--fail-on-hazard", "--allow-hazard", "MH003",
                           cwd=tmp_path)
    assert done.returncode == 0 and "0 hazards, 3 accepted" in done.stdout, done.stderr
