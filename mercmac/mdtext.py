"""MD text: the one module that reads and writes command lines as the controller stores them.

A stored line is base commands separated by commas (MS176E §5.3): `MR5000,WS100`.
`parse_line` reads one into `Op`s and says what is wrong with it, with the very
validation `mercmac check` applies to a native command (both call `validate`);
`format_ops` writes ops back; `canonical` is the line as the controller keeps it
(docs/uploader.md, "Reading macros back"); the wire builders (`md`, `tm`, `tz`, `rz`, `rm`, `rt`,
`ve`) give every command line the uploader sends. The compiler, the VM, the emulator and the
uploader all read and write MD text here.

Macro listings, too: `listed` reads the header of a line that names a macro by its slot
(a `[MCnn]` block, an `MDn,` definition, a line of a TM report), `RAW_HEADER` is the
pattern of a raw block's header that highlighting shares, and `slot_name` and `tm_line`
write a slot's name. fmt, the parser, the decompiler and the uploader read them here.

Blanks: "Both uppercase and lowercase characters are valid, and spaces are
allowed" (MS176E §5.2): a command is what its characters say with the blanks
dropped (`m r 5` is MR5, `EM + 9` is EM9). Where that reading is no command, the
command is read again as written, blanks separating words, to say what is wrong.
"""
from __future__ import annotations

import functools
import re
from enum import Enum
from typing import Iterable, NamedTuple

from mercmac.commands import Arg, Command, Mnemonic, lookup, nearest
from mercmac.ops import Op, Role

MAX_COMMANDS = 16  # MS176E §3.8: "Each macro can contain up to 16 base commands"
# Longer numbers are outside every range of MS176E §6.4, and int() refuses more than
# 4,300 digits: such an argument is `argument-range` without its value.
MAX_DIGITS = 18
BLANKS = " \t\f\v\r\n"

_BLANK = re.compile(r"[ \t\f\v\r\n]+")
_COMPACT = re.compile(r"([A-Za-z]+\??)([+-]?[0-9]+)?")  # one command, blanks dropped
# One command as written (grammar.lark's MNEMONIC, then an INT, a NAME or a SIGNED_NAME)
_WRITTEN = re.compile(r"[ \t\f\v]*([A-Za-z]+\??)[ \t\f\v]*(?:([+-][ \t\f\v]*[0-9]+|[0-9]+)"
                      r"|((?:[+-][ \t\f\v]*)?[A-Za-z_][A-Za-z0-9_.]*))?[ \t\f\v]*")
_NUMBER = re.compile(r"[+-]?[0-9]+")


class TooLong(NamedTuple):
    """An argument of more than MAX_DIGITS digits: out of every range."""

    digits: int


class Written(NamedTuple):
    """One command as written in a line; positions are 0-based offsets into the line."""

    word: str  # the mnemonic as written, blanks dropped: 'em', 'TP?', 'EMxx'
    value: int | str | TooLong | None  # a number, a word that is no number, or omitted
    start: int  # the command: start..end
    end: int
    word_end: int  # the mnemonic: start..word_end
    value_start: int  # the argument: value_start..end


class Finding(NamedTuple):
    """What `validate` found: a rule of mercmac.diagnostics, where, and its message values."""

    rule: str
    where: str  # "word", "value" or "command"
    variant: str = ""
    values: tuple = ()  # ((field, value), ...)
    skip: int = 0  # characters of the word before the place meant (EMxx: the xx)


class Checked(NamedTuple):
    """A validated command: its op when it may stand, and every finding."""

    op: Op | None
    findings: tuple[Finding, ...]


class Problem(NamedTuple):
    """A finding in a line: rule, 0-based column range, message variant and values."""

    rule: str
    start: int
    end: int
    variant: str = ""
    values: tuple = ()

    @property
    def message(self) -> str:
        from mercmac.diagnostics import rule

        return rule(self.rule).text(self.variant, **dict(self.values))

    @property
    def is_error(self) -> bool:
        from mercmac.diagnostics import Severity, rule

        return rule(self.rule).severity is Severity.ERROR


