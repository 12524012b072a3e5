"""Diagnostics are data: the rules (docs/checks.md), each with a stable code, its message
templates and its story (pyflakes `messages.py`, ruff's rule text beside the rule).

Checks only call `Report.add(rule, span, variant, **values)` and carry on: the
wording of every situation lives here, once, as a template of its rule.
Rendering lives in `mercmac.render`.
"""
from __future__ import annotations

import functools
from enum import Enum, IntEnum
from typing import Mapping, NamedTuple

from mercmac.source import Span


class Severity(IntEnum):
    """Ordered so that errors sort first."""

    ERROR = 0
    WARNING = 1
    INFO = 2

    def __str__(self) -> str:
        return self.name.lower()


class Rule(NamedTuple):
    """One check: stable code, kebab-case name, default severity, the long story, and the
    one-line message of each situation it reports (`{name}` fields, keyed by variant)."""

    code: str
    name: str
    severity: Severity
    summary: str
    explanation: str
    messages: Mapping[str, str] = {}

    def text(self, variant: str = "", /, **values) -> str:
        """The message of one situation, its template filled with `values`."""
        try:
            template = self.messages[variant]
        except KeyError:
            raise KeyError(f"rule {self.name} has no message {variant!r}: add its template "
                           "to mercmac/diagnostics.py") from None
        return template.format(**values)


_E, _W, _I = Severity.ERROR, Severity.WARNING, Severity.INFO

# Sentences that several messages of one rule start with.
_TOO_MANY = "{macro} holds {count} commands; a macro holds at most {max} (MS176E §3.8)"
_NESTED = ("{caller} calls {callee} and continues ({rest}), but {callee} calls {inner}: the "
           "controller keeps one return point (MS176E §3.8.4), so the rest of {caller} never "
           "runs after that")
_IN_LOOP = (". A when block in a loop is a macro the loop calls, so it may end in a goto but "
            "not call on")

