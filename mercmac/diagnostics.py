"""Diagnostics are data: the rules of SPEC §2, each with a stable code, its message
templates and its story (pyflakes `messages.py`, ruff's rule text beside the rule).

Checks only call `Report.add(rule, span, variant, **values)` and carry on: the
wording of every situation lives here, once, as a template of its rule.
Rendering lives in `mercmac.render`.
"""
from __future__ import annotations

import functools
from enum import IntEnum
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
the number. Commands without an argument (TP, GH, ...) take none.""", {
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
        "full": "no free slot for '{name}': the program needs {count} macros and the "
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
        "moved": "SC is only allowed in macro 0, the autostart macro (this block was moved "
                 "into {macro})",
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
the callee call nothing, or restructure. mercmac does this for you where the
meaning stays the same:
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
        "loop": _NESTED + ". Inside a repeat or every loop a when block may run commands or end "
                          "in a goto, but not call macros; move those commands into the block",
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
after the stop (§6.4 WS), a bare RP repeats 65535 times (§6.4 RP), and a gain
such as `DI,` is set to 0 (Example 1). Write the value to make the intent
explicit.""", {"": "{mnemonic} without an argument: the controller uses {default}"}),
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
`goto NAME` transfers for good (SPEC §1): it lowers to an EM that must end its
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
A goto transfers for good (SPEC §1), so a loop whose block ends in one leaves
on its first pass: `repeat 3 { CN 1, TT, goto x }` means `CN 1, TT, goto x`,
and mercmac lowers it so (`CN1,TT,EMx`). Code after such a loop never runs.
Drop the loop, or put the goto in a `when` block so that it only leaves the
loop when an input says so.""", {"": "this goto ends the {kind} block (line {line}) on its first pass: the "
              "block runs once. Drop the loop, or put the goto in a when block"}),
    Rule("MM031", "ti-moved", _W, "a TI runs in another macro than the RP of its loop", """\
TI reports the remaining count of the RP in the running macro, and each macro
has its own RP counters that reset when it is entered (MS176E §6.4 RP, TI;
SPEC §3). A TI in a `when` block inside a loop runs in the macro the block is
hoisted into, so it reports that macro's counter (0) instead of the loop's:
`repeat 3 { when 1 { TI } }` reports 0, 0, 0 where the loop means 0, 2, 1.
Move the TI out of the when block, straight into the loop.""", {"": "this TI runs in '{owner}', a macro of its own, not in '{loop}' with the RP "
              "of its loop: it reports the counter of '{owner}' (0), not the loop's remaining "
              "count (each macro has its own RP counters)"}),
    Rule("MM032", "repeat-zero", _I, "repeat 0: the block never runs", """\
`repeat 0 { ... }` runs its block no times, so mercmac leaves it out (RP
cannot express it: a line always runs at least once, MS176E §6.4 RP). Remove
the block, or give a count of 1 or more.""", {"": "repeat 0 never runs its block: it is left out"}),
    Rule("MM033", "every-zero", _W, "every 0ms: a polling loop without a wait", """`every 0ms { ... }` waits nothing between passes, so it is a busy loop: it runs
at the full command rate, one command per controller cycle (SPEC §3), keeps the
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
remove the comment. Only `check` reads these comments.""", {
        "unclosed": "this `mercmac: ignore[` has no closing `]`, so it turns nothing off: "
                    "write `// mercmac: ignore[RULE, ...]`",
        "unknown": "no rule {key}: this comment does not turn it off (`mercmac explain` "
                   "lists the codes and names)",
        "empty": "`mercmac: ignore[]` names no rule, so it turns nothing off: name the rules, "
                 "or write `// mercmac: ignore` for every rule on the line",
    }),
)

_BY_KEY = {r.code: r for r in RULES} | {r.name: r for r in RULES}


def rule(key: str) -> Rule:
    """A rule by code or name, case-insensitively; KeyError if unknown."""
    return _BY_KEY.get(key) or _BY_KEY.get(key.upper()) or _BY_KEY[key.lower()]


class Fix(NamedTuple):
    """A safe edit that resolves a finding, as data (ruff's `Fix` and `fix_title`): put
    `replacement` in place of `span` (end column exclusive; an empty span inserts). The
    language server offers it as a quick fix and `check --fix` applies it; the message
    says it in words, and no one reads it back from there."""

    span: Span
    replacement: str
    title: str

    @classmethod
    def replacing(cls, span: Span, new: str) -> Fix:
        """A misspelled word at `span` replaced by the known word `new`."""
        return cls(span, new, _replace_title(new))


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
        }

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