class ParsedLine(NamedTuple):
    """A line read as the controller reads it: its ops and what is wrong with it."""

    ops: tuple[Op, ...]
    problems: tuple[Problem, ...]

    @property
    def errors(self) -> list[Problem]:
        """The problems that make the controller (and `mercmac check`) refuse the line."""
        return [p for p in self.problems if p.is_error]


# -- numbers ----------------------------------------------------------------------------------

def number(text: str) -> int | None:
    """'12', '+5', '- 3' as an int (blanks dropped); None when not a whole number or
    longer than MAX_DIGITS digits."""
    text = _BLANK.sub("", text)
    if not _NUMBER.fullmatch(text):
        return None
    return None if len(text.lstrip("+-").lstrip("0")) > MAX_DIGITS else int(text)


def _value(text: str) -> int | TooLong:
    """The argument of a command as written: '+ 9' -> 9; too many digits -> TooLong."""
    text = _BLANK.sub("", text)
    digits = len(text.lstrip("+-").lstrip("0"))
    return TooLong(digits) if digits > MAX_DIGITS else int(text)


# -- reading a line -----------------------------------------------------------------------------

def lex(text: str) -> tuple[list[Written], list[Problem]]:
    """The commands of a line as written, and its syntax errors (`syntax` problems).

    An empty command is one only at the end: `DI,` (MS176E §3.8.6, Example 4).
    """
    items: list[Written] = []
    problems: list[Problem] = []
    if not text.strip(BLANKS):
        return items, problems
    pieces = text.split(",")
    start = 0
    for i, piece in enumerate(pieces):
        end = start + len(piece)
        m = _COMPACT.fullmatch(piece)
        if m is not None:  # the common case: no blanks, a word and maybe a number
            word, arg = m.group(1), m.group(2)
            value = None if arg is None else _value(arg)
            items.append(Written(word, value, start, end, start + m.end(1),
                                 end if arg is None else start + m.start(2)))
        else:
            found = _piece(piece, start, last=i == len(pieces) - 1 and i > 0)
            if isinstance(found, Problem):
                problems.append(found)
            elif found is not None:
                items.append(found)
        start = end + 1
    return items, problems


def _piece(piece: str, at: int, *, last: bool) -> Written | Problem | None:
    """A command with blanks, or one that is none: read with the blanks dropped, else as written."""
    compact = _BLANK.sub("", piece)
    if not compact:  # nothing before a comma, or after the last one (`DI,`: fine)
        return None if last else Problem("syntax", at, at + max(len(piece), 1), "expected",
                                          (("found", "','"), ("expected", "a command")))
    chars = [i for i, c in enumerate(piece) if c not in BLANKS]
    m = _COMPACT.fullmatch(compact)
    if m is not None and lookup(m.group(1)) is not None:
        word, arg = m.group(1), m.group(2)
        word_end = at + chars[m.end(1) - 1] + 1
        value = None if arg is None else _value(arg)
        value_start = at + chars[m.start(2)] if arg is not None else at + chars[-1] + 1
        return Written(word, value, at + chars[0], at + chars[-1] + 1, word_end, value_start)
    return _as_written(piece, at, chars)


def _as_written(piece: str, at: int, chars: list[int]) -> Written | Problem:
    """Read a command word by word, as grammar.lark reads a high-level one, to say what is wrong."""
    m = _WRITTEN.match(piece)
    if m is None:
        return _unexpected(piece, at, chars[0], None)
    if m.end() < len(piece):
        return _unexpected(piece, at, m.end(), lookup(m.group(1)))
    number_text, name = m.group(2), m.group(3)
    value = _value(number_text) if number_text else name and _BLANK.sub("", name)  # `- FAR`
    value_group = 2 if number_text else 3 if name else 1
    value_start = m.start(value_group) if value is not None else m.end(1)
    end = m.end(value_group)
    return Written(m.group(1), value, at + m.start(1), at + end, at + m.end(1), at + value_start)


