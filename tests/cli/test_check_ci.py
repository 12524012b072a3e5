"""`mercmac check` in CI: output formats, rule selection, suppression comments,
settings files, folders and exit codes. Tests match rule names and codes, not wording."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from helpers.cli import cli
from helpers.paths import DATA, FOUR_MODES
from mercmac import config

# One warning (undefined-macro, MM012) and one info (default-argument) in macro 0.
WARNS = "[MC00] EM5,WS\n"
NESTED = "[MC00] EM1\n[MC01] EM2,MR5\n[MC02] EM3\n[MC03] MR1\n"  # nested-call (warning)
BROKEN = "[MC00] MR5,FOO\n"  # unknown-command (error)


@pytest.fixture(autouse=True)
def _fresh_settings(monkeypatch, tmp_path):
    """Each test finds its own settings files, from a folder of its own."""
    monkeypatch.setattr(config, "_FOUND", {})
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("NO_COLOR", "1")


def _write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="utf-8")
    return path


def _rules(*args) -> tuple[int, list[str]]:
    """Exit code and rule names of `check --format json ARGS`."""
    result = cli("check", "--format", "json", *args)
    return result.exit_code, [d["rule"] for d in json.loads(result.output)["diagnostics"]]


# -- formats --------------------------------------------------------------------------

def test_json_has_end_line_and_column(tmp_path):
    _write(tmp_path / "a.mcm", "[MC00] MR5,FOO\n")
    (d,) = json.loads(cli("check", "--output-format", "json", "a.mcm").output)["diagnostics"]
    assert (d["rule"], d["line"], d["column"], d["end_line"], d["end_column"]) == \
        ("unknown-command", 1, 12, 1, 15)


def test_format_is_an_alias_of_output_format(tmp_path):
    _write(tmp_path / "a.mcm", BROKEN)
    assert cli("check", "--format", "concise", "a.mcm").output == \
        cli("check", "--output-format", "concise", "a.mcm").output


def test_concise_is_one_line_per_diagnostic(tmp_path):
    _write(tmp_path / "a.mcm", WARNS)
    lines = cli("check", "--output-format", "concise", "a.mcm").output.splitlines()
    assert lines[0].startswith("a.mcm:1:8: MM012 [undefined-macro] ")
    assert lines[1].startswith("a.mcm:1:12: MM014 [default-argument] ")
    assert len(lines) == 3 and lines[2].startswith("0 errors, 1 warning, 1 info")


def test_github_workflow_commands_are_escaped(tmp_path):
    _write(tmp_path / "odd,name:x.mcm", BROKEN)
    result = cli("check", "--output-format", "github", "odd,name:x.mcm")
    (line,) = result.output.splitlines()
    assert result.exit_code == 1
    assert line.startswith("::error file=odd%2Cname%3Ax.mcm,line=1,col=12,endLine=1,endColumn=15,"
                           "title=MM002 unknown-command::")


def test_github_levels_and_message_escapes():
    from mercmac.diagnostics import Diagnostic, Severity, rule
    from mercmac.render.report import to_github
    from mercmac.source import Span

    d = Diagnostic(rule("undefined-macro"), Severity.INFO, "a.mcm", Span(2, 3, 2, 5), "50%\nnext")
    assert to_github([d]) == ("::notice file=a.mcm,line=2,col=3,endLine=2,endColumn=5,"
                              "title=MM012 undefined-macro::50%25%0Anext\n")


def test_sarif_is_valid_sarif_2_1_0(tmp_path):
    jsonschema = pytest.importorskip("jsonschema")
    schema = json.loads((DATA / "sarif-schema-2.1.0.json").read_text(encoding="utf-8"))
    _write(tmp_path / "progs" / "a b.mcm", NESTED)
    _write(tmp_path / "progs" / "b.mcm", BROKEN + WARNS)
    result = cli("check", "--output-format", "sarif", "progs")
    log = json.loads(result.output)
    jsonschema.validate(log, schema, cls=jsonschema.Draft4Validator)
    (run,) = log["runs"]
    rules = run["tool"]["driver"]["rules"]
    assert {"id": "MM011", "name": "nested-call"}.items() <= rules[[r["id"] for r in rules].index("MM011")].items()
    found = {(r["ruleId"], r["level"], r["locations"][0]["physicalLocation"]["artifactLocation"]["uri"])
             for r in run["results"]}
    assert ("MM011", "warning", "progs/a%20b.mcm") in found
    assert ("MM002", "error", "progs/b.mcm") in found
    assert all(rules[r["ruleIndex"]]["id"] == r["ruleId"] for r in run["results"])
    region = run["results"][0]["locations"][0]["physicalLocation"]["region"]
    assert set(region) == {"startLine", "startColumn", "endLine", "endColumn"}
    assert result.exit_code == 1


def test_sarif_of_a_clean_file_is_valid(tmp_path):
    jsonschema = pytest.importorskip("jsonschema")
    schema = json.loads((DATA / "sarif-schema-2.1.0.json").read_text(encoding="utf-8"))
    result = cli("check", "--output-format", "sarif", FOUR_MODES)
    jsonschema.validate(json.loads(result.output), schema, cls=jsonschema.Draft4Validator)
    assert result.exit_code == 0


def test_statistics_count_each_rule(tmp_path):
    _write(tmp_path / "a.mcm", "[MC00] EM5,EM6,WS\n")
    text = cli("check", "--statistics", "a.mcm").output.splitlines()
    assert text[0].split() == ["2", "MM012", "undefined-macro", "warning"]
    assert text[1].split()[:3] == ["1", "MM014", "default-argument"]
    stats = json.loads(cli("check", "--statistics", "--format", "json", "a.mcm").output)["statistics"]
    assert [(s["rule"], s["count"]) for s in stats][0] == ("undefined-macro", 2)


def test_json_truncation_is_kept(tmp_path):
    _write(tmp_path / "a.mcm", "[MC00] EM5,EM6,EM7\n")
    out = json.loads(cli("check", "--format", "json", "--max-diagnostics", "1", "a.mcm").output)
    assert len(out["diagnostics"]) == 1 and out["truncated"] == {"a.mcm": 2}


# -- selection, suppression, exit codes ----------------------------------------------------

def test_select_and_ignore_by_code_or_name(tmp_path):
    _write(tmp_path / "a.mcm", WARNS)
    assert _rules("a.mcm")[1] == ["undefined-macro", "default-argument"]
    assert _rules("--select", "MM012", "a.mcm") == (0, ["undefined-macro"])
    assert _rules("--select", "default-argument", "a.mcm") == (0, ["default-argument"])
    assert _rules("--ignore", "undefined-macro,mm014", "a.mcm") == (0, [])
    assert _rules("--select", "MM012", "--select", "MM014", "--ignore", "MM012", "a.mcm") == \
        (0, ["default-argument"])


def test_unknown_rule_is_a_usage_error(tmp_path):
    _write(tmp_path / "a.mcm", WARNS)
    result = cli("check", "--select", "nested-cal", "a.mcm")
    assert result.exit_code == 2 and "nested-cal" in result.output


def test_syntax_errors_cannot_be_turned_off(tmp_path):
    _write(tmp_path / "a.mcm", "[MC00] EMxx   // mercmac: ignore\n")
    assert _rules("--ignore", "syntax", "a.mcm") == (1, ["syntax"])


@pytest.mark.parametrize("comment, left", [
    ("// mercmac: ignore[nested-call]", []),
    ("// mercmac: ignore[MM011]", []),
    ("// mercmac: ignore[undefined-macro, MM011]", []),
    ("// mercmac: ignore", []),
    ("// mercmac: ignore[undefined-macro]", ["nested-call"]),
    ("// why: the rest never runs   // mercmac: ignore[nested-call]", []),
])
def test_suppression_comments(tmp_path, comment, left):
    _write(tmp_path / "a.mcm", NESTED.replace("[MC01] EM2,MR5", "[MC01] EM2,MR5 " + comment))
    assert _rules("a.mcm") == (0, left)


def test_a_comment_on_another_line_does_not_suppress(tmp_path):
    _write(tmp_path / "a.mcm", "// mercmac: ignore[nested-call]\n" + NESTED)
    assert _rules("a.mcm")[1] == ["nested-call"]


def test_warnings_as_errors(tmp_path):
    _write(tmp_path / "w.mcm", NESTED)
    _write(tmp_path / "i.mcm", "[MC00] WS\n")
    assert cli("check", "w.mcm").exit_code == 0
    assert cli("check", "--warnings-as-errors", "w.mcm").exit_code == 1
    assert cli("check", "--warnings-as-errors", "i.mcm").exit_code == 0  # infos stay infos
    assert cli("check", "--warnings-as-errors", "--ignore", "nested-call", "w.mcm").exit_code == 0


# -- folders --------------------------------------------------------------------------

def test_a_folder_means_every_mcm_below_it_sorted(tmp_path):
    _write(tmp_path / "p" / "z.mcm", BROKEN)
    _write(tmp_path / "p" / "sub" / "a.mcm", WARNS)
    _write(tmp_path / "p" / "notes.txt", "FOO")
    result = cli("check", "--output-format", "concise", "--select", "unknown-command,MM012", "p")
    files = [line.split(":")[0] for line in result.output.splitlines()[:-1]]
    assert files == [str(Path("p", "z.mcm")), str(Path("p", "sub", "a.mcm"))]  # errors first
    assert result.output.splitlines()[-1].endswith("in 2 files.")
    assert result.exit_code == 1


def test_a_folder_without_mcm_files_is_a_usage_error(tmp_path):
    (tmp_path / "empty").mkdir()
    _write(tmp_path / "a.mcm", WARNS)
    result = cli("check", "empty")
    assert result.exit_code == 2 and "no .mcm files in empty" in result.output
    assert cli("check", "empty", "a.mcm").exit_code == 2


# -- settings ---------------------------------------------------------------------------

def test_pyproject_settings_apply_below_it(tmp_path):
    _write(tmp_path / "pyproject.toml", '[project]\nname = "x"\n\n[tool.mercmac]\n'
                                        'ignore = ["default-argument"]\n')
    _write(tmp_path / "deep" / "er" / "a.mcm", WARNS)
    assert _rules("deep/er/a.mcm") == (0, ["undefined-macro"])
    assert _rules("--ignore", "MM012", "deep/er/a.mcm") == (0, ["default-argument"])  # options win


def test_nearest_settings_win_and_mercmac_toml_beats_pyproject(tmp_path):
    _write(tmp_path / "pyproject.toml", '[tool.mercmac]\nselect = ["undefined-macro"]\n')
    _write(tmp_path / "sub" / "pyproject.toml", '[project]\nname = "no table: passed over"\n')
    _write(tmp_path / "sub" / "a.mcm", WARNS)
    _write(tmp_path / "other" / "mercmac.toml", 'select = ["default-argument"]\n')
    _write(tmp_path / "other" / "pyproject.toml", '[tool.mercmac]\nselect = ["MM012"]\n')
    _write(tmp_path / "other" / "b.mcm", WARNS)
    assert _rules("sub/a.mcm", "other/b.mcm")[1] == ["undefined-macro", "default-argument"]


def test_settings_target_is_a_default_for_the_option(tmp_path):
    _write(tmp_path / "mercmac.toml", 'target = "C-863"\n')
    _write(tmp_path / "a.mcm", "[MC00] DC100\n")  # DC is not on the C-863 (docs/checks.md)
    assert _rules("a.mcm") == (1, ["model-unsupported"])
    assert _rules("--target", "C-663", "a.mcm") == (0, [])


@pytest.mark.parametrize("text, words", [
    ('selct = ["MM011"]\n', "selct"),
    ('target = "C-999"\n', "C-999"),
    ('ignore = [1]\n', "ignore"),
    ('select = ["no-such-rule"]\n', "no-such-rule"),
    ('select = [\n', "TOML"),
])
def test_bad_settings_are_usage_errors(tmp_path, text, words):
    _write(tmp_path / "mercmac.toml", text)
    _write(tmp_path / "a.mcm", WARNS)
    result = cli("check", "a.mcm")
    assert result.exit_code == 2 and words in result.output and "mercmac.toml" in result.output
