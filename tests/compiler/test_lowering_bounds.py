"""Lowering does bounded work on any file within the parser's limits.

Before, a hoisted block that calls on was lowered once alone (to see that it calls on)
and again with the rest of its line as its tail, and so was every block inside it: 2^depth
lowerings of the innermost block (16 levels 0.9 s, 18 levels 3.6 s, 32 levels hours). And a line of
thousands of statements that run in place (`repeat 1 { ... }`) or of blocks that each
take the return point recursed once per statement (RecursionError: "internal error").
The work is counted here, not timed (the times are in benchmarks/check_large.py).
"""
from __future__ import annotations

import subprocess
import sys

import pytest

from helpers.compiling import compile_text
from mercmac.compiler import lower
from mercmac.compiler.ast_builder import build
from mercmac.compiler.checks import check_module
from mercmac.compiler.parse import MAX_NESTING, parse
from mercmac.diagnostics import Report
from helpers.semantics import firmware_trace, high_level_trace, same_effects

N = MAX_NESTING
LONG = ", ".join(["MR 2"] * 20)  # a body over 16 commands: chained into parts, so it calls on

# One level of a nest around `{}`; each is wrapped N deep (two-level ones N/2 times).
SHAPES = {
    "when, then code": ("when 1 {{ {} }} MR 1", 1),
    "when, then a comma": ("when 1 {{ {} }}, TP", 1),
    "when around repeat": ("when 1 {{ repeat 2 {{ {} }} MR 1 }} MR 1", 2),
    "when around every": ("when 1 {{ every 10ms {{ {} }} TP }} MR 1", 2),
    "every around when": ("every 10ms {{ TP, when 1 {{ {} }} MR 1 }} MR 1", 2),
    "repeat around when": ("repeat 2 {{ TP, when 1 {{ {} }} MR 1 }} MR 1", 2),
    "long body after": ("when 1 {{ {}, " + LONG + " }} MR 1", 1),
    "long body before": ("when 1 {{ " + LONG + ", {} }} MR 1", 1),
}


class TooMuchWork(Exception):
    pass


@pytest.fixture
def work(monkeypatch):
    """Counts the passes of `lower` and the blocks they lower; stops the old exponential
    lowering by count long before it would hang."""
    counts = {"passes": 0, "blocks": 0}
    init, block_ops = lower._Lowerer.__init__, lower._Lowerer.block_ops

    def counted_init(self, *args, **kw):
        counts["passes"] += 1
        init(self, *args, **kw)

    def counted_block_ops(self, *args, **kw):
        counts["blocks"] += 1
        if counts["blocks"] > 4 * N * N:
            raise TooMuchWork(f"more than {4 * N * N:,} block lowerings")
        return block_ops(self, *args, **kw)

    monkeypatch.setattr(lower._Lowerer, "__init__", counted_init)
    monkeypatch.setattr(lower._Lowerer, "block_ops", counted_block_ops)
    return counts


def nest(level: str, depth: int) -> str:
    """`level` around itself `depth` times in a macro, and its caller."""
    body = "MR 1"
    for _ in range(depth):
        body = level.format(body)
    return f"macro a {{ {body} }}\nautostart {{ call a }}\n"


