"""Lowering very long blocks (the one-macro line of 100,000 commands): a block is
chained into thousands of parts without recursion or quadratic copies (the times are in
benchmarks/check_large.py)."""
from __future__ import annotations

from helpers.compiling import compile_text


def test_a_long_hoisted_block_is_read_back_without_recursion():
    """A when block of 20,000 commands becomes 1,300 chained parts, which the nested-call
    check read back by recursion, one level a part (RecursionError: 'internal error')."""
    text = "macro a { when 1 { " + ",".join(["MR 1"] * 20_000) + " }, TP }\n"
    found = {(d.rule.name, "internal" in d.message) for d in compile_text(text).report.items}
    assert found == {("slot-range", False), ("nested-call", False)}


def test_parts_are_named_in_order_and_each_once():
    text = "macro a { " + ",".join(["MR 1"] * 2_000) + " }\n"
    names = [d.message.removeprefix("no free slot for ").split(":")[0]
             for d in compile_text(text).report.items if d.rule.name == "slot-range"]
    assert names == [f"part {n} of a" for n in range(32, 32 + len(names))]


def test_parts_of_a_block_lowered_twice_keep_their_names():
    """A hoisted block that calls on is lowered again with a macro for the rest: its parts
    are made again under the same names (a guard of the part numbering)."""
    ones, twos = ",".join(["MR 1"] * 35), ",".join(["MR 2"] * 19)
    text = f"autostart {{ when 1 {{ {ones} }}, TT, when 2 {{ {twos} }}, TP }}\n"
    program = compile_text(text).program
    assert sorted(program.names().items()) == [
        (0, "autostart"), (1, "autostart.when@1"), (2, "autostart.rest@1"),
        (3, "autostart.rest@1.when@1"), (4, "autostart.rest@1.rest@1"),
        (5, "autostart.rest@1.when@1.part2"), (6, "autostart.when@1.part2"),
        (7, "autostart.when@1.part3")]
