"""`mercmac commands [--model M] [WORD]` and `mercmac explain MNEMONIC`: the
language is learned from the tool. Both read the one command table (mercmac.commands)."""
from __future__ import annotations

import pytest

from helpers.cli import cli, mercmac_process
from mercmac.commands import COMMANDS, C663, C863
from mercmac.compiler import guesses
from mercmac.compiler.parse import KEYWORDS
from mercmac.render import explain
from mercmac.render.commands import command_help, facts


def listed(output: str) -> list[str]:
    """The mnemonics of a `mercmac commands` table, in order (the header and notes aside)."""
    rows = output.split("command  ", 1)[1].splitlines()[1:]
    return [row.split()[0] for row in rows if row.strip()]


# -- the list ---------------------------------------------------------------------------------

def test_every_command_is_listed_once_with_its_argument_and_models():
    result = cli("commands")
    assert result.exit_code == 0, result.output
    assert sorted(listed(result.output)) == sorted(COMMANDS)
    row = next(r for r in result.output.splitlines() if r.startswith("DP "))
    assert "C-863" in row and "C-663" not in row and "a gain 0-65535 (optional)" in row


@pytest.mark.parametrize("word, first", [
    ("led", ["CN", "CF", "CP"]),  # the box's LEDs are outputs 1-4 (MS176E §3.8.6)
    ("LED", ["CN", "CF", "CP"]),
    ("wait", ["WA", "WS", "WN", "WF"]),
    ("velocity", ["SV"]),  # the setting before its reports and the joystick
    ("mr", ["MR"]),
    ("sleep", ["WA"]),  # a natural guess (compiler/guesses.py)
    ("button", ["WN", "WF"]),
    ("veloc", ["SV"]),  # the start of a word
])
def test_search_by_words_of_the_description(word, first):
    result = cli("commands", word)
    assert result.exit_code == 0, result.output
    assert listed(result.output)[:len(first)] == first


def test_several_words_must_all_match():
    assert listed(cli("commands", "move", "relative").output) == ["MR"]
    assert set(listed(cli("commands", "report position").output)[:3]) == {"TE", "TP", "TT"}


@pytest.mark.parametrize("model, absent", [(C663, "DP"), (C863, "DC")])
def test_model_leaves_out_what_it_lacks(model, absent):
    everything = listed(cli("commands", "--model", model.lower()).output)
    assert absent not in everything and "MR" in everything
    assert len(everything) == sum(c.available_on(model) for c in COMMANDS.values())


def test_no_match_exits_1_and_says_so():
    result = cli("commands", "xyzzy")
    assert result.exit_code == 1
    assert "no command mentions 'xyzzy'" in result.output
    assert "command  " not in result.output
    other = cli("commands", "--model", "C-663", "DP")
    assert other.exit_code == 1 and "no command of the C-663 mentions 'DP'" in other.output


def test_a_guess_without_commands_says_what_to_write():
    result = cli("commands", "main")
    assert result.exit_code == 1 and "autostart" in result.output


def test_a_word_only_a_guess_knows_gets_its_note():
    result = cli("commands", "sleep")
    assert "note: sleep: write `WA n`" in result.output
    assert "note:" not in cli("commands", "wait").output  # the descriptions say it already


def test_the_list_as_a_real_process(tmp_path):
    out = mercmac_process("commands", "led", cwd=tmp_path)
    assert out.returncode == 0 and listed(out.stdout) == ["CN", "CF", "CP"], out.stderr


# -- explain MNEMONIC -------------------------------------------------------------------------

@pytest.mark.parametrize("mnemonic", sorted(COMMANDS))
def test_explain_any_mnemonic_says_what_the_hover_says(mnemonic):
    from mercmac.lsp.symbols import command_help as hover

    result = cli("explain", mnemonic.lower())
    assert result.exit_code == 0, result.output
    c = COMMANDS[mnemonic]
    assert result.output.startswith(f"{c.mnemonic}: {c.summary}")
    for label, text in facts(c):
        assert f"{label}: {text}" in result.output
        assert f"- {label}: {text}" in hover(mnemonic)
    assert hover(mnemonic) == command_help(mnemonic)  # one text: the hover re-uses it


