"""The compiler keeps every meaning the firmware can hold, and says so when it cannot.

- Exact lowerings of the cases once refused or miscompiled (the techniques of
  docs/language.md, "Lowering", and the ones this adds).
- A property test on a richer generator than test_properties.py's (long bodies,
  loops that start macros, macros that call on only through hoisted blocks,
  called with code after the call, big counts and periods, repeat 0): every
  program is accepted (only the slot budget may run out) and its MD lines, run
  on the firmware model, mean what the source says for every held-input
  combination.
"""
from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from helpers.budgets import budget
from helpers.compiling import compile_text, rules
from mercmac.compiler.ast_builder import build
from mercmac.compiler.checks import check_module
from mercmac.compiler.parse import parse
from mercmac.compiler.program import MAX_COMMANDS, rp_counts, wait_pieces
from mercmac.diagnostics import Report
from helpers.programs import CONDITION, EFFECTS
from helpers.semantics import firmware_trace, high_level_trace, same_effects

MR = [f"MR {i}" for i in range(1, 16)]


def lowered(text: str) -> tuple[list[str], list[str]]:
    result = compile_text(text)
    names = [d.rule.name for d in result.report.sorted()]
    return (result.program.md_lines() if result.program and not result.report.has_errors else []), names


def means_the_same(text: str, inputs=range(16)) -> bool:
    result = compile_text(text)
    assert not result.report.has_errors, [d.message for d in result.report.items]
    stored = {s: [(op.mnemonic, op.arg) for op in m.ops] for s, m in result.program.macros.items()}
    report = Report("t")
    module = build(parse(text, report))
    env = check_module(module, report, None)
    held = [{n for n in range(1, 5) if mask >> (n - 1) & 1} for mask in inputs]
    return all(same_effects(firmware_trace(stored, i), high_level_trace(module, env, i)) for i in held)


# -- Must fix ---------------------------------------------------------------------
def test_a_call_of_a_macro_that_ends_in_a_goto_is_a_nested_call_naming_the_chain():
    result = compile_text("macro g { goto m }\nmacro m { CP 3 }\nautostart { call g, CN 1 }\n")
    [d] = [d for d in result.report.items if d.rule.name == "nested-call"]
    assert d.severity == 0 and d.span.line == 3 and "g (MC01) -> goto m (MC02)" in d.message
    text = "macro m3 { TP }\nmacro m4 { TT, goto m3 }\nautostart { repeat 2 { call m4 } }\n"
    assert "nested-call" in rules(text)
    # a goto of a when block stays a mode switch; a call as the last step may end in a goto
    assert "nested-call" not in rules("macro m { TP }\nautostart { when 1 { goto m }, TT }\n")
    assert "nested-call" not in rules("macro g { goto m }\nmacro m { TP }\nautostart { TT, call g }\n")


def test_a_long_when_block_followed_by_code_continues_in_a_rest_macro():
    text = "autostart { when 1 { " + ", ".join(MR[:14]) + ", MR 15, TT }, CP 1 }\n"
    lines, found = lowered(text)
    assert found == [] and lines == [
        "MD1,XN1," + ",".join(m.replace(" ", "") for m in MR[:14]) + ",EM3",
        "MD2,CP1", "MD3,MR15,TT,EM2", "MD0,EM1,EM2"]
    assert means_the_same(text)


def test_a_long_loop_followed_by_code_stays_in_line_and_moves_the_fewest_commands():
    text = "autostart { repeat 3 { " + ", ".join(MR) + ", TT }, CP 1 }\n"
    lines, found = lowered(text)
    assert found == [] and lines == [
        "MD1,MR1,MR2,MR3", "MD0,EM1," + ",".join(m.replace(" ", "") for m in MR[3:]) + ",TT,RP2,CP1"]
    assert means_the_same(text)
    hoisted = "autostart { TP, repeat 3 { " + ", ".join(MR) + ", TT }, CP 1 }\n"
    assert lowered(hoisted)[1] == [] and means_the_same(hoisted)


def test_a_goto_that_ends_a_loop_is_one_warning_and_the_loop_runs_once():
    text = "macro x { TP }\nautostart { repeat 3 { CN 1, TT, goto x }, CN 2 }\n"
    lines, found = lowered(text)
    assert found == ["goto-ends-loop"] and lines == ["MD1,TP", "MD0,CN1,TT,EM1"]
    assert means_the_same(text)
    nested = "macro x { TP }\nautostart { every 5ms { CN 1, repeat 2 { TT, goto x }, MR 4 } }\n"
    lines, found = lowered(nested)
    assert "syntax" not in found and lines == ["MD1,TP", "MD0,CN1,TT,EM1"] and means_the_same(nested)


