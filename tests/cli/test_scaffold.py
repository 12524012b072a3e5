"""`mercmac examples` copies the bundled examples out; `mercmac new` writes starting programs
that check clean. Neither replaces a file nor writes through a link."""
from __future__ import annotations

import json
import os
import shlex

import pytest

from helpers.cli import cli
from helpers.paths import ROOT
from mercmac.commands import MODELS
from mercmac.templates import RIG_TEMPLATES, TEMPLATES

EXAMPLES = ROOT / "examples"


def repository_examples() -> dict[str, bytes]:
    """Every file of the repository's examples/ folder, by path below it."""
    return {p.relative_to(EXAMPLES).as_posix(): p.read_bytes()
            for p in sorted(EXAMPLES.rglob("*")) if p.is_file() and "__pycache__" not in p.parts}


def tree(folder) -> dict[str, bytes]:
    return {p.relative_to(folder).as_posix(): p.read_bytes()
            for p in sorted(folder.rglob("*")) if p.is_file()}


# -- mercmac examples --------------------------------------------------------------------------

def test_examples_copies_every_example_into_examples_by_default(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    result = cli("examples")
    assert result.exit_code == 0, result.output
    assert tree(tmp_path / "examples") == repository_examples()
    assert "13 example files in examples:" in result.stdout
    assert "examples/rigs/raster/raster.rig.toml" in result.stdout


def test_the_readme_commands_run_on_the_copied_examples(tmp_path, monkeypatch):
    """The README's paths (examples/macros/..., examples/rigs/raster/...) hold after
    `mercmac examples` in an empty folder."""
    monkeypatch.chdir(tmp_path)
    cli("examples")
    assert cli("sim", "examples/macros/four-modes.mcm", "--buttons", "3@0-300ms,1@1s-1.2s",
               "--until", "3s").exit_code == 0
    assert cli("check", "examples/rigs/raster/raster.rig.toml").exit_code == 0
    assert cli("sim", "examples/macros/manual-example4-four-modes.mcm", "--scenario",
               "examples/scenarios/manual-example4-four-modes.mode2.toml").exit_code == 0


def test_examples_into_a_named_folder_made_with_its_parents(tmp_path):
    result = cli("examples", tmp_path / "a" / "b")
    assert result.exit_code == 0, result.output
    assert tree(tmp_path / "a" / "b") == repository_examples()


def test_examples_replace_nothing_without_force_and_write_nothing(tmp_path):
    """A file in the last folder there already: nothing is written, in no folder."""
    edited = tmp_path / "scenarios" / "manual-example4-four-modes.mode3.toml"
    edited.parent.mkdir()
    edited.write_text("# mine\n", encoding="utf-8")
    result = cli("examples", tmp_path)
    assert result.exit_code == 2
    assert "mode3.toml" in result.stderr and "nothing was written" in result.stderr
    assert "--force" in result.stderr
    assert tree(tmp_path) == {"scenarios/manual-example4-four-modes.mode3.toml": b"# mine\n"}
    assert cli("examples", tmp_path, "--force").exit_code == 0
    assert tree(tmp_path) == repository_examples()


def test_examples_never_write_through_a_link(tmp_path):
    """A link in the folder, to a folder or to a file, is refused even with --force, before
    anything is written; what it points to stays as it is."""
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "x.mcm").write_text("// outside\n", encoding="utf-8")
    target = tmp_path / "target"
    (target / "rigs").mkdir(parents=True)
    (target / "scenarios").mkdir()
    os.symlink(outside, target / "rigs" / "raster")
    os.symlink(outside / "x.mcm", target / "scenarios" / "manual-example4-four-modes.mode2.toml")
    for force in ([], ["--force"]):
        result = cli("examples", target, *force)
        assert result.exit_code == 2 and "symbolic link" in result.stderr, result.output
    assert tree(outside) == {"x.mcm": b"// outside\n"}
    assert not (target / "macros").exists()
    os.unlink(target / "rigs" / "raster")
    result = cli("examples", target, "--force")
    assert result.exit_code == 2 and "mode2.toml: it is a symbolic link" in result.stderr
    assert tree(outside) == {"x.mcm": b"// outside\n"} and not (target / "macros").exists()


@pytest.mark.parametrize("command", ["examples", "new"])
def test_a_file_where_the_folder_goes_is_refused(command, tmp_path):
    (tmp_path / "f").write_text("", encoding="utf-8")
    result = cli(command, tmp_path / "f" / "prog.mcm", catch=True)
    assert isinstance(result.exception, SystemExit), result.exception
    assert result.exit_code == 2 and "is not a folder" in result.stderr