RULES: tuple[Rule, ...] = (
    Rule("MM001", "syntax", _E, "the file cannot be parsed", """\
The parser met something it cannot read. The message points at the offending
token and says what would have been accepted there; for a native command it
says what argument the command takes (MS176E §6.4), e.g. "EM takes a macro
number 1-31" for the placeholder `EMxx` of the manual's Example 3.
A raw block is `[MCnn] CMD,CMD,...` on one line (MS176E §3.8.6); commands in a
high-level block are separated by commas or new lines. Fix the text at the
caret.""", {
        "unexpected": "unexpected {found}",
        "expected": "unexpected {found}; expected {expected}",
        "ascii": "unexpected {found}: names and commands are ASCII letters, digits and '_' "
                 "(arguments are ASCII digits)",
        "decimal": "arguments are whole numbers (counts, steps, ms); there is no decimal point",
        "argument": "{expects}, found {found}",
        "placeholder": "{expects}, found the placeholder '{placeholder}'",
        "keyword": "unknown word '{word}'; did you mean '{keyword}'?",
        "guess": "unknown word '{word}': {hint}",  # compiler/guesses.py
        "or": "there is no 'or': write one when block per condition, e.g. "
              "`when 1 {{ ... }}` and `when 2 {{ ... }}`",
        "milliseconds": "{command} takes plain milliseconds, without a unit: write "
                        "{command} {ms} for {written}",
        "unit": "{command} takes a plain number, without a unit ('{written}')",
        # named errors: parse.py keeps snippets that fail the same way (lark's match_examples)
        "comma": "commands are separated by commas",
        "outside": "a command must stand in a [MCnn] block or in a macro/autostart block",
        "brace": "a block needs its closing '}}'",
        "macro-header": "'macro' needs a name, an optional @slot and a block: macro NAME @5 {{ ... }}",
        "binary": "the file holds NUL characters: it looks like a binary file, not .mcm text "
                  "(UTF-8, Windows-1252, or UTF-16 with a byte-order mark)",
        "internal": "internal error while checking this file ({detail}); it was not fully "
                    "checked - please report this with the file",
    }),
    Rule("MM002", "unknown-command", _E, "mnemonic not in the manual's command set", """\
The controller only knows the base commands of MS176E §6.2. An unknown
mnemonic in a macro is stored as is and fails silently when the macro runs
(error 06 "Wrong Command" in the TS report, §6.4 TS). mercmac suggests the
nearest known mnemonic, or, for a word people write for a command (`LED 1`,
`wait 100`, `move 5000`), the command the manual has for it. `mercmac commands`
lists them all (`mercmac commands led` searches), `mercmac explain CN` tells one,
and §6.2 of the manual has the full list.""", {"": "unknown command '{word}'{hint}"}),
    Rule("MM003", "bad-argument", _E, "argument missing where required, or not a number", """\
Commands such as MA, MR, EM, CN, WA or XN need a number right after the
mnemonic (MS176E §6.1.2: "MR alone would be useless"). Arguments are decimal
integers, optionally signed; in high-level blocks a `const` name may stand for
the number, signed too (`MR -FAR`). Commands without an argument (TP, GH, ...) take none.""", {
        "model": "unknown model '{model}': use C-663 or C-863",
        "unexpected": "{expects}",
        "raw-name": "{expects}, found '{name}' (a raw block takes numbers only)",
        "missing": "{expects}: the argument is missing",
        "duration": "every takes a whole number of milliseconds: {error}",
    }),
    Rule("MM004", "argument-range", _E, "argument outside the manual's range", """\
Each argument has the range MS176E §6.4 gives: MA/MR targets within
+/-1,073,741,823, RP n <= 32568, CN/CF/WN/WF 1-4, XN/XF 1-6 (5 = joystick,
6 = joystick button), CP 0-15, EM 1-31, SC 0-15, FE 0-3, JT 0-3,
JN 1000-500000, WA 0-65535, TA 0-6, TC 0-4, ZM 0-3. Out-of-range values are
refused or misread by the firmware. `repeat N` needs 1 <= N <= 32569 (it
lowers to RP N-1) and `every T` 0-65535 ms (it lowers to WA T).""", {
        "": "{command} is out of range: {expects} ({range})",
        "repeat": "{number} is out of range: repeat takes a count 0-{max} (it lowers to RP n-1, "
                  "RP n <= 32568), or a product of two such counts (two RPs)",
        "when": "{number} is out of range: when takes inputs 1-6 (1-4 buttons, 5 joystick, "
                "6 joystick button)",
        "every": "{number} is out of range: every takes a whole period of 0-{max} ms (it lowers "
                 "to WA, several WAs of at most {wa} ms past that)",
        "digits": "a number of {digits:,} digits is out of every range (no argument of the "
                  "controller has more than 10)",
    }),
    Rule("MM005", "too-many-commands", _E, "a macro holds more than 16 base commands", """\
A stored macro holds at most 16 base commands (MS176E §3.8, §3.8.4). The
controller would cut or refuse a longer line. mercmac fits a long high-level
block when that keeps the meaning:
  - a straight line is chained into parts reached by a tail EM;
  - a loop (RP repeats the whole line, so a chain would repeat only its last
    part) keeps its line and moves runs of plain commands into macros it
    calls; what follows its last RP is chained;
  - a loop that starts its macro stays in the line (RP jumps to the start),
    so `repeat 3 { MR 10, TT }, CN 2` is `MR10,TT,RP2,CN2`, one macro;
  - a small repeat of plain commands in a block that must call nothing (a
    when inside a loop) is written out: `MR100,MR100,MR100`;
  - `repeat 40000` is `RP1,RP19999` (2 x 20000 passes), `every 2min` waits
    with `WA60000,WA60000`, `repeat 0` is left out.
Calls, XN/XF conditions and TI cannot move, and a raw `[MCnn]` block is kept
exactly as written. Move part of the work into a macro of its own and call it,
or shorten the block.""", {
        "": _TOO_MANY,
        "loop": "this loop holds {count} commands as written, and the compiler adds {added} to "
                "repeat them: {total}, and a macro holds at most {max} (MS176E §3.8). A loop "
                "line cannot be split (its RP repeats the whole line), and calls, conditions "
                "and TI cannot move out of it. Write at most {room} commands in the loop, or "
                "move some into a macro of your own and `call` it",
    }),
    Rule("MM006", "slot-range", _E, "macro number outside 0-31, or more than 32 macros", """\
Macros are numbered 0 to 31 (MS176E §3.8.4); macro 0 is the autostart macro.
A raw block or a pin (`macro NAME @n`) outside 0-31 cannot be stored, and a
program that needs more than 32 macros after hoisting and splitting does not
fit the controller. Merge small macros or drop unused ones.""", {
        "": "macro number {slot} is outside 0-31",
        "full": "no free slot for {name}: the program needs {count} macros and the "
                "controller holds 32",
        "nesting": "blocks nested more than {depth} deep cannot fit the controller (32 macros "
                   "of 16 commands): move inner blocks into macros of their own",
    }),
    Rule("MM007", "duplicate-slot", _E, "two blocks define the same slot", """\
MD gives no warning when it overwrites a macro (MS176E §3.8.1, §3.8.4): of two
blocks with the same number only the last one would be stored, silently. The
manual's Example 3 defines MC18 and MC19 twice. Give each block its own number
(or let mercmac allocate slots with `macro NAME { ... }`). A macro *name*
defined twice is `duplicate-name`.""", {"": "{what} defines slot {slot} again (first at line {first}); the controller "
              "silently keeps only the last definition"}),
    Rule("MM008", "sc-outside-autostart", _E, "SC anywhere but macro 0", """\
SC (select controller) "is only allowed in the Macro 0 (autostart macro)"
(MS176E §6.4 SC, §3.1.2). Elsewhere it does not select the controller. Move
SC into `autostart { ... }` / `[MC00]`, outside any `when` or `repeat` block
(those are hoisted into macros of their own).""", {
        "": "SC is only allowed in macro 0, the autostart macro",
        "moved": "SC is only allowed in macro 0, the autostart macro, and this SC runs in "
                 "{macro}, a macro of its own",
    }),
    Rule("MM009", "not-in-macro", _E, "a command that cannot be stored in a macro", """\
MD, RT, RM, RMALL and RZ manage the macro store itself and are for direct
mode only (MS176E §3.8.1, §3.8.5, §6.4 RT: "This command can not be used in a
macro command"). mercmac writes the macros for you: `mercmac flash` sends MD
and RZ as needed. Remove the command from the macro.""", {"": "{mnemonic} cannot be stored in a macro ({section})"}),
    Rule("MM010", "model-unsupported", _E, "command not available on the target model", """\
Some commands exist on one model only (MS176E §6.2: dark rows C-863, light
rows C-663): the PID and force-control commands (DP, DI, DD, DL, F*, GD, GI,
GL, GP, TE, TF, TD, TR, SB, SF, SM, WT, WW) are C-863 only, the current
settings DC, HC, HT are C-663 only. Checked when the target is known, from
`target C-863` in the file or `--target` on the command line.""", {"": "{mnemonic} is not available on the {target} ({models} only)"}),
    Rule("MM011", "nested-call", _W, "a called macro calls on: the caller's remainder never runs", """\
The controller keeps ONE return point (MS176E §3.8.4): "MC1 could call MC2,
but MC2 could not then call MC3 and still be able to return to complete the
remainder of MC1". When macro A continues after `EMb` and b contains an EM,
b's EM replaces A's return point and the rest of A never runs; Example 3's
MC18 can no longer return to its own caller. On raw blocks this is a warning
(it is the manual's way of switching modes, Example 4); on `call` it is an
error, and so is a `call` of a macro that ends in (or may run) a `goto`: it
never comes back. Use `goto` for a transfer that is not meant to return, make
the callee call nothing, or restructure. A `when` block in a loop is a macro
the loop calls, so work that calls on (or holds a loop of its own) goes in a
macro that the block ends with `goto work`, and that ends with `goto` back
to the macro the loop starts: `every 20ms { when 1 { goto work } }` in
`macro jog`, and `macro work { repeat 100 { MR 10, WS 10 }, goto jog }`.
mercmac does this for you where the meaning stays the same:
  - a hoisted `when`/`repeat` block that calls, or is too long for one macro,
    ends in a tail EM to a macro holding the rest of its caller;
  - a loop that starts its macro stays in the line, so the macro stays a leaf
    that may be called with code after the call;
  - a called macro that calls on (and holds no goto) is inlined into a caller
    that continues after the call;
  - a small repeat inside a `when` inside a loop is written out in place.""", {
        "": _NESTED,
        "split": _NESTED + ". {callee} holds more than {max} commands, so it was chained into "
                           "parts, and a called macro must fit in one: shorten it, or `goto` it",
        "call": _NESTED + ". Use `goto` if the caller need not continue, or make the called "
                          "macro call nothing (a split or hoisted block calls on too)",
        # a when block in a loop: goto the work, and goto back to the loop (MS176E §3.8.4)
        "loop": _NESTED + _IN_LOOP + ": end the block with `goto {target}` instead, and end "
                          "{target} with `goto {loop}`, back to the start of the loop",
        "loop-block": _NESTED + _IN_LOOP + ", and {inner} is a macro of its own: move it (and "
                                "what follows it in the block) into a macro, end the block "
                                "with a `goto` to that macro, and end that macro with "
                                "`goto {loop}`, back to the start of the loop",
        "loop-unnamed": _NESTED + _IN_LOOP + ": end the block with `goto {target}` instead, and "
                                  "end {target} with a `goto` back to the start of the loop at "
                                  "line {line}, which needs a macro of its own for that",
        "loop-block-unnamed": _NESTED + _IN_LOOP + ", and {inner} is a macro of its own: move "
                                        "it (and what follows it in the block) into a macro, "
                                        "end the block with a `goto` to that macro, and end "
                                        "that macro with a `goto` back to the start of the "
                                        "loop at line {line}, which needs a macro of its own "
                                        "for that",
        "goto": "{caller} calls {callee} and continues ({rest}), but {chain} transfers for "
                "good: the call never comes back, so the rest of {caller} never runs after it. "
                "Write `goto` if the caller need not continue, or make the called macro end "
                "without a goto",
    }),
    Rule("MM012", "undefined-macro", _W, "EM to a slot no block defines", """\
"If there is no macro defined for the number n, no action will be taken"
(MS176E §6.4 EM). Example 1's MC13 calls 14-17 without defining them. Define
the macro in the same file, or make sure it is already stored on the
controller.""", {"": "EM{slot}: no macro {slot} is defined here, so the controller does "
              "nothing (unless the macro is already stored on it)"}),
    Rule("MM013", "contradictory-condition", _W, "XNn and XFn on the same input in one macro", """\
XN and XF end the macro when their input is not ON / not OFF (MS176E §5.5,
§6.4 XN/XF). Testing the same input both ways in one macro means the commands
after the second test can only run if the input changed in between - usually
a typo: Example 2's MC14 says "unless button 1" but tests XF2. Check the input
numbers.""", {"": "{macro} tests input {input} with both {first} and {second}: the "
              "rest can only run if the input changed in between"}),
    Rule("MM014", "default-argument", _I, "argument omitted where the controller substitutes a default", """\
Some commands take a default when the argument is left out: WS waits 1000 ms
after the stop (§6.4 WS), a bare RP repeats 65535 times (mercmac's reading of
§6.4 RP and §3.8.6: `mercmac explain RP` says why), and a gain such as `DI,` is
set to 0 (Example 1). Write the value to make the intent explicit.""", {"": "{mnemonic} without an argument: the controller uses {default}"}),
    Rule("MM015", "joystick-in-macro", _W, "JN in a macro", """\
CAUTION (MS176E §3.6.1, §3.8.6): "Do not enable a joystick axis when no
joystick is connected to the controller hardware. Otherwise the corresponding
controller axis may start moving." A macro - above all the autostart macro -
runs with nobody watching. Make sure a calibrated joystick is always
connected, or enable it from the host instead.""", {"": "JN enables the joystick from a macro: the axis may move if no "
              "joystick is connected (MS176E §3.6.1 caution)"}),
    Rule("MM016", "unreachable-macro", _I, "macro not reachable from macro 0", """\
No chain of EM commands leads from the autostart macro (macro 0) to this
macro, so in stand-alone operation it never runs (MS176E §3.8.5). That is
fine for macros the host starts with EMn. Reported when the program has an
autostart macro.""", {"": "{macro} is not reached from the autostart macro; it runs only when "
              "the host starts it"}),
    Rule("MM017", "undefined-name", _E, "high-level name (macro or const) not defined", """\
`call`, `goto` and constant arguments refer to names defined in the same file
with `macro NAME { ... }` or `const NAME = value`. Names are case-sensitive.
Define the name or fix its spelling.""", {
        "macro": "no macro named '{name}'{hint}",
        "const": "no const named '{name}'{hint}",
        "const-is-macro": "no const named '{name}'; '{name}' is a macro: write `call {name}` "
                          "or `goto {name}`",
    }),
    Rule("MM018", "duplicate-name", _E, "a macro or const name is defined twice", """\
Each `macro` and `const` name may be defined once, so that every use of the
name means one thing wherever it stands: a second const would silently change
the numbers sent to the controller above or below it, and a second macro of
the same name would leave `call`/`goto` to guess which one runs. (Two blocks
for the same slot number are `duplicate-slot`.) Rename one of them, or remove
the duplicate.""", {"": "{kind} '{name}' is defined twice (first at line {first})"}),
)