def test_a_ti_moved_away_from_its_loop_is_reported():
    assert rules("autostart { repeat 3 { when 1 { TI } } }\n") == ["ti-moved"]
    assert rules("autostart { repeat 3 { TI, when 1 { TP } } }\n") == []
    assert rules("autostart { TP, repeat 3 { TI } }\n") == []
    # an inner loop kept in line would make TI read the inner RP: loops with TI stay apart
    assert lowered("autostart { repeat 3 { TP, repeat 2 { TI } } }\n")[0] == ["MD1,TI,RP1", "MD0,TP,EM1,RP2"]
    assert lowered("autostart { repeat 3 { repeat 2 { TI }, TP } }\n")[0] == ["MD1,TI,RP1", "MD0,EM1,TP,RP2"]


def test_running_out_of_slots_names_no_none_macro():
    text = "autostart { " + " ".join(f"when 1 {{ TP }}, CN {1 + i % 4}," for i in range(40)) + " TT }\n"
    result = compile_text(text)
    assert "slot-range" in rules(text)
    assert not any("None" in d.message for d in result.report.items)


def test_an_empty_macro_is_stored_as_a_command_that_does_nothing():
    lines, found = lowered("macro e { }\nautostart { call e, TP }\n")
    assert lines == ["MD1,WA0", "MD0,EM1,TP"] and found == []
    assert lowered("autostart { }\n")[0] == ["MD0,WA0"]
    assert lowered("autostart { repeat 0 { TP } }\n") == (["MD0,WA0"], ["repeat-zero"])


def test_c663_status_sets_ready_when_no_macro_runs():
    from mercmac.compiler.program import Op, Program
    from mercmac.vm.machine import Machine

    seen = []
    m = Machine(Program({}), model="C-663", on_report=lambda t, s: seen.append(s))
    m.power_on()
    m.execute_line([Op("TS")])
    m.run_until(5)
    block1 = int(seen[-1][2:4], 16)
    assert block1 & 0x01 and block1 & 0x02 and not block1 & 0x10  # ready, on target, no macro


# -- Go further ---------------------------------------------------------------------
def test_a_loop_that_starts_a_macro_stays_in_line_so_the_macro_may_be_called():
    text = "macro r { repeat 3 { MR 10, TT }, CN 2 }\nautostart { call r, TP }\n"
    assert lowered(text) == (["MD1,MR10,TT,RP2,CN2", "MD0,EM1,TP"], [])
    assert means_the_same(text)
    nested = "autostart { repeat 3 { repeat 2 { MR 1 }, MR 2 }, CN 1 }\n"
    assert lowered(nested)[0] == ["MD0,MR1,RP1,MR2,RP2,CN1"] and means_the_same(nested)


def test_small_repeats_in_a_when_in_a_loop_are_unrolled():
    text = "autostart { every 20ms { when 1 { repeat 3 { MR 100 } }, CN 2 } }\n"
    assert lowered(text) == (["MD1,XN1,MR100,MR100,MR100", "MD0,EM1,CN2,WA20,RP,RP"], [])
    assert means_the_same(text)


def test_a_macro_that_calls_on_only_through_its_blocks_is_inlined():
    text = "macro a { TP, repeat 3 { MR 1 }, TT }\nautostart { call a, CN 1 }\n"
    lines, found = lowered(text)
    assert found == [] and lines[-1] == "MD0,TP,EM3,TT,CN1" and means_the_same(text)
    # one that calls as written stays a nested call (docs/checks.md)
    assert "nested-call" in rules("macro a { call b, TP }\nmacro b { call c }\nmacro c { TP }\n")


def test_big_counts_and_periods_and_repeat_zero():
    assert rp_counts(40000) == (1, 19999) and rp_counts(32569) == (32568,) and rp_counts(32573) is None
    assert wait_pieces(120000) == [60000, 60000] and wait_pieces(70000) == [35000, 35000]
    assert lowered("autostart { repeat 40000 { MR 1 } }\n")[0] == ["MD0,MR1,RP1,RP19999"]
    assert lowered("autostart { every 2min { TP } }\n")[0] == ["MD0,TP,WA60000,WA60000,RP,RP"]
    assert lowered("autostart { repeat 0 { TP }, TT }\n") == (["MD0,TT"], ["repeat-zero"])
    assert means_the_same("autostart { repeat 40000 { MR 1 }, TT }\n", [0])