def _unexpected(piece: str, at: int, i: int, command: Command | None) -> Problem:
    """A syntax error at piece[i]: what stands there, and what would have been right."""
    char = piece[i]
    word = re.match(r"[A-Za-z_][A-Za-z0-9_]*\??", piece[i:])
    found = repr(word.group()) if word else repr(char)
    width = len(word.group()) if word else 1
    where = (at + i, at + i + width)
    if not char.isascii():
        return Problem("syntax", *where, "ascii", (("found", found),))
    if char == "." and piece[:i].rstrip(BLANKS)[-1:].isdigit():
        return Problem("syntax", *where, "decimal")
    if word and command is not None:
        return Problem("syntax", *where, "comma")  # `MR5000 WS100`: two commands, no comma
    if command is not None:
        return Problem("syntax", *where, "argument", (("expects", command.expects()),
                                                      ("found", found)))
    return Problem("syntax", *where, "expected", (("found", found), ("expected", "a command")))


def parse_line(text: str, *, model: str | None = None, stored: bool = True,
               slot: int | None = None) -> ParsedLine:
    """The ops of a command line and its problems, as `mercmac check` finds them.

    `stored`: the line goes into a macro (MD), so MD, RM, RT, ... may not stand in it and
    it holds at most 16 commands; `model`: refuse what that model lacks; `slot`: the
    macro it goes into (SC belongs in macro 0 only, MS176E §6.4 SC).
    """
    items, problems = lex(text)
    ops = []
    for item in items:
        checked = validate(item.word, item.value, model=model, stored=stored, slot=slot)
        problems += [_problem(item, f) for f in checked.findings]
        if checked.op is not None:
            ops.append(checked.op._replace(span=None))
    if stored and len(items) > MAX_COMMANDS:
        macro = "the line" if slot is None else slot_name(slot)
        problems.append(Problem("too-many-commands", 0, len(text), "", (
            ("macro", macro), ("count", len(items)), ("max", MAX_COMMANDS))))
    return ParsedLine(tuple(ops), tuple(problems))


def _problem(item: Written, f: Finding) -> Problem:
    start, end = {"word": (item.start, item.word_end), "value": (item.value_start, item.end),
                  "command": (item.start, item.end)}[f.where]
    return Problem(f.rule, start + f.skip, end, f.variant, f.values)


# -- the validation of one command: `mercmac check` and parse_line ------------------------------

def validate(word: str, value, *, model: str | None = None, stored: bool = True,
             slot: int | None = None) -> Checked:
    """Check one native command against the command table (docs/checks.md).

    `value` is None (omitted), an int, or anything else that is no usable number (a
    word, TooLong). No op when the command or its argument is wrong; one that may not
    stand where it is (not-in-macro, model-unsupported, ...) keeps its op.
    """
    return _validate(word, value, model, stored, slot)


# Files repeat a few commands many times (1 MB of them): check each once.
@functools.lru_cache(maxsize=4096)
def _validate(word: str, value, model: str | None, stored: bool, slot: int | None) -> Checked:
    spec = lookup(word)
    if spec is None:
        return Checked(None, (_unknown(word),))
    arg, findings = None, []
    if value is not None:
        if spec.arg is Arg.NONE:
            return Checked(None, (Finding("bad-argument", "value", "unexpected",
                                          (("expects", spec.expects()),)),))
        if isinstance(value, TooLong):
            return Checked(None, (Finding("argument-range", "value", "digits",
                                          (("digits", value.digits),)),))
        if not isinstance(value, int):
            return Checked(None, (Finding("bad-argument", "value", "raw-name", (
                ("expects", spec.expects()), ("name", str(value)))),))
        if not spec.in_range(value):
            return Checked(None, (Finding("argument-range", "value", "", (
                ("command", f"{spec.mnemonic}{value}"), ("expects", spec.expects()),
                ("range", spec.range_text()))),))
        arg = value
    elif spec.arg is Arg.REQUIRED:
        return Checked(None, (Finding("bad-argument", "command", "missing",
                                      (("expects", spec.expects()),)),))
    elif spec.note_default:
        findings.append(Finding("default-argument", "command", "", (
            ("mnemonic", spec.mnemonic), ("default", spec.default))))
    findings += _use(spec, model, stored, slot)
    role = Role.RAW if spec.mnemonic == Mnemonic.EM else Role.NONE
    return Checked(Op(spec.mnemonic, arg, None, role), tuple(findings))