RULES += (
    Rule("MM019", "goto-not-last", _E, "a goto is not the last statement of its block", """\
`goto NAME` transfers for good: it lowers to an EM that must end its
macro, because the controller keeps one return point (MS176E §3.8.4) and
nothing after a transfer for good would ever run. So a goto may only be the
last statement of its block, e.g. `when 1 { CN 1, goto run }`. Statements
after it are dead code: remove them, move them before the goto, or use
`call NAME` if the block should continue after NAME has run.""", {
        "": "goto transfers for good, so it must be the last statement of its block",
        "loop": "this goto would come back into the loop around it: goto must end its "
                "macro, so it cannot stand directly in a repeat or every block (wrap it in "
                "a when block)",
    }),
    Rule("MM030", "goto-ends-loop", _W, "a repeat or every block ends in a goto: it runs once", """\
A goto transfers for good, so a loop whose block ends in one leaves
on its first pass: `repeat 3 { CN 1, TT, goto x }` means `CN 1, TT, goto x`,
and mercmac lowers it so (`CN1,TT,EMx`). Code after such a loop never runs.
Drop the loop, or put the goto in a `when` block so that it only leaves the
loop when an input says so.""", {"": "this goto ends the {kind} block (line {line}) on its first pass: the "
              "block runs once. Drop the loop, or put the goto in a when block"}),
    Rule("MM031", "ti-moved", _W, "a TI runs in another macro than the RP of its loop", """\
TI reports the remaining count of the RP in the running macro, and each macro
has its own RP counters that reset when it is entered (MS176E §6.4 RP, TI).
A TI in a `when` block inside a loop runs in the macro the block is
hoisted into, so it reports that macro's counter (0) instead of the loop's:
`repeat 3 { when 1 { TI } }` reports 0, 0, 0 where the loop means 0, 2, 1.
Move the TI out of the when block, straight into the loop.""", {"": "this TI runs in {owner}, a macro of its own, not in {loop} with the RP "
              "of its loop: it reports that macro's counter (0), not the loop's remaining "
              "count (each macro has its own RP counters)"}),
    Rule("MM032", "repeat-zero", _I, "repeat 0: the block never runs", """\
`repeat 0 { ... }` runs its block no times, so mercmac leaves it out (RP
cannot express it: a line always runs at least once, MS176E §6.4 RP). Remove
the block, or give a count of 1 or more.""", {"": "repeat 0 never runs its block: it is left out"}),
    Rule("MM033", "every-zero", _W, "every 0ms: a polling loop without a wait", """`every 0ms { ... }` waits nothing between passes, so it is a busy loop: it runs
at the full command rate, one command per controller cycle, keeps the
controller busy and floods the host with any reports the block makes. The
simulator reports it as a busy-loop hazard. Give the loop a period of a few ms
(`every 20ms`), which adds a WA to each pass.""", {
        "": "every 0ms waits nothing between passes: a busy loop at the full command rate; "
            "poll every few ms instead (every 20ms)"}),
    Rule("MM034", "invalid-suppression", _W, "a `// mercmac: ignore[...]` comment that cannot be read", """\
`// mercmac: ignore[RULE, ...]` turns the named rules off on its own line, and
`// mercmac: ignore` every rule (codes and names in any case). A comment whose
bracket is never closed, that names a rule mercmac does not have, or that names
none, turns nothing off - rather than guess, which could hide an error - and
`check` says so here, as ruff reports a `# noqa` with an unknown code (RUF102).
Close the bracket, fix the spelling (`mercmac explain` lists the rules), or
remove the comment. Only `check` reads these comments.
`// mercmac: expect[soft-limit-clamp]` is their twin for the simulator's hazards
(MH001-MH008): the line means to cause them, so `sim` shows them there as
accepted and `--fail-on-hazard` does not count them. One that cannot be read, or
names no hazard rule, accepts nothing and is reported here too.""", {
        "unclosed": "this `mercmac: ignore[` has no closing `]`, so it turns nothing off: "
                    "write `// mercmac: ignore[RULE, ...]`",
        "unknown": "no rule {key}: this comment does not turn it off (`mercmac explain` "
                   "lists the codes and names)",
        "expect-form": "write `// mercmac: expect[RULE, ...]` with the hazard rules this line "
                       "means to cause (soft-limit-clamp, MH003, ...): as written it accepts "
                       "nothing",
        "expect-unknown": "no hazard rule {key}: `expect[...]` names the simulator's hazards "
                          "(MH001-MH008, `mercmac explain MH003`), so it accepts nothing",
        "empty": "`mercmac: ignore[]` names no rule, so it turns nothing off: name the rules, "
                 "or write `// mercmac: ignore` for every rule on the line",
    }),
    Rule("MM035", "slow-poll", _I, "a when in a loop whose pass takes over 250 ms: a short press is missed", """\
A condition is read once, when its XN or XF runs (MS176E §5.5, §6.4 XN/XF).
So a `when` inside an `every` or `repeat` loop reads its buttons once per pass
of the loop, and a press that begins and ends between two reads is never seen:
in `every 500ms { when 1 { CN 1 } }` a press must last 500 ms to be sure to be
seen. The same holds for a raw line that loops with RP and calls macros that
start with XN/XF, as the manual's Example 4 polls its buttons (§3.8.6), which
it does every 20 to 100 ms.
mercmac adds up what a pass waits with no button pressed: WA n (n ms), the
period of an `every`, the passes of a `repeat` inside, what a `call` waits,
and WS n - n ms after a move of unknown length, so the message then says "at
least". A `when` block adds nothing: it runs only while its buttons are held.
It says so above 250 ms, longer than a quick press. Shorten the pass: poll
often (`every 20ms`) and move the long work into the `when` blocks, or into a
macro that a `when` block ends with `goto`; or wait for the press with WN n
where nothing else has to run meanwhile.""", {
        "": "this when reads {inputs} once per pass of the `{kind}` at line {line}, and a "
            "pass takes {took}, so a button must be held {took} to be sure to be seen: a "
            "shorter press may fall between two reads. Poll more often (every 20ms) and put "
            "the long work in the when block",
        "raw": "{call} runs {callee}, whose {condition} reads input {input} once per pass of "
               "the RP loop of {loop}, and a pass takes {took}, so a button must be held "
               "{took} to be sure to be seen: a shorter press may fall between two reads",
    }),
    # -- rigs (docs/rigs.md): the rig file, checked by mercmac/rig/checks.py --
    Rule("MR001", "rig-file", _E, "the rig file cannot be read as a rig", """\
A rig file (`NAME.rig.toml`) is UTF-8 TOML with the keys the README's "Rigs"
section lists: `name`, `box`, `box_buttons`, `wires`, a `[joystick]` table and
one `[controllers.NAME]` table per controller with `address`, `model` and
`program`. A key mercmac does not know is refused rather than passed over, so
a misspelled `adress` cannot silently leave a controller at a default. A
controller's name is at most 64 ASCII letters, digits and '_'. A `program` is a
`.mcm` file in the rig file's folder or below it (a link that leads out of it
is refused too): any other path is refused without opening the file, so a rig
from elsewhere cannot make `check` show another file's lines. Fix the text at
the position given.""", {
        "toml": "{error}",
        "unknown": "unknown key '{key}' {where}: {hint}the keys are {keys}",
        "missing": "{where} needs '{key}'",
        "type": "'{key}' {where} must be {expects}",
        "empty": "the rig names no controller: add a [controllers.NAME] table per controller",
        "name": "'{name}' is no controller name: write a letter or '_' then letters, digits "
                "or '_' (x, stage_1), at most {longest} characters",
        "program": "the program of {controller} must be a .mcm file in the rig file's folder "
                   "or below it: {why}",
        "rig-name": "'{name}' is no rig name: write a letter or '_' then letters, digits or "
                    "'_' (raster, stage_1), at most {longest} characters; the name is used in file "
                    "names, never as a path",
        "unknown-controller": "{where} names '{name}', which is no controller of the "
                              "rig{hint}",
        "branch": "the joystick has no branch '{branch}': its branches are X, Y and Z "
                  "(MS176E §3.6)",
        "button": "the C-170.PB box has no button {button}: its buttons are 1-4 on inputs 1-4",
        "button-twice": "button {button} is listed twice in box_buttons",
        "buttons-without-box": "box_buttons lists the buttons of the C-170.PB box, and the "
                               "rig has no box: add box = \"NAME\" (the box's controller) "
                               "or remove box_buttons",
        "unread": "the rig cannot be checked: {why}",
        "internal": "internal error while checking this rig ({detail}); it was not checked - "
                    "please report this with the file",
    }),
    Rule("MR002", "rig-program", _E, "a controller's program cannot be read", """\
Each controller's `program` is a `.mcm` path relative to the rig file. The
rig is checked, simulated and flashed as a whole, so a program that is missing
or unreadable stops all of it; the message says why the file could not be
read. Like any file that cannot be read, it makes every command exit 2 (I/O),
`check` too.""", {"": "the program of {controller} cannot be read: {why}"}),
    Rule("MR003", "rig-wire", _E, "a wire that is not OUTPUT -> INPUT", """\
A wire joins an output line of one controller to an input line of another:
`"x.out1 -> y.in1"` (or `→`). A Mercury has 4 digital outputs and 4 inputs
(MS176E §4.5.1); output 4 is also the trigger output (§4.5.2). A wire starts at
an output (`out1`-`out4`) and ends at an input (`in1`-`in4`) of a different
controller: inputs 5 and 6 are the joystick and its button (§6.4 XN), which
no wire reaches.""", {
        "syntax": "a wire is written \"NAME.outN -> NAME.inN\" (e.g. \"x.out1 -> y.in1\"), "
                  "found {text}",
        "line": "{line}: {kind} lines are numbered 1-4 (MS176E §4.5.1)",
        "direction": "a wire runs from an output to an input: {wire}",
        "loop": "{wire} joins a controller to itself: a program knows its own outputs",
    }),
    Rule("MR004", "address-range", _E, "a controller address outside 0-15", """\
The address of a controller is set with DIP switches 1 to 4 (MS176E §3.1.3,
§3.2): 16 combinations, addresses 0-15, selected on the link by the code
\\x01 and one hex digit. Any other number can never be selected. Set the
address the switches give.""", {"": "address {address} is out of range: the DIP switches "
                                    "give 0-15 (MS176E §3.2)"}),
    Rule("MR005", "address-repeated", _E, "two controllers of a rig share an address", """\
Every controller of a daisy chain compares the address selection code with its
own DIP-switch address and answers when they match (MS176E §3.2). Two
controllers with one address both answer at once and garble each other's
replies, and a flash would write both with one program. Give each its own
address.""", {"": "{controller} has address {address}, as {other} has: each controller of a "
                  "chain needs its own (MS176E §3.2)"}),
    Rule("MR006", "model-mismatch", _E, "a program's target differs from its controller's model", """\
A program states the model it was written for (`target C-663`), and the rig
says which model each controller is. They must agree: the C-663 drives
steppers and the C-863 DC servos, with different commands, ranges and
power-on defaults (MS176E §3.4, §6.2). The program is checked with the rig's
model; fix whichever of the two is wrong.""", {
        "": "{controller} is a {model} in the rig, but its program targets {target}"}),
    Rule("MR007", "select-networked", _E, "SC in an autostart macro of a rig of several controllers", """\
SCn in the autostart macro (macro 0) selects the controller at power-on
without an address selection code (MS176E §3.1.2), for a single controller
whose host cannot send the \\x01 byte. The manual says "This method can not be
used with networked controllers": on a chain every controller selecting
itself at once answers together with the others. Remove SC from macro 0 and
let the host send address selection codes.""", {
        "": "SC in macro 0 of {controller}: \"can not be used with networked controllers\" "
            "(MS176E §3.1.2), and this rig has {count}"}),
    Rule("MR008", "input-driven-twice", _E, "an input line driven by two sources", """\
An input line reads one TTL level. Two outputs wired to it, or a wire and a
button of the C-170.PB box (which applies its own TTL signals to the input
lines, MS176E §4.5.1), fight over it: the level the program reads depends on
which drives harder, and a pressed button may short an output. Drive each
input from one place; leave the button out of `box_buttons` if the box's
button is not connected.""", {
        "wire": "{line} is driven by {first} and by {second}",
        "button": "{line} is driven by {wire} and by button {button} of the C-170.PB box",
    }),
    Rule("MR009", "output-never-set", _W, "a wire from an output its program never sets", """\
A wire carries an output line's level to another controller (MS176E §4.5.1:
"interaxis communication" in stand-alone mode). The program of the
controller the wire starts at never sets that output (no CN, CF, CP or trigger
mode ZM for output 4, §4.5.2), so the wire always carries OFF and whatever
waits on it at the other end waits for good. Set the output in the program, or
wire the output that the program does set.""", {
        "": "{wire}: the program of {controller} never sets output {number} (no CN/CF/CP)"}),
    Rule("MR010", "input-undriven", Severity.INFO, "a program reads an input nothing drives", """\
The program waits on or tests an input line (WN, WF, XN or XF, MS176E §4.5.1)
that no wire of the rig and no button of the C-170.PB box drives, so on the
rig it reads a constant level. That is right when something outside the rig
(a sensor, a switch) is connected there; otherwise add the wire, or name the
box on this controller.""", {
        "": "{controller} reads input {number} ({command}), which no wire or box button "
            "of the rig drives"}),
    Rule("MR011", "wait-cycle", _W, "controllers that wait on each other, or on a line nothing drives, for good", """\
Controller A waits (WN) for an input wired from an output of B, while B
only raises that output after it has itself waited for an input wired from
A, which A raises only after its own wait: each waits for the other and
neither moves - a dead-lock the simulator shows as well (MS176E §4.5.1
interaxis I/O). Over three or more controllers the waits may go round the
same way.
The check is a static approximation: it reads each program in run order
from the autostart macro (each macro where it is first called or jumped to)
and takes a wait as "before" a raise (CN, a CP pattern with the line's bit,
ZM for output 4) when it comes first on that path. WF is not counted: the
lines start OFF, so a WF on a line no one has raised passes at once. It does
not follow which way an XN/XF goes, nor a second pass of a loop, so a cycle
that a button or a branch breaks is still reported, and a dead-lock that
needs a loop to turn round, or a WF on a line left high, is not. Let one
side raise its output first (in the autostart macro), or run `mercmac sim`
on the rig to see the run.
It also reports, at the wait, a dead-lock on an input that no wire and no
box button drives, which stays OFF on the rig: only a sure one.
Each controller is followed from its autostart macro through the commands
that surely run (no XN/XF condition, no loop without a wait); when each one
ends or reaches a WN that never ends, on such an input or on a wire from an
output its controller has not raised by then, and one of them waits on an
input nothing drives, no controller will go on (`sim` reports it as MH008).
A wait on an input a box button drives is never counted: a person may press
it. Wire the input, name the box on that controller, or wait on a line that
is driven.""", {
        "": "{first} waits for {first_line} before raising {first_out}, and {second} waits "
            "for {second_line} before raising {second_out}: each waits for the other",
        "undriven": "dead-lock: {controller} waits for {line} ({command}) in {macro}, which "
                    "no wire or box button drives{others}; no controller goes on"}),
    Rule("MR012", "joystick-branch", _E, "a joystick wired in a way it cannot work", """\
A C-819.20 joystick drives two controllers through its Y-cable, and a
C-819.30 three through separate cables (MS176E §3.6.1). "If the Y-cable is
used to connect a joystick to two controllers, the X-branch must be connected
to a powered-up controller because joystick power is taken from that side":
a Y branch without an X branch leaves the joystick without power. And a
controller has one joystick socket, so two branches cannot go to one
controller. Name the X branch's controller in `[joystick]`, one branch per
controller.""", {
        "power": "the joystick's Y branch goes to {controller}, but no controller has its X "
                 "branch: the Y-cable takes the joystick's power from the X side (MS176E §3.6.1)",
        "socket": "branches {first} and {second} both go to {controller}, which has one "
                  "joystick socket (MS176E §3.6.1)",
    }),
)

