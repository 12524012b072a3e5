"""`describe` calls macros what the source calls them, as `sim` and `flash` do:
`jog (MC01)`, not `MC01 (mode_1)`; names made from what a line does only for raw
slots, never one the source uses; on --port, the names of the recorded source."""
from __future__ import annotations

import json
import os
import re

import pytest

from helpers.cli import cli
from helpers.emulator import FAST
from mercmac.compiler import compile_file

needs_pty = pytest.mark.skipif(not hasattr(os, "openpty"), reason="needs pseudo-terminals")
# The README's tour program (`prog.mcm`).
TOUR = """\
target C-863
const FAR = 9999999

autostart {
    when 1 { SV 70000, goto jog }     // hold button 1 at power-on for jog mode
}

macro jog {
    every 20ms {                      // ...,WA20,RP,RP: poll the buttons "forever"
        when 1 { MR FAR, WF 1, AB 1 } // run while button 1 is held
        when 2 { MR -10000, WF 2 }
    }
}
"""
MIXED = """\
target C-863
[MC05] SV1000,SA5000
autostart { EM 5, call init }
macro init { SV 2000, CN 1 }
"""


@pytest.fixture
def tour(tmp_path):
    path = tmp_path / "prog.mcm"
    path.write_text(TOUR)
    return path


def _labels(path) -> list[str]:
    """What `sim` and `flash` call each macro of PATH (Macro.label)."""
    return [m.label for m in compile_file(str(path)).program.macros.values()]


def test_describe_uses_the_names_sim_uses(tour):
    described = cli("describe", tour)
    simulated = cli("sim", tour, "--buttons", "1@0-300ms,2@1s-1.5s", "--until", "2s", "-v")
    assert described.exit_code == 0 and simulated.exit_code == 0, described.output
    assert set(_labels(tour)) == {"autostart (MC00)", "jog (MC01)", "jog.when@10 (MC02)",
                                  "jog.when@11 (MC03)"}
    for label in _labels(tour):
        assert label in described.stdout, label
    for label in ("jog (MC01)", "jog.when@10 (MC02)"):  # as the timeline shows them
        assert label in simulated.stdout and label in described.stdout
    assert "mode_1" not in described.stdout and "MC01 (" not in described.stdout
    assert "jog (MC01): every 20 ms" in described.stdout


def test_json_and_the_call_graph_carry_the_names_too(tour, tmp_path):
    data = json.loads(cli("describe", tour, "--format", "json").stdout)
    assert {m["slot"]: m["name"] for m in data["macros"]} == {
        0: "autostart", 1: "jog", 2: "jog.when@10", 3: "jog.when@11"}
    assert cli("describe", tour, "--graph", tmp_path / "calls.dot").exit_code == 0
    dot = (tmp_path / "calls.dot").read_text()
    assert 'MC01 [label="MC01\\njog (every 20 ms)"];' in dot
    markdown = cli("describe", tour, "--format", "markdown").stdout
    assert 'MC01["MC01 jog (every 20 ms)"]' in markdown


def test_raw_slots_get_made_up_names_unlike_the_sources(write):
    text = cli("describe", write(MIXED)).stdout
    assert "init (MC01): set the velocity to 2,000 counts/s" in text
    # MC05 does what an `init` does; the source has an `init`: the made-up name differs
    assert "MC05 (init_2): set the velocity to 1,000 counts/s" in text
    assert "run MC05 (init_2), then go to init (MC01)" in text


def test_a_raw_file_keeps_made_up_names(write):
    text = cli("describe", write("[MC00] XN1,EM1\n[MC01] EM2,WA20,RP,RP\n[MC02] XN1,MR5\n")).stdout
    assert "MC01 (mode_1): every 20 ms" in text and "MC02 (mode_1_button_1)" in text


def _serve():
    from helpers.emulator import serve

    return serve()


@needs_pty
def test_port_with_a_record_uses_the_recorded_names(tour, tmp_path, data_dir):
    with _serve() as (server, vc):
        flashed = cli("flash", server.path, tour, "--backup", tmp_path / "b.mcm", *FAST)
        assert flashed.exit_code == 0, flashed.output
        described = cli("describe", "--port", server.path, *FAST)
        graph = cli("describe", "--port", server.path, "--graph", tmp_path / "g.dot", *FAST)
    assert described.exit_code == 0, described.output
    assert "holds prog.mcm, flashed " in described.output
    for label in _labels(tour):
        assert label in described.stdout, label
    assert "mode_1" not in described.stdout
    assert graph.exit_code == 0 and "jog (every 20 ms)" in (tmp_path / "g.dot").read_text()


@needs_pty
def test_port_without_a_record_makes_names_up(tour, tmp_path, data_dir):
    with _serve() as (server, vc):
        flashed = cli("flash", server.path, tour, "--backup", tmp_path / "b.mcm", *FAST)
        assert flashed.exit_code == 0, flashed.output
        for record in (data_dir / "history").glob("*.json"):
            record.unlink()  # a controller flashed elsewhere: nothing recorded here
        described = cli("describe", "--port", server.path, *FAST)
    assert described.exit_code == 0, described.output
    assert "holds" not in described.output
    assert re.search(r"MC01 \(mode_1\): every 20 ms", described.stdout)
    assert "jog" not in described.stdout


@needs_pty
def test_port_with_a_stale_record_says_so_and_makes_names_up(tour, tmp_path, data_dir):
    with _serve() as (server, vc):
        flashed = cli("flash", server.path, tour, "--backup", tmp_path / "b.mcm", *FAST)
        assert flashed.exit_code == 0, flashed.output
        (record,) = (data_dir / "history").glob("*.json")
        saved = json.loads(record.read_text())
        saved["source"] = saved["source"].replace("every 20ms", "every 30ms")  # edited since
        record.write_text(json.dumps(saved))
        described = cli("describe", "--port", server.path, *FAST)
    assert described.exit_code == 0, described.output
    assert "no longer builds to what the controller holds" in described.output
    assert "described with made-up names instead" in described.output
    assert "MC01 (mode_1): every 20 ms" in described.stdout and "jog" not in described.stdout
