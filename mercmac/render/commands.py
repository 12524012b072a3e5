"""A native command in words (MS176E §6.4, the one command table mercmac.commands): the
language server's hover, `mercmac explain MR` and the list of `mercmac commands`."""
from __future__ import annotations

from mercmac.commands import Arg, Command, lookup
from mercmac.commands import Mnemonic as M
from mercmac.render.console import Line, table, write_lines

HEADER = ("command", "models", "argument", "what it does")
# The constructs of the language that write these commands (docs/language.md), for a reader who
# found the command first.
_CONSTRUCTS = {
    M.XN: "`when n { ... }` runs a block only if input n is on",
    M.XF: "`when not n { ... }` runs a block only if input n is off",
    M.RP: "`repeat 10 { ... }` (RP9), `every 20ms { ... }` (WA20,RP,RP: a polling loop)",
    M.EM: "`call NAME` (run it and come back), `goto NAME` (for good)",
    M.MD: "`macro NAME { ... }`, `autostart { ... }` (macro 0); `mercmac flash` sends MD",
}


# What each keyword of the language means (docs/language.md): the hover and `mercmac explain when`.
KEYWORD_HELP = {
    "target": "`target C-863` / `target C-663`: the controller model, for the model checks "
              "and the simulator's defaults. It lowers to nothing.",
    "const": "`const NAME = 250000`: a named integer, usable wherever a number goes; it "
             "lowers to the number.",
    "macro": "`macro NAME { ... }` / `macro NAME @20 { ... }`: a named macro. The compiler "
             "gives it a free slot, or the pinned one; it lowers to `MDn,...`.",
    "autostart": "`autostart { ... }`: macro 0, which the controller runs at power-on and "
                 "reset (MS176E §3.8.5). It lowers to `MD0,...`.",
    "call": "`call NAME`: run NAME, then continue here (`EMn`). The controller keeps one "
            "return point (MS176E §3.8.4), so NAME must not call further.",
    "goto": "`goto NAME`: go on in NAME for good (`EMn` as the last command); only as the "
            "last statement of its block.",
    "when": "`when 1 { ... }`, `when not 2 { ... }`, `when 2 and 3 { ... }`: run the block "
            "only while the inputs hold (1-4 buttons, 5 joystick, 6 joystick button); an "
            "`XN`/`XF` prefix, the block in a macro of its own unless it ends its macro.",
    "repeat": "`repeat 10 { ... }`: run the block 10 times (`...,RP9`), hoisted into a "
              "macro of its own unless it is the whole macro.",
    "every": "`every 20ms { ... }`: a stand-alone polling loop that runs for ever "
             "(`...,WA20,RP,RP`).",
    "not": "`when not 2 { ... }`: the condition holds while input 2 is off (`XF2`).",
    "and": "`when 2 and 3 { ... }`: both conditions must hold (`XN2,XN3`).",
}


def facts(c: Command) -> list[tuple[str, str]]:
    """What there is to say about a command, (label, text) each: the one wording of the
    hover and of `mercmac explain`."""
    said = [("argument", c.expects())]
    if c.arg is not Arg.NONE:
        said.append(("range", c.range_text()))
    if c.default is not None:
        said.append(("default when omitted", str(c.default)))
    said.append(("models", ", ".join(sorted(c.models))))
    if not c.storable:
        said.append(("direct mode only", "cannot be stored in a macro"))
    if c.mnemonic in _CONSTRUCTS:
        said.append(("in a .mcm file", _CONSTRUCTS[c.mnemonic]))
    said.append(("manual", c.section))
    for reading in c.readings:  # where mercmac chose between readings of the manual
        said += [("the manual", reading.manual), ("mercmac's choice", reading.mercmac)]
    return said


def command_help(mnemonic: str) -> str | None:
    """The hover of a mnemonic in Markdown: what it does and its facts; None if unknown."""
    c = lookup(mnemonic)
    if c is None:
        return None
    return "\n".join([f"**{c.mnemonic}**: {c.summary} ({c.kind.value})", "",
                      *(f"- {label}: {text}" for label, text in facts(c))])


def keyword_explanation(word: str) -> list[Line]:
    """`mercmac explain when`: what a keyword of the language means; [] for any other word."""
    said = KEYWORD_HELP.get(word.lower())
    return [[(word.lower(), "bold"), (" (a keyword of the .mcm language)", "")],
            [(said, "")]] if said else []


def explanation(c: Command) -> list[Line]:
    """`mercmac explain MR`: what the hover says, as lines for the terminal."""
    return [[(c.mnemonic, "bold"), (f": {c.summary}", ""), (f" ({c.kind.value})", "dim")],
            [("", "")], *([(f"{label}: ", "bold"), (text, "")] for label, text in facts(c))]


def write_list(found: list[Command], said: list[str] = ()) -> None:
    """`mercmac commands`: one line per command, after what a natural guess says."""
    lines: list[Line] = [[("note: ", "bold"), (text, "")] for text in said]
    rows = [(c.mnemonic, ", ".join(sorted(c.models)), c.argument(), c.summary) for c in found]
    write_lines(lines + table(HEADER, rows))
