"""`mercmac check RIG.rig.toml`: the rig file's diagnostics and each program's,
in every output format, with --select/--ignore and check's exit codes; `explain MRnnn`."""
from __future__ import annotations

import json

import pytest

from helpers.cli import cli, mercmac_process
from mercmac.diagnostics import RULES
from helpers.rigs import DEAD_X, DEAD_Y, RASTER, WIRES, controllers, write_rig


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


# -- hostile rig files through every command that takes a rig ----------------------------------

SECRET = "aws_secret_access_key = hunter2\n"
CODES = {"check": 1, "sim": 1, "describe": 1, "fmt": 2}  # fmt: a rig it cannot read is I/O


@pytest.mark.parametrize("program", ['"../home/credentials"', '"../home/secret.mcm"',
                                     '"/proc/self/environ"', '"link.mcm"'])
@pytest.mark.parametrize("command", sorted(CODES))
def test_a_program_outside_the_rig_folder_is_never_shown_nor_written(tmp_path, command,
                                                                     program):
    """Item 3: `check` printed the lines of ~/.aws/credentials, `fmt` rewrote them."""
    home = tmp_path / "home"
    home.mkdir()
    for name in ("credentials", "secret.mcm"):
        (home / name).write_text(SECRET, encoding="utf-8")
    (tmp_path / "rig").mkdir()
    (tmp_path / "rig" / "link.mcm").symlink_to(home / "secret.mcm")
    rig = write_rig(tmp_path / "rig", WIRES + controllers().replace('"x.mcm"', program))
    result = cli(command, rig, catch=True)
    assert isinstance(result.exception, SystemExit), result.exception
    assert result.exit_code == CODES[command], result.output
    assert "hunter2" not in result.output and "must be a .mcm file in the rig file's folder" \
        in result.output
    assert [(p.name, p.read_text(encoding="utf-8")) for p in sorted(home.iterdir())] == \
        [("credentials", SECRET), ("secret.mcm", SECRET)]


@pytest.mark.parametrize("toml, where", [
    (WIRES + controllers().replace('"x.mcm"', '"x\\u0000.mcm"'), ":5:1: error[MR001"),
    (WIRES + controllers(x="9" * 5000), ":3:11: error[MR001"),
    (f'wires = ["x.out1 -> y.in{"1" * 5000}"]\n' + controllers(), ":1:10: error[MR003"),
    (controllers() + f"[joystick]\nX = {'1' * 4400}\n", ":10:5: error[MR001"),
])
@pytest.mark.parametrize("command", [["check"], ["sim"], ["describe"], ["fmt"],
                                     ["emulate", "--rig"]])
def test_a_nul_or_a_number_of_thousands_of_digits_is_said_not_traced(tmp_path, command, toml,
                                                                     where):
    """Item 11: ValueError (embedded null byte; integer string conversion) traced back."""
    rig = write_rig(tmp_path, toml)
    result = cli(*command, rig, catch=True)
    assert isinstance(result.exception, SystemExit), result.exception
    assert result.exit_code in (1, 2) and f"{rig}{where}" in result.output, result.output


def test_an_unreadable_program_is_io_exit_2_with_its_diagnostic(tmp_path):
    """Item 15: `check RIG` exited 1 where sim, describe and fmt exit 2; an unreadable
    program is an I/O problem in every command, and check still says where it is named."""
    rig = write_rig(tmp_path, WIRES + controllers().replace('"y.mcm"', '"gone.mcm"'))
    result = cli("check", rig)
    assert result.exit_code == 2
    assert f"{rig}:9:1: error[MR002 rig-program]: the program of y cannot be read" \
        in result.output
    assert cli("check", rig, "--format", "json").exit_code == 2
    for command in (["sim", rig], ["describe", rig], ["fmt", rig],
                    ["flash", tmp_path / "no-port", rig]):
        assert cli(*command).exit_code == 2, command


def test_a_rig_error_is_still_exit_1_beside_a_readable_program(tmp_path):
    rig = write_rig(tmp_path, WIRES + controllers().replace('"y.mcm"', '"y.txt"'))
    assert cli("check", rig).exit_code == 1
