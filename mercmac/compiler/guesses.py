"""Words a newcomer writes for what the controller spells otherwise: `LED 1`, `wait 100ms`,
`if 1 {` (docs/checks.md: the hint for a natural guess belongs to the rule that fires).

The one table of such words. `unknown-command` (compiler/checks.py) and `syntax` at the
start of a statement (compiler/parse.py) say its hint instead of a "did you mean" by
spelling, `mercmac explain WORD` says it too, and `mercmac commands WORD` finds the
commands a word points to. Only words whose answer the manual gives plainly.
"""
from __future__ import annotations

import re
from typing import NamedTuple

from mercmac.commands import Mnemonic as M


class Guess(NamedTuple):
    """Words that mean one thing, what to write instead, and where the manual says so."""

    words: tuple[str, ...]
    hint: str  # `{n}`: the number the user wrote after the word, else "n"
    commands: tuple[str, ...]  # the native commands it points to
    section: str
    construct: bool = False  # the answer is a construct of the language: not in a raw block
    duration: bool = False  # the number is a time: `wait 2s` is `WA 2000`


_TABLE = (
    # -- native commands --
    Guess(("led", "leds", "lamp", "light"),
          "to light LED {n} of the pushbutton box write `CN {n}` (`CF {n}` turns it off, "
          "`CP p` sets all four)", (M.CN, M.CF, M.CP), "MS176E §3.8.6, §6.4 CN p. 48"),
    Guess(("led off", "lamp off", "light off"),
          "to turn LED {n} of the pushbutton box off write `CF {n}` (`CN {n}` lights it)",
          (M.CF, M.CN, M.CP), "MS176E §3.8.6, §6.4 CF p. 48"),
    Guess(("output", "out"),
          "to switch output {n} on write `CN {n}` (`CF {n}` switches it off, `CP p` sets all "
          "four)", (M.CN, M.CF, M.CP), "MS176E §4.5.1, §6.4 CN p. 48"),
    Guess(("wait", "sleep", "delay", "pause"),
          "write `WA {n}` to wait {n} ms (`WS`: until the move has ended, `WN i`: until input "
          "i is on)", (M.WA, M.WS, M.WN, M.WF), "MS176E §6.4 WA p. 84",
          duration=True),
    Guess(("move",),
          "write `MR {n}` to move by {n} counts, `MA {n}` to move to position {n}",
          (M.MR, M.MA), "MS176E §6.4 MA p. 68, MR p. 69"),
    Guess(("home",),
          "`GH` moves to position 0; `FE` searches the reference switch, and `DH` makes the "
          "current position 0", (M.GH, M.FE, M.DH), "MS176E §4.3, §6.4 GH p. 60"),
    Guess(("stop", "halt", "abort"),
          "`AB 1` stops smoothly, `AB` at once (`ST` stops and moves back to where it was "
          "received)", (M.AB, M.ST), "MS176E §6.4 AB p. 47, ST p. 75"),
    Guess(("print", "report", "tell", "show", "echo"),
          "`TP` reports the position, `TT` the target; `mercmac commands report` lists every "
          "report", (M.TP, M.TT), "MS176E §5.6, §6.4 TP p. 79"),
    Guess(("speed", "velocity"), "write `SV {n}` to set the velocity to {n} counts/s",
          (M.SV,), "MS176E §6.4 SV p. 75"),
    Guess(("accel", "acceleration", "accelerate"),
          "write `SA {n}` to set the acceleration to {n} counts/s²", (M.SA,),
          "MS176E §6.4 SA p. 71"),
    Guess(("position", "pos"),
          "`MA {n}` moves to position {n}, `TP` reports the position, and `DH {n}` makes the "
          "current position {n}", (M.MA, M.TP, M.DH), "MS176E §6.4 MA p. 68, TP p. 79, DH p. 50"),
    Guess(("trigger", "camera", "shutter"),
          "output 4 gives trigger pulses to a camera or other device: `ZP p` sets the position "
          "of the first, `ZI i` the distance to the next, and `ZM m` the mode (1 one pulse, "
          "2 pulses from ZP every ZI, 3 a pulse every ZI counts, 0 off)",
          (M.ZM, M.ZP, M.ZI), "MS176E §4.5.2, §6.4 ZM p. 89"),
    Guess(("servo", "motor"), "`MN` switches the motor (servo) on, `MF` off",
          (M.MN, M.MF), "MS176E §6.4 MN p. 69"),
    # -- constructs of the language (docs/language.md) --
    Guess(("if",), "write `when {n} {{ ... }}`: the block runs only if input {n} is on "
                   "(`when not {n} {{ ... }}`: off)", (M.XN, M.XF), "MS176E §5.5, §6.4 XN p. 87",
          construct=True),
    Guess(("unless",), "write `when not {n} {{ ... }}`: the block runs only if input {n} is off",
          (M.XF,), "MS176E §5.5, §6.4 XF p. 87", construct=True),
    Guess(("else",), "there is no else: write a second block, `when not n {{ ... }}`",
          (M.XF,), "MS176E §5.5", construct=True),
    Guess(("while",), "`when n {{ ... }}` runs a block if input n is on; to test it again and "
                      "again put it in `every 20ms {{ ... }}`", (M.XN, M.RP),
          "MS176E §5.5, §3.8.6 Example 1", construct=True),
    Guess(("loop", "forever"), "`every 20ms {{ ... }}` runs a block again and again "
                               "(WA20,RP,RP: \"forever\"); `repeat 10 {{ ... }}` runs it 10 times",
          (M.RP,), "MS176E §3.8.6 Example 1, §6.4 RP p. 70", construct=True),
    Guess(("for",), "`repeat {n} {{ ... }}` runs a block {n} times", (M.RP,),
          "MS176E §6.4 RP p. 70", construct=True),
    Guess(("jump", "jmp"), "`goto NAME` goes to macro NAME for good; `call NAME` runs it and "
                           "comes back", (M.EM,), "MS176E §3.8.4, §6.4 EM p. 52", construct=True),
    Guess(("def", "function", "func", "sub", "proc"), "`macro NAME {{ ... }}` defines a macro",
          (M.MD,), "MS176E §3.8.1", construct=True),
    Guess(("main", "startup"), "`autostart {{ ... }}` is macro 0: it runs at power-on",
          (), "MS176E §3.8.5", construct=True),
    Guess(("var", "let", "define"), "`const NAME = 5` names a number", (), "", construct=True),
)