def _use(spec: Command, model: str | None, stored: bool, slot: int | None) -> list[Finding]:
    """Where the command may stand: in a macro, on this model, in this slot."""
    findings = []
    if stored and not spec.storable:
        findings.append(Finding("not-in-macro", "command", "", (
            ("mnemonic", spec.mnemonic), ("section", spec.section))))
    if not spec.available_on(model):
        findings.append(Finding("model-unsupported", "command", "", (
            ("mnemonic", spec.mnemonic), ("target", model),
            ("models", " and ".join(sorted(spec.models))))))
    if spec.mnemonic == Mnemonic.SC and slot not in (None, 0):
        findings.append(Finding("sc-outside-autostart", "command"))
    if stored and spec.mnemonic == Mnemonic.JN:
        findings.append(Finding("joystick-in-macro", "command"))
    return findings


def _unknown(word: str) -> Finding:
    """`EMxx` is EM with a placeholder for its argument; `FOO5` is an unknown command."""
    spec = lookup(word[:2])
    # The manual writes arguments as placeholders: EMxx (Example 3), EMn, MDn,xxx (§3.8.5).
    if spec is not None and len(word) > 2 and set(word[2:].lower()) <= {"x", "n"}:
        return Finding("syntax", "word", "placeholder", (
            ("expects", spec.expects()), ("placeholder", word[2:])), skip=2)
    near = nearest(word.upper())
    guess = near[0] if near else None
    hint = f"; did you mean {_either(near)}?" if near else ""
    # `guess` is data for the fix (compiler/checks.py); `hint` says it
    return Finding("unknown-command", "word", "", (("word", word), ("hint", hint),
                                                   ("guess", guess)))


def _either(words: tuple[str, ...]) -> str:
    """'EM', 'EM or XF', 'EM, XF or XN'."""
    return words[0] if len(words) == 1 else f"{', '.join(words[:-1])} or {words[-1]}"


# -- writing ------------------------------------------------------------------------------------

def format_ops(ops: Iterable[Op]) -> str:
    """Ops as a stored line: 'MR5000,WS100' (MS176E §5.3)."""
    return ",".join(op.text for op in ops)


def canonical(text: str) -> str:
    """A line as the controller keeps it: upper case, blanks dropped (MS176E §5.2;
    docs/uploader.md, "Reading macros back")."""
    return _BLANK.sub("", text.upper())


def normal(text: str | None) -> str:
    """What a stored line means, as text: its ops formatted when it reads as commands
    (`em+09,` -> 'EM9'; MMCRun writes `EM+9`, MS176E §3.8.6), else its canonical form."""
    text = canonical(text or "")
    parsed = parse_line(text, stored=False)
    return text if parsed.errors else format_ops(parsed.ops)


# -- macro listings: `[MCnn]` blocks, `MDn,` definitions and TM reports ----------------------

def slot_name(slot: int) -> str:
    """'MC05': a macro named by its slot, as MMCRun writes it (MS176E §3.8.6, Example 4)."""
    return f"MC{slot:02d}"


def tm_line(slot: int, line: str | None = None) -> str:
    """'MC005 MR5000': a line of a TM or TZ report (MS176E §6.4 TM); a bare 'MC005' for None."""
    return f"MC{slot:03d}" if line is None else f"MC{slot:03d} {line}"


# A raw block's header in a .mcm file (MS176E §3.8.6): grammar.lark's RAW_LINE up to its `]`
# (tests/test_listings.py keeps them equal), written so that Pygments and Oniguruma read it too.
_RAW = r"\[[ \t]*(?i:MC)[ \t]*{}[ \t]*\]"
_SLOT = r"[+-]?[ \t]*\d+"
RAW_HEADER = _RAW.format(_SLOT)


