"""The README's set-up commands are true: CI runs exactly its test command."""
from __future__ import annotations

from helpers.paths import ROOT
from helpers.readme import setup_commands


def test_readme_opens_with_two_setup_commands():
    install, tests = setup_commands()
    assert "pip install ." in install and "mercmac" in install.split("&&")[-1]
    assert "pytest" in tests


def test_ci_runs_the_readme_test_command():
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8").splitlines()
    assert setup_commands()[1] in ci


def test_readme_example_files_exist():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    for word in text.split():
        if word.startswith("examples/") and word.endswith(".mcm"):
            assert (ROOT / word).exists(), word


def test_the_setup_simulation_does_what_the_text_says(monkeypatch):
    """The text said button 3 picks mode 3, "then a press of button 1 steps the stage"; the
    run first stepped it to -2000 too, as button 3 was still held when mode 3 began."""
    import json
    import shlex

    from helpers.cli import cli
    from helpers.readme import README

    words = shlex.split(setup_commands()[0].split("&&")[-1])
    assert words[0].endswith("mercmac") and words[1] == "sim"
    text = README.split("The first installs mercmac", 1)[1].split("The\nsecond", 1)[0]
    monkeypatch.chdir(ROOT)  # "from the top of this repository"
    result = cli(*words[1:], "--format", "json", catch=True)
    assert result.exit_code == 0, result.output
    moves = [e["target"] for e in json.loads(result.stdout)["events"]
             if e["kind"] == "move" and e["motion"] == "move"]
    assert moves == [-2000, 2000]
    for target in moves:
        assert f"to {target}" in " ".join(text.split()), f"the text does not say `to {target}`"