# -- Property: the documented techniques fit every generated program --------------
@st.composite
def body(draw, depth: int, leaves: int, subs: int, in_loop: bool, nested: bool):
    """Statements; calls only where they keep one return point: leaves (which may start
    with a loop) anywhere but in blocks nested in a loop, subs (macros that call on only
    through their blocks) anywhere but in a loop."""
    stmts = []
    # a long run, but not in a block nested in a loop: that block must call nothing, and
    # with its XN/XF it cannot hold 16 commands (no technique fits it; see the report)
    if not (in_loop and nested) and draw(st.integers(0, 9)) == 0:
        stmts += draw(st.lists(EFFECTS, min_size=12, max_size=20))
    for _ in range(draw(st.integers(0 if depth else 1, 4))):
        options = ["effect", "effect"]
        if leaves and not (in_loop and nested):
            options.append("leaf")
        if subs and not in_loop:
            options.append("sub")
        if depth < 2:
            options += ["when", "repeat"] + ([] if in_loop else ["every"])
        kind = draw(st.sampled_from(options))
        if kind == "effect":
            stmts.append(draw(EFFECTS))
        elif kind in ("leaf", "sub"):
            stmts.append(f"call {kind}{draw(st.integers(0, (leaves if kind == 'leaf' else subs) - 1))}")
        elif kind == "when":
            conds = " and ".join(draw(st.lists(CONDITION, min_size=1, max_size=2)))
            stmts.append(f"when {conds} {{ {', '.join(draw(body(depth + 1, leaves, subs, in_loop, True)))} }}")
        elif kind == "repeat":
            count = draw(st.sampled_from([0, 1, 2, 3, 3, 40000]))
            stmts.append(f"repeat {count} {{ {', '.join(draw(body(depth + 1, leaves, subs, True, in_loop)))} }}")
        else:
            period = draw(st.sampled_from(["0ms", "7ms", "20ms", "2min"]))
            stmts.append(f"every {period} {{ {', '.join(draw(body(depth + 1, leaves, subs, True, in_loop)))} }}")
    return stmts


@st.composite
def rich_programs(draw):
    leaves, subs = draw(st.integers(0, 2)), draw(st.integers(0, 2))
    text = []
    for i in range(leaves):
        effects = draw(st.lists(EFFECTS, min_size=1, max_size=6))
        if draw(st.booleans()):
            effects = [f"repeat {draw(st.integers(2, 4))} {{ {', '.join(effects[:3])} }}"] + effects[3:]
        text.append(f"macro leaf{i} {{ {', '.join(effects)} }}")
    for i in range(subs):
        text.append(f"macro sub{i} {{\n  " + "\n  ".join(draw(body(1, 0, 0, False, False))) + "\n}")
    text.append("autostart {\n  " + "\n  ".join(draw(body(0, leaves, subs, False, False))) + "\n}")
    return "\n".join(text) + "\n"


@pytest.mark.slow
@settings(max_examples=budget(300), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(rich_programs())
def test_no_rejection_the_techniques_could_express_and_the_meaning_is_kept(text):
    result = compile_text(text)
    errors = {d.rule.name for d in result.report.items if d.severity == 0}
    if errors == {"slot-range"}:
        return
    assert not errors, (text, [d.message for d in result.report.items])
    for m in result.program.macros.values():
        assert len(m.ops) <= MAX_COMMANDS, (text, m.md)
    assert means_the_same(text, range(0, 16, 3)), text


def test_a_closing_brace_ends_its_statement_as_in_the_issue():
    """`repeat 3 { ... }  CP 1` on one line: the brace separates, as a comma would."""
    body = ", ".join(MR[:15]) + ", TT"
    lines, found = lowered("autostart { repeat 3 { " + body + " }  CP 1 }\n")
    assert found == [] and lines == [
        "MD1,MR1,MR2,MR3", "MD0,EM1," + ",".join(m.replace(" ", "") for m in MR[3:15]) + ",TT,RP2,CP1"]
    lines, found = lowered("macro x { TP }\nautostart { repeat 3 { CN1, TT, goto x }  CN2 }\n")
    assert found == ["goto-ends-loop"] and lines == ["MD1,TP", "MD0,CN1,TT,EM1"]
