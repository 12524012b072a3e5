"""`nested-call` in a loop advises what works (goto the work, goto back to the loop), in the
user's names; no message names a macro the compiler made ('jog.when@4.repeat@5')."""
from __future__ import annotations

import re

import pytest

from helpers.compiling import compile_text, program_of
from mercmac.compiler.program import as_written

MADE_UP = re.compile(r"\w\.(when|repeat|every|rest)@|\.part\d")

# (program, what the advice says, the program written as advised)
CASES = [
    # the when block calls a macro of the user's: goto it, and it goes back to the loop
    ("macro stepper { repeat 100 { MR 10, WS 10 } }\n"
     "macro jog { every 20ms { when 1 { call stepper } } }\nautostart { goto jog }\n",
     ["`goto stepper`", "end stepper with `goto jog`"],
     "macro stepper { repeat 100 { MR 10, WS 10 }, goto jog }\n"
     "macro jog { every 20ms { when 1 { goto stepper } } }\nautostart { goto jog }\n"),
    # the old advice (move the commands into the block) led here: the repeat is a macro too
    ("macro jog {\n  every 20ms {\n    when 1 {\n      repeat 100 { MR 10, WS 10 }\n    }\n  }\n}\n"
     "autostart { goto jog }\n",
     ["the `repeat` at line 4", "`goto jog`"],
     "macro jog { every 20ms { when 1 { goto work } } }\n"
     "macro work { repeat 100 { MR 10, WS 10 }, goto jog }\nautostart { goto jog }\n"),
    # a loop in autostart has no name to go back to: the advice says it needs a macro
    ("macro stepper { MR 100, call other }\nmacro other { MR 5 }\n"
     "autostart {\n  every 20ms {\n    when 1 { call stepper }\n  }\n}\n",
     ["`goto stepper`", "loop at line 4, which needs a macro of its own"],
     "macro stepper { MR 100, call other, goto poll }\nmacro other { MR 5 }\n"
     "macro poll { every 20ms { when 1 { goto stepper } } }\nautostart { goto poll }\n"),
    # a loop after other commands is a block of the macro, not the macro
    ("macro jog {\n  CN 1\n  repeat 5 {\n    when 1 {\n      TT\n"
     "      repeat 100 { MR 10, WS 10 }\n    }\n    WA 5\n  }\n}\nautostart { goto jog }\n",
     ["the `repeat` at line 6", "loop at line 3, which needs a macro of its own"],
     "macro jog { CN 1, goto loop }\nmacro loop { repeat 5 { when 1 { TT, goto work }, WA 5 } }\n"
     "macro work { repeat 100 { MR 10, WS 10 }, goto loop }\nautostart { goto jog }\n"),
]


@pytest.mark.parametrize("text, says, advised", CASES)
def test_the_advice_in_a_loop_is_goto_and_goto_back(text, says, advised):
    [found] = compile_text(text).report.items
    assert found.rule.name == "nested-call"
    for words in says:
        assert words in found.message
    assert "move those commands into the block" not in found.message
    assert not MADE_UP.search(found.message), found.message
    program_of(advised)  # what the advice says checks clean


@pytest.mark.parametrize("name, said", [
    ("jog", "jog"),
    ("MC05", "MC05"),
    ("jog.when@29.repeat@30", "the `repeat` at line 30"),
    ("jog.when@4:47", "the `when` at line 4, column 47"),
    ("jog.when@29.rest@31", "the rest of jog from line 31"),
    ("jog.part2", "part 2 of jog"),
    ("jog.every@3.part3", "part 3 of the `every` at line 3"),
])
def test_a_made_name_is_said_as_the_block_the_user_wrote(name, said):
    assert as_written(name) == said


@pytest.mark.parametrize("text", [
    # ti-moved named 'm.repeat@2.when@2'
    "macro m {\n  TP\n  repeat 3 { when 1 { TI } }\n}\nautostart { call m }\n",
    # sc-outside-autostart named 'autostart.when@1'
    "autostart { when 1 { SC 1 }, TP }\n",
    # contradictory-condition in a hoisted block
    "autostart { when 1 and not 1 { TP }, TT }\n",
])
def test_no_message_names_a_macro_the_compiler_made(text):
    found = compile_text(text).report.items
    assert found
    for d in found:
        assert not MADE_UP.search(d.message), d.message