GUESSES: dict[str, Guess] = {word: g for g in _TABLE for word in g.words}
# word -> the native commands it points to, for `mercmac commands WORD` (commands.search)
POINTS_TO: dict[str, tuple[str, ...]] = {word: g.commands for word, g in GUESSES.items()}
# The number after the word: `1`, `-5`, `100ms`, `2 s`; or a second word: `LED off`.
_WORD = re.compile(r"[ \t]*([A-Za-z]+)")
_NUMBER = re.compile(r"[ \t]*([+-]?\d+(?:\.\d+)?(?:[ \t]*[A-Za-z]+)?)")


def guess(word: str) -> Guess | None:
    """The guess a word is, in any case, or None."""
    return GUESSES.get(word.lower())


def hint(word: str, after: str | None = None, *, raw: bool = False) -> str | None:
    """What to write instead of `word` (and `after`, the text that follows it), or None:
    no guess, or one whose answer is a construct and the word stands in a raw block."""
    if word.lower() not in GUESSES:  # the common case, quickly; a pair's first word is a guess
        return None
    after = after or ""
    then = _WORD.match(after)
    pair = guess(f"{word} {then.group(1)}") if then else None  # `LED off 2`
    found = pair or guess(word)
    if found is None or (raw and found.construct):
        return None
    return found.hint.format(n=_number(after[then.end():] if pair else after, found.duration))


def command(word: str, *, raw: bool = False) -> str | None:
    """The command a one-word guess names first (`LED`: CN), for a fix that is displayed,
    never applied; None for a construct of the language, or in a raw block."""
    found = guess(word)
    if found is None or found.construct or raw:
        return None
    return found.commands[0]


def _number(after: str, duration: bool) -> str:
    """The user's number as the hint writes it; 'n' when there is none (or it makes none)."""
    m = _NUMBER.match(after)
    if m is None:
        return "n"
    text = m.group(1)
    if duration:
        from mercmac.timespec import parse_duration

        try:
            return str(parse_duration(text))  # a bare number is ms, as WA takes it
        except ValueError:  # TimeSpecError: `-5`, `1.0001ms`, `5 parsecs`
            return "n"
    return text if re.fullmatch(r"[+-]?\d+", text) else "n"


def syntax_hint(word: str, after: str) -> tuple[str, dict] | None:
    """(variant, values) of the `syntax` error of a statement that starts with a guess
    (`if 1 {`, `wait 100ms`, `loop {`: parse.py), or None."""
    found = hint(word, after)
    return None if found is None else ("guess", {"word": word, "hint": found})
