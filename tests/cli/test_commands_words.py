"""`mercmac commands WORD` knows the words a user comes with, not only the manual's: a camera
is triggered by the trigger output (MS176E §4.5.2), a jog box is the joystick (§3.6)."""
from __future__ import annotations

import pytest

from helpers.cli import cli
from mercmac.commands import COMMANDS, SYNONYMS, search
from mercmac.compiler import guesses


def listed(output: str) -> list[str]:
    """The mnemonics of a `mercmac commands` table, in order (the header and notes aside)."""
    rows = output.split("command  ", 1)[1].splitlines()[1:]
    return [row.split()[0] for row in rows if row.strip()]


@pytest.mark.parametrize("word, first", [
    ("camera", ["ZM", "ZP", "ZI"]),
    ("shutter", ["ZM", "ZP", "ZI"]),
    ("trigger", ["ZM", "ZP", "ZI"]),
    ("pulse", ["ZM", "ZP", "ZI"]),
    ("led", ["CN", "CF", "CP"]),
    ("button", ["WN", "WF"]),
    ("home", ["GH", "FE", "DH"]),
    ("homing", ["DH", "GH", "FE"]),
    ("limit", ["LF", "LN", "LH", "LL"]),
    ("speed", ["SV"]),
    ("velocity", ["SV"]),
    ("accelerate", ["SA", "TL"]),
    ("acceleration", ["SA", "TL"]),
    ("jog", ["JN", "JF"]),
    ("joystick", ["JN", "JF"]),
    ("wait", ["WA", "WS", "WN", "WF"]),
    ("stop", ["AB", "ST"]),
    ("position", ["MA", "TP", "DH"]),  # before "Trigger position" and the position-control gains
    ("reference", ["FE"]),
    ("pid", ["DD", "DI", "DP"]),
    ("get position", ["TP"]),
])
def test_a_users_word_finds_its_commands_first(word, first):
    result = cli("commands", *word.split())
    assert result.exit_code == 0, result.output
    assert listed(result.output)[:len(first)] == first


def test_a_word_said_in_passing_comes_after_the_word_a_summary_is_about():
    """'position' in "Move absolute to position n" names what MA does; in "Derivative gain,
    position control" it only qualifies the gain."""
    found = [c.mnemonic for c in search(["position"])]
    assert found.index("TT") < found.index("DD") and found.index("MA") < found.index("DD")


def test_a_camera_gets_the_trigger_outputs_story():
    result = cli("commands", "camera")
    assert "note: camera: output 4 gives trigger pulses" in result.output
    assert "`ZM m`" in guesses.hint("camera")


def test_synonyms_are_words_of_the_table_not_mnemonics():
    described = " ".join(f"{c.summary} {c.arg_name} {c.kind.value}".lower()
                         for c in COMMANDS.values())
    for word, means in SYNONYMS.items():
        assert word.upper() not in COMMANDS, word
        assert all(m in described for m in means), (word, means)
        assert search([word]), word