_BY_KEY = {r.code: r for r in RULES} | {r.name: r for r in RULES}


def rule(key: str) -> Rule:
    """A rule by code or name, case-insensitively; KeyError if unknown."""
    return _BY_KEY.get(key) or _BY_KEY.get(key.upper()) or _BY_KEY[key.lower()]


class Applicability(Enum):
    """How sure a fix is of what the user meant (ruff's applicability; docs/checks.md, "Fixes").

    SAFE: the program surely means this (a `target` line for the model named, a keyword
    misspelled where only one keyword is that near, a name with exactly one candidate of its
    kind); `check --fix` applies it. UNSAFE: a guess, such as another command for an unknown
    one; `--unsafe-fixes` applies it. DISPLAY_ONLY: what to write, shown but never applied
    (`LED 1`: `CN 1` lights the LED, `CF 1` puts it out)."""

    SAFE = "safe"
    UNSAFE = "unsafe"
    DISPLAY_ONLY = "display-only"

    def __str__(self) -> str:
        return self.value

    def applied(self, unsafe: bool) -> bool:
        """Whether `check --fix` makes a fix of this kind (`unsafe`: --unsafe-fixes)."""
        return self is Applicability.SAFE or (unsafe and self is Applicability.UNSAFE)


SAFE, UNSAFE, DISPLAY_ONLY = Applicability


