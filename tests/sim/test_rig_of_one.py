"""A program is a rig of one (docs/rigs.md): `sim FILE` and `sim` of a rig file whose one
controller runs FILE (the box on it) show the same run, byte for byte: the timeline at every
verbosity, the trace, the JSON, the VCD and the plot's data; a scenario passes or fails alike.
One pipeline: the fast-forward of a lone controller is its own in both (the rig of one once
listed a fast-forward of 14 passes from 444.422 ms where the program listed it from
445.422 ms)."""
from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from helpers.budgets import budget
from helpers.cli import sim
from helpers.paths import ROOT
from helpers.programs import programs

FOUR_MODES = ROOT / "examples" / "macros" / "four-modes.mcm"
SCENARIO = ROOT / "examples" / "scenarios" / "manual-example4-four-modes.mode3.toml"
README = ["--buttons", "3@0-300ms,1@1s-1.2s", "--until", "3s"]


def rig_of_one(folder: Path, program: Path, model: str = "C-863") -> tuple[Path, Path]:
    """PROGRAM copied into FOLDER, and a rig file whose one controller runs it, the box and
    the joystick on it: (the program, the rig)."""
    folder.mkdir(exist_ok=True)
    copy = folder / program.name
    shutil.copyfile(program, copy)
    rig = folder / "one.rig.toml"
    rig.write_text(f'box = "s"\n[joystick]\nX = "s"\n[controllers.s]\naddress = 0\n'
                   f'model = "{model}"\nprogram = "{program.name}"\n', encoding="utf-8")
    return copy, rig


def outputs(path: Path, args: list[str], tmp: Path, plot: bool = False) -> dict:
    """What `sim PATH ARGS` shows: text at each verbosity, JSON, the VCD (and plot data)."""
    shown = {}
    for name, extra in (("text", []), ("-v", ["-v"]), ("-vv", ["-vv"]),
                        ("json", ["--format", "json"])):
        result = sim(path, *args, *extra)
        shown[name] = (result.exit_code, result.output)
    vcd = tmp / "out.vcd"
    result = sim(path, *args, "--vcd", vcd)
    shown["vcd"] = (result.exit_code, vcd.read_text(encoding="ascii") if vcd.exists() else None)
    vcd.unlink(missing_ok=True)
    if plot:
        from helpers.plots import page_data

        page = tmp / "out.html"
        assert sim(path, *args, "--plot", page).exit_code == 0
        shown["plot"] = page_data(page.read_text(encoding="utf-8"))
    return shown


def test_the_readme_run_shows_alike_for_the_program_and_its_rig_of_one(tmp_path):
    program, rig = rig_of_one(tmp_path / "r", FOUR_MODES)
    alone, one = outputs(program, README, tmp_path), outputs(rig, README, tmp_path)
    assert alone == one
    assert "0.445 s  fast-forward 14 identical passes of steps (MC04)" in one["text"][1]


def test_the_joystick_of_a_program_alone_is_its_rig_of_ones(tmp_path):
    """A program is a rig of one with the joystick on it (branch X): `--joystick` was
    refused for it ("is for a rig file") though its rig of one took it."""
    source = tmp_path / "js.mcm"
    source.write_text("target C-863\nautostart { JN 8000 }\n", encoding="utf-8")
    program, rig = rig_of_one(tmp_path / "r", source)
    args = ["--joystick", "X=+0.5@1s-3s", "--until", "4s"]
    alone, one = outputs(program, args, tmp_path), outputs(rig, args, tmp_path)
    assert alone == one and alone["text"][0] == 0
    assert "joystick at +0.50 (input 5 ON): commands +1,000 counts/s" in alone["text"][1]
    refused = sim(program, "--joystick", "Y=-1@1s")
    assert refused.exit_code == 2 and "a program alone has one joystick, on branch X" in refused.output


def test_the_plot_draws_the_same_lanes(tmp_path):
    pytest.importorskip("matplotlib")
    program, rig = rig_of_one(tmp_path / "r", FOUR_MODES)
    args = README + ["--until", "10s"]
    assert (outputs(program, args, tmp_path, plot=True)["plot"]
            == outputs(rig, args, tmp_path, plot=True)["plot"])


def test_the_trace_and_a_scenario_read_alike(tmp_path):
    program, rig = rig_of_one(tmp_path / "r", FOUR_MODES)
    for args in (["--trace", "--until", "50ms"], ["--scenario", str(SCENARIO)]):
        assert sim(program, *args).output == sim(rig, *args).output
    failing = tmp_path / "fails.toml"
    failing.write_text('[[expect]]\nat = "1s"\noutputs = 15\n', encoding="utf-8")
    alone, one = sim(program, "--scenario", failing), sim(rig, "--scenario", failing)
    assert alone.exit_code == one.exit_code == 1 and alone.output == one.output


@settings(max_examples=budget(25), deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(source=programs(), presses=st.lists(st.tuples(st.integers(1, 4), st.integers(0, 3000),
                                                     st.integers(1, 2000)), max_size=4),
       model=st.sampled_from(["C-863", "C-663"]))
def test_any_program_shows_alike_alone_and_as_a_rig_of_one(tmp_path, source, presses, model):
    folder = tmp_path / "p"
    folder.mkdir(exist_ok=True)
    original = folder / "original.mcm"
    original.write_text(f"target {model}\n" + source, encoding="utf-8")
    program, rig = rig_of_one(tmp_path / "r", original, model)
    buttons = ",".join(f"{n}@{t}-{t + d}" for n, t, d in presses)
    args = ["--buttons", buttons, "--until", "20s"] if buttons else ["--until", "20s"]
    assert outputs(program, args, tmp_path) == outputs(rig, args, tmp_path)
