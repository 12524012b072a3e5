"""Lowering: the MD strings the high-level constructs become (docs/language.md)."""
from __future__ import annotations

from helpers.compiling import compile_text


def md(text: str) -> list[str]:
    result = compile_text(text)
    assert not result.report.has_errors, [d.message for d in result.report.items]
    return result.program.md_lines()


def test_raw_blocks_pass_through_normalised():
    assert md("[MC00] EM+9,EM+10\n[MC09] TP\n[MC10] TT\n") == ["MD9,TP", "MD10,TT", "MD0,EM9,EM10"]


def test_slots_allocated_around_raw_blocks_and_pins():
    program = compile_text("[MC01] TP\nmacro a @3 { TT }\nmacro b { TE }\nmacro c { TY }\n").program
    assert program.names() == {1: "MC01", 2: "b", 3: "a", 4: "c"}


def test_when_at_the_end_stays_inline():
    assert md("autostart { TP, when 1 and not 2 { MR 5 } }\n") == ["MD0,TP,XN1,XF2,MR5"]


def test_when_in_the_middle_is_hoisted_and_called():
    assert md("autostart { when 1 { MR 5 }, TP }\n") == ["MD1,XN1,MR5", "MD0,EM1,TP"]


def test_repeat_as_whole_macro_and_hoisted():
    assert md("macro a { repeat 10 { MR 5, WS 0 } }\n") == ["MD1,MR5,WS0,RP9"]
    assert md("autostart { TP, repeat 3 { MR 5 }, TT }\n") == ["MD1,MR5,RP2", "MD0,TP,EM1,TT"]
    assert md("autostart { repeat 1 { MR 5 }, TT }\n") == ["MD0,MR5,TT"]


def test_every_is_wait_and_double_repeat():
    assert md("autostart { every 20ms { when 1 { MR 5 } } }\n") == [
        "MD1,XN1,MR5", "MD0,EM1,WA20,RP,RP"]
    assert md("autostart { SV 5, every 1.5s { TP } }\n") == ["MD1,TP,WA1500,RP,RP", "MD0,SV5,EM1"]


def test_rest_continues_after_a_when_that_calls():
    lines = md("autostart { when 1 { call a, TP }, TT }\nmacro a { MR 5 }\n")
    assert lines == ["MD1,MR5", "MD2,XN1,EM1,TP,EM3", "MD3,TT", "MD0,EM2,EM3"]


def test_rest_continues_after_a_repeat_that_calls():
    # a repeat that starts its macro now stays in line (RP jumps to the start),
    # so the hoisting this test is about is shown after a first command
    lines = md("autostart { TP, repeat 3 { call a }, TT }\nmacro a { MR 5 }\n")
    assert lines == ["MD1,MR5", "MD2,EM1,RP2,EM3", "MD3,TT", "MD0,TP,EM2,EM3"]
    assert md("autostart { repeat 3 { call a }, TT }\nmacro a { MR 5 }\n") == [
        "MD1,MR5", "MD0,EM1,RP2,TT"]


def test_long_block_is_chained_through_a_tail_em():
    program = compile_text("macro a { " + ", ".join(f"MR {i}" for i in range(1, 21)) + " }\n").program
    assert [m.md for m in program.ordered()] == [
        "MD1," + ",".join(f"MR{i}" for i in range(1, 16)) + ",EM2",
        "MD2," + ",".join(f"MR{i}" for i in range(16, 21)),
    ]
    assert program.names() == {1: "a", 2: "a.part2"}


def test_goto_is_a_tail_em_and_a_mode_switch_is_legal():
    lines = md("autostart { when 1 { SV 7, goto fast }, TP }\nmacro fast { TT }\n")
    assert lines == ["MD1,TT", "MD2,XN1,SV7,EM1", "MD0,EM2,TP"]


def test_consts_stand_for_numbers():
    assert md("const FAST = 250000\nconst B = 3\nautostart { SV FAST, when B { TP } }\n") == [
        "MD0,SV250000,XN3,TP"]


def test_names_and_spans_survive_lowering():
    program = compile_text("macro jog {\n  every 20ms {\n    when 1 { MR 5 }\n  }\n}\n").program
    hoisted = next(m for m in program.macros.values() if m.origin == "when")
    assert hoisted.name == "jog.when@3" and hoisted.span.line == 3
    assert hoisted.ops[1].span.line == 3 and hoisted.ops[1].text == "MR5"


def test_long_loop_moves_plain_runs_into_called_macros_and_keeps_the_meaning():
    from mercmac.compiler.ast_builder import build
    from mercmac.compiler.checks import check_module
    from mercmac.compiler.parse import parse
    from mercmac.diagnostics import Report
    from helpers.semantics import firmware_trace, high_level_trace

    text = ("autostart { repeat 3 { " + ", ".join(f"MR {i}" for i in range(1, 25))
            + ", when 1 { TP }, CN 2 } }\n")
    program = compile_text(text).program
    assert all(len(m.ops) <= 16 for m in program.macros.values())
    assert program.macros[0].ops[-1].text == "RP2"
    report = Report("t")
    module = build(parse(text, report))
    env = check_module(module, report, None)
    stored = {s: [(op.mnemonic, op.arg) for op in m.ops] for s, m in program.macros.items()}
    for inputs in (set(), {1}):
        assert firmware_trace(stored, inputs) == high_level_trace(module, env, inputs)