class Fix(NamedTuple):
    """An edit that resolves a finding, as data (ruff's `Fix` and `fix_title`): put
    `replacement` in place of `span` (end column exclusive; an empty span inserts), as sure
    of the user's meaning as its `applicability`. The language server offers it as a quick
    fix, labelled unless it is safe; `check --fix` applies the safe ones (with
    --unsafe-fixes the unsafe ones too); the JSON and SARIF outputs carry it."""

    span: Span
    replacement: str
    title: str
    applicability: Applicability = Applicability.SAFE

    @classmethod
    def replacing(cls, span: Span, new: str, applicability: Applicability) -> Fix:
        """The word at `span` replaced by the word `new`."""
        return cls(span, new, _replace_title(new), applicability)

    def as_json(self) -> dict:
        """`"fix"` of a diagnostic in `check --format json` (docs/cli.md, "JSON output"):
        its applicability, its title and its one edit (1-based, the end just past)."""
        span = self.span
        end = (span.end_line, span.end_column) if span.end_line else (span.line, span.column + 1)
        return {"applicability": str(self.applicability), "message": self.title,
                "edits": [{"content": self.replacement, "line": span.line,
                           "column": span.column, "end_line": end[0], "end_column": end[1]}]}


# A 1 MB line of one misspelled command has 250,000 fixes of a few words (check_large).
@functools.lru_cache(maxsize=256)
def _replace_title(new: str) -> str:
    return f"Replace with '{new}'"


