"""`mercmac check RIG.rig.toml` (issue 18): the rig file's diagnostics and each program's,
in every output format, with --select/--ignore and check's exit codes; `explain MRnnn`."""
from __future__ import annotations

import json

import pytest

from helpers.cli import cli, mercmac_process
from mercmac.diagnostics import RULES
from helpers.rig_files import DEAD_X, DEAD_Y, RASTER, WIRES, controllers, write_rig


@pytest.fixture
def broken(tmp_path):
    """A rig with a repeated address (error), a wait cycle (warning) and a bad program line."""
    return write_rig(tmp_path, WIRES + controllers(y="0"), x=DEAD_X,
                     y=DEAD_Y.replace("MR 100", "MR"))


def test_the_raster_example_checks_clean():
    result = cli("check", RASTER)
    assert result.exit_code == 0, result.output
    assert "No problems found in 3 files" in result.output


def test_text_names_the_rig_file_line_and_column(broken):
    result = cli("check", broken)
    assert result.exit_code == 1
    assert f"{broken}:7:1: error[MR005 address-repeated]" in result.output
    assert f"{broken.parent / 'y.mcm'}:2:18: error[MM003 bad-argument]" in result.output


def test_json_has_one_entry_per_diagnostic_with_positions(broken):
    result = cli("check", broken, "--format", "json")
    found = {(d["code"], d["file"].rsplit("/", 1)[-1], d["line"], d["column"])
             for d in json.loads(result.output)["diagnostics"]}
    assert found == {("MR005", "r.rig.toml", 7, 1), ("MM003", "y.mcm", 2, 18)}


@pytest.mark.parametrize("fmt,expected", [
    ("concise", "r.rig.toml:7:1: MR005 [address-repeated]"),
    ("github", "::error file={rig},line=7,col=1,endLine=7,endColumn=8,title=MR005 address-repeated::"),
    ("sarif", '"ruleId": "MR005"'),
])
def test_every_output_format_takes_rig_diagnostics(broken, fmt, expected):
    result = cli("check", broken, "--output-format", fmt)
    assert result.exit_code == 1
    assert expected.format(rig=broken) in result.output


def test_a_warning_fails_only_with_warnings_as_errors(tmp_path):
    path = write_rig(tmp_path, x=DEAD_X, y=DEAD_Y)
    assert cli("check", path).exit_code == 0
    assert "MR011 wait-cycle" in cli("check", path).output
    assert cli("check", path, "--warnings-as-errors").exit_code == 1


def test_select_and_ignore_name_rig_rules(broken):
    assert cli("check", broken, "--select", "MR005").exit_code == 1
    only = cli("check", broken, "--select", "wait-cycle", "--format", "json").output
    assert [d["code"] for d in json.loads(only)["diagnostics"]] == []  # the cycle needs y to build
    ignored = cli("check", broken, "--ignore", "address-repeated,MM003", "--format", "json")
    assert ignored.exit_code == 0 and json.loads(ignored.output)["diagnostics"] == []


def test_a_rig_file_that_cannot_be_read_exits_2(tmp_path):
    result = cli("check", tmp_path / "none.rig.toml")
    assert result.exit_code == 2 and "cannot read" in result.output


def test_fix_refuses_a_rig_file(tmp_path):
    result = cli("check", "--fix", write_rig(tmp_path))
    assert result.exit_code == 2 and "rig file" in result.output


def test_a_rig_and_a_program_in_one_run(broken):
    result = cli("check", broken, RASTER.parent / "x.mcm", "--format", "json")
    assert len(json.loads(result.output)["diagnostics"]) == 2


@pytest.mark.parametrize("r", [r for r in RULES if r.code.startswith("MR")], ids=lambda r: r.code)
def test_explain_tells_each_rig_rule(r):
    result = cli("explain", r.code)
    assert result.exit_code == 0 and result.output.startswith(f"{r.code} {r.name}")


def test_check_as_a_real_process(broken, tmp_path):
    clean = mercmac_process("check", str(RASTER), cwd=tmp_path)
    assert clean.returncode == 0, clean.stderr
    failed = mercmac_process("check", str(broken), "--format", "json", cwd=tmp_path)
    assert failed.returncode == 1
    assert {d["code"] for d in json.loads(failed.stdout)["diagnostics"]} == {"MR005", "MM003"}
    bad = mercmac_process("check", str(tmp_path / "nothing.rig.toml"), cwd=tmp_path)
    assert bad.returncode == 2 and "Traceback" not in bad.stderr


def test_the_raster_programs_are_in_the_one_layout():
    result = cli("fmt", "--check", *sorted(RASTER.parent.glob("*.mcm")))
    assert result.exit_code == 0, result.output