class Form(Enum):
    """The three ways a macro's line is listed."""

    RAW = "[MCnn]"  # a block of a .mcm file, as MMCRun saves it (MS176E §3.8.6)
    MD = "MDn,"  # a definition (MS176E §3.8.1)
    TM = "MCnnn"  # a line of a TM or TZ report: "MC001 MR55555" (MS176E §6.4 TM)


class Listed(NamedTuple):
    """One line of a macro listing: its form, its slot and what follows the header."""

    form: Form
    slot: int | None  # None: no number (more than MAX_DIGITS digits)
    header: int  # the header's length: the commands start there
    body: str  # the rest of the line (a `[MCnn]` block's may end in a `//` comment)


_LISTED = re.compile(
    _RAW.format(f"(?P<RAW>{_SLOT})")
    + r"|MD[ \t]*(?P<MD>[+-]?[ \t]*[0-9]+)[ \t]*(?:,|$)"
    # TM writes three digits; one or two before a blank are read too (docs/uploader.md)
    + r"|MC\s*(?P<TM>[0-9]{3}|[0-9]{1,2}(?=\s|$))(?:\s+|$)", re.IGNORECASE)
_FORMS = (None, Form.RAW, Form.MD, Form.TM)  # by the group of the form's slot number


def listed(line: str) -> Listed | None:
    """LINE read as a line of a macro listing; None when it starts with no header."""
    m = _LISTED.match(line)
    if m is None:
        return None
    digits, end = m.group(m.lastindex), m.end()
    # `05`, as almost every header writes it, without number()'s blanks and signs (fmt
    # reads each header of a file three times: benchmarks/fmt_large.py)
    slot = int(digits) if digits.isdecimal() and digits.isascii() and len(digits) < 4 else \
        number(digits)
    return Listed(_FORMS[m.lastindex], slot, end, line[end:])


def split_md(line: str) -> tuple[int | None, str]:
    """'MD5,MR5000,WS100' -> (5, 'MR5000,WS100'); the slot is None when it is no number."""
    text = canonical(line)
    found = listed(text)
    if found is not None and found.form is Form.MD:
        return found.slot, found.body
    return None, text.partition(",")[2]


# -- wire commands (without their CR: mercmac.upload.protocol.command frames them) --------------

def md(slot: int, line: str | Iterable[Op]) -> str:
    """MDn,...: define macro n (MS176E §3.8.1); `line` is text or ops."""
    body = line if isinstance(line, str) else format_ops(line)
    return f"{Mnemonic.MD}{slot},{body}" if body else f"{Mnemonic.MD}{slot}"


def tm(slot: int | None = None) -> str:
    """TMn reads macro n back; a bare TM (or TM0) lists all but macro 0 (MS176E §6.4 TM)."""
    return Mnemonic.TM if slot is None else f"{Mnemonic.TM}{slot}"


def tz() -> str:
    """TZ reads macro 0 back (MS176E §6.4 TZ)."""
    return Mnemonic.TZ


def tell(slot: int) -> str:
    """The command that reads one slot back: TZ for 0 (TM0 would list all but 0), else TMn."""
    return tz() if slot == 0 else tm(slot)


def rz() -> str:
    """RZ removes macro 0 (MS176E §6.4 RZ)."""
    return Mnemonic.RZ


def rm(slot: int) -> str:
    """RMn removes macro n, 1-31; never a bare RM, which removes all but 0 (MS176E §6.4 RM)."""
    if not 1 <= slot <= 31:
        raise ValueError(f"no macro slot {slot} for RM (1-31; RZ removes macro 0)")
    return f"{Mnemonic.RM}{slot}"


def remove(slot: int) -> str:
    """The command that erases one slot: RZ for 0, else RMn."""
    return rz() if slot == 0 else rm(slot)


def rt() -> str:
    """RT resets as after power-on, so macro 0 runs (MS176E §6.4 RT)."""
    return Mnemonic.RT


def ve() -> str:
    """VE names the model and the firmware version (MS176E §6.4 VE)."""
    return Mnemonic.VE