# -- mercmac new -------------------------------------------------------------------------------

CASES = [(template, model) for template in TEMPLATES for model in MODELS]


def made_name(template: str) -> str:
    return "bench.rig.toml" if template in RIG_TEMPLATES else "prog.mcm"


@pytest.mark.parametrize("template,model", CASES)
def test_each_template_checks_clean_and_is_formatted(template, model, tmp_path, monkeypatch):
    """No error, warning or info for either model, and in `fmt`'s layout already."""
    monkeypatch.chdir(tmp_path)
    name = made_name(template)
    result = cli("new", name, "--target", model, "--template", template)
    assert result.exit_code == 0, result.output
    checked = cli("check", "--format", "json", name)
    assert checked.exit_code == 0, checked.output
    assert json.loads(checked.stdout)["diagnostics"] == []
    assert cli("fmt", "--check", name).exit_code == 0
    assert all(f"target {model}" in p.read_text(encoding="utf-8")
               for p in tmp_path.glob("*.mcm"))


@pytest.mark.parametrize("template,model", CASES)
def test_each_template_runs_in_sim_as_its_comments_say(template, model, tmp_path, monkeypatch):
    """The sim command the file's own comments give runs, moves the stage, finds no hazard."""
    monkeypatch.chdir(tmp_path)
    name = made_name(template)
    cli("new", name, "--target", model, "--template", template)
    comment = "#" if template in RIG_TEMPLATES else "//"
    (line,) = [l for l in (tmp_path / name).read_text(encoding="utf-8").splitlines()
               if l.startswith(f"{comment}   mercmac sim ")]
    words = shlex.split(line.removeprefix(comment))[1:]
    result = cli(*words, "--format", "json", "--fail-on-hazard")
    assert result.exit_code == 0, result.output
    run = json.loads(result.stdout)
    axes = list(run["controllers"].values()) if "controllers" in run else [run]
    for axis in axes:  # every axis moves, and the box's LEDs (or the wires) change
        assert any(e["kind"] == "move" for e in axis["events"])
        assert axis["outputs"] and not axis["hazards"]


def test_new_defaults_jog_for_a_program_and_the_raster_for_a_rig(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert cli("new", "a.mcm").exit_code == 0
    assert "target C-863" in (tmp_path / "a.mcm").read_text(encoding="utf-8")
    assert "macro run" in (tmp_path / "a.mcm").read_text(encoding="utf-8")
    result = cli("new", "lab/xy.rig.toml")
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in (tmp_path / "lab").iterdir()) == ["x.mcm", "xy.rig.toml",
                                                                    "y.mcm"]
    assert "mercmac check lab/xy.rig.toml" in result.stdout


def test_new_replaces_no_file_and_writes_nothing_when_one_is_there(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "y.mcm").write_text("// mine\n", encoding="utf-8")
    result = cli("new", "xy.rig.toml")
    assert result.exit_code == 2
    assert "y.mcm there already" in result.stderr and "nothing was written" in result.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["y.mcm"]
    assert (tmp_path / "y.mcm").read_text(encoding="utf-8") == "// mine\n"


def test_new_does_not_write_through_a_link(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "elsewhere.mcm").write_text("// mine\n", encoding="utf-8")
    os.symlink(tmp_path / "elsewhere.mcm", tmp_path / "prog.mcm")
    result = cli("new", "prog.mcm")
    assert result.exit_code == 2 and "symbolic link" in result.stderr
    assert (tmp_path / "elsewhere.mcm").read_text(encoding="utf-8") == "// mine\n"


@pytest.mark.parametrize("args,says", [
    (["prog.txt"], "'prog.txt' does not end in .mcm"),
    (["prog.mcm", "--template", "raster-rig"], "NAME.rig.toml"),
    (["xy.rig.toml", "--template", "scan"], "does not end in .mcm"),
    (["prog.mcm", "--template", "nope"], "Invalid value for '--template'"),
    (["prog.mcm", "--target", "C-862"], "Invalid value for '--target'"),
])
def test_new_refuses_a_name_that_does_not_fit(args, says, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    result = cli("new", *args)
    assert result.exit_code == 2 and says in result.output
    assert list(tmp_path.iterdir()) == []


def test_a_strange_file_name_stays_in_its_comment(tmp_path, monkeypatch):
    """The name goes into the file's comments escaped and quoted: a newline in it cannot
    end the comment and add a line to the program."""
    monkeypatch.chdir(tmp_path)
    name = "a\nautostart { XY }\n.mcm"
    assert cli("new", name).exit_code == 0
    assert cli("check", name).exit_code == 0