class Diagnostic(NamedTuple):
    """One finding at one place, and the fix that resolves it when one is safe."""

    rule: Rule
    severity: Severity
    file: str
    span: Span
    message: str
    fix: Fix | None = None

    def sort_key(self):
        return (self.severity, self.file, self.span.line, self.span.column)

    def as_json(self) -> dict:
        return {
            "rule": self.rule.name,
            "code": self.rule.code,
            "severity": str(self.severity),
            "file": self.file,
            "line": self.span.line,
            "column": self.span.column,
            "end_line": self.end[0],
            "end_column": self.end[1],
            "message": self.message,
        } | ({} if self.fix is None else {"fix": self.fix.as_json()})

    @property
    def end(self) -> tuple[int, int]:
        """Line and column just past the span (a span without an end marks one character)."""
        span = self.span
        if span.end_line and (span.end_line, span.end_column) > (span.line, span.column):
            return span.end_line, span.end_column
        return span.line, span.column + 1


class Report:
    """Collects diagnostics for one file."""

    __slots__ = ("file", "items")

    def __init__(self, file: str, items: list[Diagnostic] | None = None):
        self.file = file
        self.items: list[Diagnostic] = [] if items is None else items

    def add(self, key: str, span: Span, variant: str = "", /, *,
            severity: Severity | None = None, fix: Fix | None = None, **values) -> None:
        """Report rule `key` at `span` in the words of its `variant` message."""
        # inlined `rule` and `Rule.text`: a 1 MB file makes 250,000 diagnostics (check_large)
        r = _BY_KEY.get(key) or rule(key)
        template = r.messages.get(variant)
        message = r.text(variant) if template is None else template.format_map(values)
        self.items.append(Diagnostic(r, r.severity if severity is None else severity,
                                     self.file, span, message, fix))

    @property
    def has_errors(self) -> bool:
        return any(d.severity is Severity.ERROR for d in self.items)

    def sorted(self) -> list[Diagnostic]:
        return sorted(self.items, key=Diagnostic.sort_key)
