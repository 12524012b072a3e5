"""`describe`: a stored program in plain words, and its call graph."""
from __future__ import annotations

import json

import pytest

from mercmac.compiler import compile_file
from mercmac.decompile import call_graph_dot, describe, read_macros
from helpers.paths import EXAMPLE4, FOUR_MODES, GOLDEN

def _example4() -> dict[int, str]:
    return read_macros(EXAMPLE4.read_text())


def _four_modes() -> dict[int, str]:
    program = compile_file(str(FOUR_MODES)).program
    return {m.slot: m.line for m in program.macros.values()}


@pytest.mark.parametrize("name, macros", [("example4", _example4), ("four-modes", _four_modes)])
def test_golden_text(name, macros):
    text = describe(macros())
    golden = GOLDEN / f"describe-{name}.txt"
    assert text == golden.read_text(encoding="utf-8")


def test_the_manuals_own_words():
    text = describe(_example4())
    # MS176E §3.8.6: "MC16: only while button 1 is held: move +9,999,999 counts, wait until
    # button 1 is released, then stop smoothly"
    assert ("MC16 (mode_1_button_1): only while button 1 is held: move +9,999,999 counts, "
            "wait until button 1 is released, then stop smoothly") in text
    assert "every 20 ms" in text and "LED 1 on" in text


def test_units_follow_the_model():
    assert "+500 steps" in describe({1: "MR500"}, model="C-663")
    assert "+500 counts" in describe({1: "MR500"}, model="C-863")


def test_unreached_macros_are_listed():
    data = json.loads(describe({0: "MR5", 3: "CN1"}, fmt="json"))
    assert data["unreached"] == [3]


def test_markdown_has_a_mermaid_call_graph():
    text = describe(_example4(), fmt="markdown")
    assert "```mermaid" in text and "MC15 -->|call if button 1 is held| MC16" in text
    assert 'MC15["MC15 mode_1 (every 20 ms)"]' in text and text.startswith("# ")


def test_json_and_dot():
    data = json.loads(describe(_example4(), fmt="json"))
    assert data["model"] == "C-863" and {m["mode"] for m in data["modes"]} == {15, 20, 26}
    assert [loop["period_ms"] for loop in data["loops"]] == [20, 100, 30]
    dot = call_graph_dot(_example4())
    assert dot.startswith("digraph") and 'MC10 -> MC14 [label="goto if button 4 is held", style=dashed];' in dot
    assert 'MC15 [label="MC15\\nmode_1 (every 20 ms)"];' in dot


def test_unknown_format():
    with pytest.raises(ValueError):
        describe({}, fmt="yaml")
