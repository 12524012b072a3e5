"""`slow-poll`: a `when` inside a loop reads its inputs once per pass (MS176E §5.5, §6.4 XN),
so a press shorter than a pass may be missed; the message says how long a pass takes."""
from __future__ import annotations

import json

import pytest

from helpers.cli import cli
from helpers.compiling import compile_text


def polls(text: str) -> list:
    return [d for d in compile_text(text).report.items if d.rule.name == "slow-poll"]


@pytest.mark.parametrize("text, took", [
    # every T: the block, then WA T; a nested repeat counts its passes
    ("autostart { every 100ms { WA 200, repeat 2 { WA 50 }, when 1 { CN 1 } } }\n", "400 ms"),
    # a call counts what the macro waits; WS waits for a move of unknown length first
    ("macro p { WA 100 }\nautostart { repeat 3 { MR 9, WS 200, call p, when 2 { CF 1 } } }\n",
     "at least 300 ms"),
    ("autostart { every 300ms { WN 3, when 1 { CN 1 } } }\n", "at least 300 ms"),
    ("const T = 1000\nautostart { every T { when 1 { CN 1 } } }\n", "1000 ms"),
    # a raw line that loops and calls a macro that starts with a condition (Example 4's way)
    ("[MC00] EM1,EM2,WA300,RP,RP\n[MC01] XN1,CN1\n[MC02] WA50,XF2,CF1\n", "350 ms"),
])
def test_the_message_says_how_long_a_pass_takes(text, took):
    found = polls(text)
    assert found and all(f"a pass takes {took}" in d.message for d in found), found
    assert all(f"held {took}" in d.message for d in found)


def test_it_points_at_each_when_and_names_its_inputs_and_loop():
    text = "autostart {\n  every 1s {\n    when 1 { CN 1 }\n    when 2 and not 3 { CF 1 }\n  }\n}\n"
    first, second = polls(text)
    assert (first.span.line, first.span.column, first.span.end_column) == (3, 5, 11)  # `when 1`
    assert "reads input 1 once per pass of the `every` at line 2" in first.message
    assert "reads inputs 2 and 3" in second.message and second.span.end_column == 21
    assert str(first.severity) == "info"


def test_a_when_in_an_inner_loop_counts_that_loop_only():
    text = "autostart { every 1s { repeat 5 { when 1 { CN 1 }, WA 20 }, when 2 { CF 1 } } }\n"
    [outer] = polls(text)  # the repeat passes every 20 ms; the every's pass is 1100 ms
    assert "reads input 2" in outer.message and "1100 ms" in outer.message


def test_the_raw_variant_names_the_call_and_the_condition():
    [d] = polls("[MC00] EM1,WA300,RP\n[MC01] XN1,CN1\n")
    assert d.message.startswith("EM1 runs MC01, whose XN1 reads input 1 once per pass")
    assert (d.span.line, d.span.column) == (1, 8)


def test_the_simulator_misses_a_press_shorter_than_the_pass(tmp_path):
    """What the rule says is what the simulator does: a 200 ms press between two reads of a
    500 ms loop lights nothing; one held for a pass is seen."""
    path = tmp_path / "p.mcm"
    path.write_text("target C-863\nautostart {\n  every 500ms { when 1 { CN 1 } }\n}\n")
    [d] = polls(path.read_text())
    assert "500 ms" in d.message
    lit = {}
    for press in ("1@100-300", "1@100-600"):
        out = cli("sim", path, "--buttons", press, "--until", "2s", "--format", "json")
        lit[press] = json.loads(out.output)["outputs"]
    assert lit["1@100-300"] == [] and lit["1@100-600"] != []


def test_a_long_chain_of_calls_in_a_polling_loop_is_timed_without_exhausting_the_stack():
    chain = "".join(f"macro m{i} {{ WA 1, call m{i + 1} }}\n" for i in range(1500))
    text = chain + "macro m1500 { TP }\nautostart { every 300ms { call m0, when 1 { TP } } }\n"
    items = compile_text(text).report.items
    assert not [d for d in items if "internal error" in d.message]
    [d] = [d for d in items if d.rule.name == "slow-poll"]
    assert "at least 3" in d.message  # 300 ms and the WAs it followed, then "at least"