@pytest.mark.parametrize("shape", SHAPES)
def test_a_nest_32_deep_lowers_each_block_once_per_block_around_it(work, shape):
    """At most N² block lowerings per pass of `lower` (it makes a second when `a` turns
    out to call on): each block once per block around it, and once alone."""
    level, levels = SHAPES[shape]
    result = compile_text(nest(level, N // levels))
    assert work["blocks"] <= work["passes"] * N * N, work
    # 32 levels need more than 32 macros: said as such, never as an internal error
    assert "slot-range" in {d.rule.name for d in result.report.items}
    assert not any("internal" in d.message for d in result.report.items)


def test_a_nest_15_deep_that_fits_builds_what_it_means(work):
    """The deepest `when` nest that fits 32 slots (each level is a block and its rest:
    16 levels need 33 macros)."""
    body = "MR 1"
    for level in range(15):
        body = f"when {level % 4 + 1} {{ {body} }} TP"
    text = f"macro a {{ {body} }}\nautostart {{ call a }}\n"
    result = compile_text(text)
    assert not result.report.has_errors, [d.message for d in result.report.items]
    assert len(result.program.macros) == 31
    stored = {s: [(op.mnemonic, op.arg) for op in m.ops] for s, m in result.program.macros.items()}
    report = Report("t.mcm")
    module = build(parse(text, report))
    env = check_module(module, report, None)
    for mask in range(16):
        inputs = {n for n in range(1, 5) if mask >> (n - 1) & 1}
        assert same_effects(firmware_trace(stored, inputs), high_level_trace(module, env, inputs))
    assert work["blocks"] <= work["passes"] * 15 * 15, work


def check(tmp_path, text: str) -> subprocess.CompletedProcess:
    """`mercmac check FILE` in a real process."""
    path = tmp_path / "long.mcm"
    path.write_text(text, encoding="ascii")
    return subprocess.run([sys.executable, "-m", "mercmac", "check", str(path)],
                          capture_output=True, text=True, timeout=120)


def test_a_line_of_3000_loops_that_run_once_is_a_slot_range_error(tmp_path):
    """3,000 TPs do not fit 32 macros: said as slot-range, not as an internal error."""
    done = check(tmp_path, "macro a { " + ", ".join(["repeat 1 { TP }"] * 3000) + " }\n"
                 "autostart { call a }\n")
    assert done.returncode == 1, done.stderr
    assert "slot-range" in done.stdout
    assert "internal error" not in done.stdout + done.stderr
    assert "Traceback" not in done.stderr


def test_a_line_of_3000_statements_run_in_place_builds():
    """Each `repeat 1` runs its body in place, which runs nothing: the line is one TP."""
    text = "macro a { " + ", ".join(["repeat 1 { repeat 0 { TT } }"] * 3000) + ", TP }\n" \
           "autostart { call a }\n"
    result = compile_text(text)
    assert [d.rule.name for d in result.report.items if d.severity == 0] == []
    assert [m.md for m in result.program.macros.values()] == ["MD0,EM1", "MD1,TP"]


def test_a_chain_of_3000_blocks_that_call_on_is_a_slot_range_error_with_short_names():
    """Each block takes the return point, so the rest of the line is a macro of its own,
    6,000 macros in all: each is reported, and a rest is named after its owner only while
    the chain could still fit (names thousands of owners long made gigabytes)."""
    lines = "\n".join(["  when 1 { call b }, TP"] * 3000)
    result = compile_text(f"macro b {{ TT }}\nmacro a {{\n{lines}\n}}\nautostart {{ call a }}\n")
    found = result.report.items
    assert {d.rule.name for d in found} == {"slot-range"}
    assert len(found) == 3 + 2 * 3000 - 32  # all the macros but the 32 stored
    names = [d.message.removeprefix("no free slot for ").split(": ")[0] for d in found]
    assert len(set(names)) == len(names)
    assert names[-2:] == ["the `when` at line 3002", "the rest of a from line 3002"]
    assert max(len(d.message) for d in found) < 400


def test_a_block_lowered_alone_first_reports_nothing_of_that_lowering():
    """A block that calls on is lowered alone, then again with its rest: the too-long loop
    in it was reported by both, and again when every macro was fitted at the end (three
    times); once now."""
    loop = ", ".join(["XN 1, TP"] * 9)  # 18 commands, none of which may move out of the loop
    text = f"macro a {{ when 1 {{ MR 1, repeat 2 {{ {loop} }} MR 3 }}, TP }}\nautostart {{ call a }}\n"
    assert [d.rule.name for d in compile_text(text).report.items] == ["too-many-commands"]


def test_ti_moved_names_the_macro_the_ti_runs_in():
    """The warning came from the dropped lowering and named a macro that is not built."""
    text = ("macro sub { SV 2000 }\nmacro m {\n  TP\n  repeat 3 { when 4 { when 4 { when 2 { TT }, "
            "when 3 { call sub, TI, goto n } }, goto n } }\n}\nmacro n { TT }\nautostart { call m }\n")
    result = compile_text(text)
    [warning] = result.report.items
    holder = [m.name for m in result.program.macros.values() if any(op.mnemonic == "TI" for op in m.ops)]
    assert warning.rule.name == "ti-moved" and holder == ["m.repeat@4.when@4.when@4.when@4:47"]
    assert "this TI runs in the `when` at line 4, column 47," in warning.message