def test_explain_cn_names_the_led_range_and_section():
    out = cli("explain", "CN").output
    assert "LED n" in out and "range: 1..4" in out and "MS176E §6.4, p. 48" in out


@pytest.mark.parametrize("mnemonic, manual, chosen", [
    # §6.4 RP: "repeats indefinitely"; §3.8.6: RP,RP "more than 4 billion times"
    ("RP", ['"repeats indefinitely"', "§3.8.6", "more than 4 billion"],
     ["RP65535", "65,536 times", "2^32"]),
    ("WA", ['"0 < n < 65,535"'], ["0-65,535 is accepted", "1-65,534"]),  # §6.4 WA heading
    ("SJ", ["§6.4 SJ", "§3.6.2"], ["-1024 to 1024"]),
    ("TS", ["§6.4 TS"], ["clears it to 00"]),
])
def test_explain_says_which_reading_of_the_manual_mercmac_took(mnemonic, manual, chosen):
    out = cli("explain", mnemonic).output
    said = out.split("the manual: ", 1)[1]
    assert all(text in said.split("\n")[0] for text in manual), out
    taken = said.split("mercmac's choice: ", 1)[1].split("\n")[0]
    assert all(text in taken for text in chosen), out
    assert "mercmac's choice: " in command_help(mnemonic)  # the editor's hover says it too


def test_every_reading_cites_the_manual_and_commands_without_one_say_none():
    for c in COMMANDS.values():
        for reading in c.readings:
            assert "§" in reading.manual and reading.mercmac, c.mnemonic
    assert "the manual: " not in cli("explain", "MR").output  # MR: the manual says one thing


def test_explain_still_explains_rules():
    assert "§3.8.4" in cli("explain", "MM011").output
    assert cli("explain", "nested-call").output == cli("explain", "MM011").output


def test_no_word_is_both_a_rule_and_a_mnemonic_today():
    keys = {r.code.lower() for r in explain.ALL} | {r.name.lower() for r in explain.ALL}
    assert keys.isdisjoint(m.lower() for m in COMMANDS)


def test_a_word_that_is_both_shows_both(monkeypatch):
    rule = explain.ALL[0]._replace(code="MX999", name="mr")
    monkeypatch.setitem(explain._BY_KEY, "mr", rule)
    out = cli("explain", "MR").output
    assert out.index("MX999 mr") < out.index("MR: Move relative")


@pytest.mark.parametrize("word, says", [
    ("LED", "write `CN n`"), ("wait", "write `WA n`"), ("loop", "every 20ms"), ("if", "when n")])
def test_explain_a_natural_guess(word, says):
    result = cli("explain", word)
    assert result.exit_code == 0 and "no command or keyword" in result.output
    assert says in result.output


@pytest.mark.parametrize("word, hint", [("xyzzy", "`mercmac commands`"),
                                        ("nestedcall", "did you mean 'nested-call'?"),
                                        ("nested", "did you mean 'nested-call'?"),
                                        ("", "`mercmac commands`"),
                                        ("9" * 5000, "`mercmac commands`")])
def test_explain_an_unknown_word(word, hint):
    result = cli("explain", word)
    assert result.exit_code == 2 and "no rule or command" in result.output
    assert hint in result.output


# -- the guesses table itself -----------------------------------------------------------------

def test_every_guess_points_at_commands_of_the_table_and_is_no_word_of_the_language():
    for word, g in guesses.GUESSES.items():
        assert all(m in COMMANDS for m in g.commands), word
        assert word.split()[0].upper() not in COMMANDS and word not in KEYWORDS, word
        assert word == word.lower()
        assert word.split()[0] in guesses.GUESSES  # `led off`: `led` is one too (hint's quick exit)


def test_explain_names_a_keyword_of_the_language():
    """`explain when` says what the hover says of the keyword (learn from the tool)."""
    from mercmac.render.commands import KEYWORD_HELP

    for word in ("when", "every", "goto"):
        out = cli("explain", word.upper() if word == "goto" else word)
        assert out.exit_code == 0, out.output
        assert KEYWORD_HELP[word].split(":")[0] in out.output
