"""The one command table: every native command of manual MS176E §6.

Everything that needs to know a mnemonic (parser checks, lowering, the VM
assembler, the uploader, `mercmac explain`) reads this module; nothing else
lists mnemonics.  Page numbers are those of the manual's §6.2 table.
"""
from __future__ import annotations

import functools
import re
from enum import Enum
from typing import Iterable, Mapping, NamedTuple

from mercmac.suggest import candidates, distance

C663 = "C-663"
C863 = "C-863"
MODELS = (C663, C863)
BOTH = frozenset(MODELS)
ONLY_663 = frozenset({C663})
ONLY_863 = frozenset({C863})


def unit(model: str | None) -> str:
    """What distances count in on `model` (MS176E §1.2, §3.4.2): the C-663 steps (microsteps,
    1/16 of a full step), the C-863 encoder counts; counts when the model is unknown. Every
    place that shows a distance says this one word: describe, the timeline, the plot."""
    return "steps" if model == C663 else "counts"

# MS176E §6.4 MA: -1,073,741,824 < n < 1,073,741,823; MR: the resulting target
# must lie within +/-1,073,741,823.
MAX_POSITION = 1_073_741_823
# MS176E §6.1.2: "MR ... a maximum of 9 digits".
MAX_DISTANCE = 999_999_999
# MS176E §6.4 JC/JH/JL: soft limits are 32-bit counts.
MAX_INT32 = 2_147_483_647
MAX_UINT16 = 65_535


class Kind(str, Enum):
    """What a command does, as far as checks and the VM care."""

    MOTION = "motion"
    WAIT = "wait"
    CONDITION = "condition"
    CALL = "call"
    REPEAT = "repeat"
    OUTPUT = "output"
    SETTING = "setting"
    REPORT = "report"
    MACRO = "macro management"


class Arg(str, Enum):
    """Whether a command takes an argument."""

    NONE = "none"
    REQUIRED = "required"
    OPTIONAL = "optional"


class Reading(NamedTuple):
    """Where the manual says two things of a command, or nothing, what mercmac takes:
    `mercmac explain MNEMONIC` and the editor's hover show it beside the command."""

    manual: str  # what the manual says, with its sections
    mercmac: str  # the reading mercmac takes, where it acts on it, and why


class Command(NamedTuple):
    """One native command as the manual defines it."""

    mnemonic: str
    summary: str
    kind: Kind
    page: int
    arg: Arg = Arg.NONE
    arg_name: str = ""
    lo: int | None = None
    hi: int | None = None
    default: int | None = None  # what the controller substitutes when omitted
    note_default: bool = False  # omitted argument deserves an info (docs/checks.md)
    models: frozenset = BOTH
    report: str | None = None  # report identifier, e.g. "P:"
    storable: bool = True  # may stand in a macro (MS176E §3.8, §6.4 RT)
    power_on: tuple[tuple[str, int], ...] = ()  # (model, value) after power-on or RT
    reads: str | None = None  # the setting a report command reports (§6.2)
    unsigned: bool = False  # the report shows its value without a sign (§6.4 examples)
    readings: tuple[Reading, ...] = ()  # where mercmac chose between readings of the manual

    @property
    def section(self) -> str:
        return f"MS176E §6.4, p. {self.page}"

    def range_text(self) -> str:
        if self.lo is not None and self.hi is not None:
            return f"{self.lo}..{self.hi}"
        if self.lo is not None:
            return f">= {self.lo:,}"
        if self.hi is not None:
            return f"<= {self.hi:,}"
        return "any integer"

    def in_range(self, value: int) -> bool:
        return (self.lo is None or value >= self.lo) and (self.hi is None or value <= self.hi)

    def expects(self) -> str:
        """What the argument should be, as a phrase: 'EM takes a macro number 1-31'."""
        return f"{self.mnemonic} takes {self.argument()}"

    def argument(self) -> str:
        """The argument as a noun phrase: 'a macro number 1-31', 'no argument'."""
        if self.arg is Arg.NONE:
            return "no argument"
        what = self.arg_name or "a number"
        if self.lo is not None and self.hi is not None and 0 < self.hi - self.lo <= 65_535:
            what = f"{what} {self.lo}-{self.hi}"
        return what + (" (optional)" if self.arg is Arg.OPTIONAL else "")

    def available_on(self, model: str | None) -> bool:
        return model is None or model in self.models


def _c(mnemonic, summary, kind, page, **kw) -> Command:
    return Command(mnemonic, summary, kind, page, **kw)


def _on(c863: int | None = None, c663: int | None = None) -> dict:
    """power_on=: the values a setting holds after power-on, per model."""
    return {"power_on": tuple((model, v) for model, v in ((C863, c863), (C663, c663))
                              if v is not None)}


_REQ, _OPT = Arg.REQUIRED, Arg.OPTIONAL
_M, _W, _X, _E, _R = Kind.MOTION, Kind.WAIT, Kind.CONDITION, Kind.CALL, Kind.REPEAT
_O, _S, _T, _MM = Kind.OUTPUT, Kind.SETTING, Kind.REPORT, Kind.MACRO
# power_on: MS176E §3.4.1 (C-863: DP 35, DI 0, DD 0, DL 2000, FP 35, FL 2000, FT/FN 10000 Hz,
# FQ 0.8 as 80, WT 0, WW 5; §6.4 SM default 2000) and §3.4.2 (C-663: DC 200 mA, HC 100 mA,
# HT 200 ms); the other settings start at 0.
_GAIN = dict(arg=_OPT, arg_name="a gain", lo=0, hi=MAX_UINT16, default=0, note_default=True)
_INPUT_5 = Reading(
    '§6.4 XN names input 5 "Joystick input" and does not say when it counts as ON',
    "the simulator takes it as ON while the joystick stands above mid-scale "
    "(docs/simulator.md, \"Conditions\")")
_SOFT_LIMITS = Reading(
    "§3.4.1 gives the C-863 soft limits of +100,000,000 and -100,000,000 counts after "
    "power-on; §3.4.2 gives the C-663 none",
    "the simulator powers a C-663 on without soft limits (as after JC) and a C-863 with "
    "+/-100,000,000 (docs/simulator.md, \"Motion\")")

_TABLE = (
    # -- motion (§3.5, §4.3, §4.4, §6.4) --
    _c("AB", "Abort motion: AB stops abruptly, AB1 decelerates smoothly", _M, 47,
       arg=_OPT, arg_name="1 for a smooth stop", lo=1, hi=1),
    _c("DH", "Define home: the current position becomes n", _M, 50,
       arg=_OPT, arg_name="a position", lo=-MAX_POSITION, hi=MAX_POSITION, default=0),
    _c("FE", "Find edge: reference search (0 positive, 1 negative, 2 PI stages, 3 older stages)",
       _M, 53, arg=_OPT, arg_name="a search mode", lo=0, hi=3, default=0),
    _c("GH", "Go home: move to position 0 (same as MA0)", _M, 60),
    _c("MA", "Move absolute to position n", _M, 68,
       arg=_REQ, arg_name="a target position", lo=-MAX_POSITION, hi=MAX_POSITION),
    _c("MR", "Move relative by n from the last target", _M, 69,
       arg=_REQ, arg_name="a distance", lo=-MAX_DISTANCE, hi=MAX_DISTANCE),
    _c("ST", "Stop motion smoothly and move back to where ST was received", _M, 75),
    _c("JN", "Joystick on, with maximum velocity n", _M, 65,
       arg=_REQ, arg_name="a maximum velocity", lo=1000, hi=500_000),
    _c("JF", "Joystick and trackball off", _M, 65),
    _c("JA", "Trackball mode on, n counts per signal transition", _M, 62,
       arg=_REQ, arg_name="an increment", lo=0, **_on(c863=0, c663=0)),
    _c("MN", "Motor (servo) on", _M, 69, readings=(Reading(
        "§3.5.1 sends MN before the first move, the stand-alone examples of §3.8.6 never "
        "do; neither says whether the servo is on after power-on",
        "the simulator starts with the servo on, so those examples move; `sim --servo-off` "
        "gives the other answer, and a move with the servo off is the move-servo-off hazard "
        "(docs/simulator.md, \"Motion\")"),)),
    _c("MF", "Motor (servo) off", _M, 69),
    # -- waits (§6.4) --
    _c("WA", "Wait n ms from the start of this command", _W, 84,
       arg=_REQ, arg_name="a time in ms", lo=0, hi=MAX_UINT16, readings=(Reading(
           '§6.4 WA heads its range "0 < n < 65,535", which leaves out 0 and 65,535; the '
           'headings of §6.4 are loose (DD: "0 < n < 32,767" above "Range: 0 to 65,535", '
           'SM: "0 < n < 32,767" above "0 to 2^32")',
           "0-65,535 is accepted, the whole range of a 16-bit count: argument-range "
           "fires only outside it, and the simulator lets WA0 take its one cycle. A line "
           "meant for every firmware keeps to 1-65,534"),)),
    _c("WS", "Wait until the motor is on target, then n ms (default 1000)", _W, 85,
       arg=_OPT, arg_name="a time in ms", lo=0, hi=MAX_UINT16, default=1000, note_default=True),
    _c("WN", "Wait until input n is ON (button n of the C-170.PB box pressed)", _W, 85,
       arg=_REQ, arg_name="an input", lo=1, hi=4),
    _c("WF", "Wait until input n is OFF (button n released)", _W, 85,
       arg=_REQ, arg_name="an input", lo=1, hi=4),
    # -- conditions (§5.5, §6.4 XN/XF): inputs 1-4, 5 joystick, 6 joystick button --
    _c("XN", "Execute the rest of the line only if input n is ON (1-4 the box's buttons, "
       "5 joystick, 6 joystick button)", _X, 87,
       arg=_REQ, arg_name="an input", lo=1, hi=6, readings=(_INPUT_5,)),
    _c("XF", "Execute the rest of the line only if input n is OFF (1-4 the box's buttons, "
       "5 joystick, 6 joystick button)", _X, 87,
       arg=_REQ, arg_name="an input", lo=1, hi=6, readings=(_INPUT_5,)),
    # -- macro calls and repeats (§3.8, §6.4 EM/RP) --
    _c("EM", "Execute macro n", _E, 52, arg=_REQ, arg_name="a macro number", lo=1, hi=31),
    _c("RP", "Repeat the line from its beginning n more times (default 65535)", _R, 70,
       arg=_OPT, arg_name="a repeat count", lo=0, hi=32_568, default=65_535, note_default=True,
       readings=(Reading(
           '§6.4 RP: without n the line "repeats indefinitely"; but §3.8.6 (Examples 1 '
           'and 4) says `RP,RP` makes a line "repeat more than 4 billion times (in our '
           'scale, forever)", which only a bare RP that ends can do',
           "a bare RP is read as RP65535: the line runs 65,536 times, and `RP,RP` "
           "2^32 = 4,294,967,296 times, the \"more than 4 billion\". check (the "
           "default-argument info), the simulator and the emulator all count so, while "
           "RP n itself keeps to §6.4's \"n <= 32568\". On a firmware that repeats for "
           "ever, only the end of a run of hours differs"), Reading(
           "§6.4 RP says nothing of two RPs in one line; §3.8.6 only counts `RP,RP` as "
           "\"more than 4 billion\" passes",
           "each RP has its own counter: set to n on its first arrival, counted down on "
           "the later ones, forgotten when it runs out, and reset when the macro is entered "
           "(docs/simulator.md, \"Repeat counters\")"))),
    # -- outputs (§4.5) --
    # The C-170.PB box shows the outputs on its LEDs (§3.8.6).
    _c("CN", "Output n ON (lights LED n of the C-170.PB pushbutton box)", _O, 48,
       arg=_REQ, arg_name="an output", lo=1, hi=4),
    _c("CF", "Output n OFF (switches LED n of the C-170.PB pushbutton box off)", _O, 48,
       arg=_REQ, arg_name="an output", lo=1, hi=4),
    _c("CP", "Set outputs 1-4 (the box's LEDs) to the bit pattern n (bit 0 = output 1)", _O, 49,
       arg=_REQ, arg_name="an output pattern", lo=0, hi=15),
    _c("ZM", "Trigger mode on output 4 (0 off, 1 single, 2 multiple, 3 grid)", _O, 89,
       arg=_REQ, arg_name="a trigger mode", lo=0, hi=3, readings=(Reading(
           "§4.5.2 and §6.4 ZM give no width for a trigger pulse",
           "the simulator makes each pulse 100 us long, which keeps pulses apart up to "
           "10,000 a second"),)),
    _c("ZP", "Trigger position", _O, 89, arg=_REQ, arg_name="a position",
       lo=-MAX_INT32, hi=MAX_INT32),
    _c("ZI", "Trigger increment", _O, 88, arg=_REQ, arg_name="an increment",
       lo=-MAX_INT32, hi=MAX_INT32),
    # -- settings (§3.4, §4.1, §4.4, §6.4) --
    _c("SV", "Set velocity (counts or steps per second)", _S, 75,
       arg=_REQ, arg_name="a velocity", lo=0, hi=MAX_INT32),
    _c("SA", "Set acceleration and deceleration (counts or steps per second squared)", _S, 71,
       arg=_REQ, arg_name="an acceleration", lo=0, hi=MAX_INT32),
    _c("BF", "Brake off (enables the amplifier of .DD/.PD stages)", _S, 48),
    _c("BN", "Brake on", _S, 48),
    _c("LF", "Limit switch evaluation off", _S, 67),
    _c("LN", "Limit switch evaluation on", _S, 67),
    _c("LH", "Limit switches active high", _S, 67),
    _c("LL", "Limit switches active low", _S, 67),
    _c("JC", "Clear soft limits", _S, 63),
    _c("JH", "Upper soft limit", _S, 64, arg=_REQ, arg_name="a position",
       lo=-MAX_INT32, hi=MAX_INT32, readings=(_SOFT_LIMITS,)),
    _c("JL", "Lower soft limit", _S, 64, arg=_REQ, arg_name="a position",
       lo=-MAX_INT32, hi=MAX_INT32, readings=(_SOFT_LIMITS,)),
    _c("JB", "Joystick bias added to the joystick reading", _S, 63,
       arg=_REQ, arg_name="a bias", lo=-255, hi=255, **_on(c863=0, c663=0)),
    _c("JT", "Load a predefined joystick table (0-3)", _S, 66,
       arg=_REQ, arg_name="a table number", lo=0, hi=3),
    _c("SI", "Joystick table index", _S, 73, arg=_REQ, arg_name="a table index", lo=0, hi=255,
       **_on(c863=0, c663=0)),
    _c("SJ", "Joystick table value at the current index", _S, 73,
       arg=_REQ, arg_name="a table value", lo=-1024, hi=1024, **_on(c863=0, c663=0),
       readings=(Reading(
           '§6.4 SJ: "Table values range from -1024 to 1024"; §3.6.2: "Range of n: 0 to '
           '1024"',
           "-1024 to 1024 is accepted, the wider range, since §6.4's own example "
           "writes SJ-1024"),)),
    _c("SC", "Select this controller (autostart macro only)", _S, 72,
       arg=_REQ, arg_name="an address", lo=0, hi=15),
    _c("DD", "Derivative gain, position control", _S, 50, models=ONLY_863, **_GAIN, **_on(c863=0),
       readings=(Reading(
           '§6.4 DD heads its range "0 < n < 32,767" and says "Range: 0 to 65,535" below',
           "0-65,535 is accepted, the text's range and that of the other gains (DI, DL, "
           "DP, FD, FI, FL, FP)"),)),
    _c("DI", "Integral gain, position control", _S, 50, models=ONLY_863, **_GAIN, **_on(c863=0)),
    _c("DL", "Integral limit, position control", _S, 51, models=ONLY_863, **_GAIN,
       **_on(c863=2000)),
    _c("DP", "Proportional gain, position control", _S, 51, models=ONLY_863, **_GAIN,
       **_on(c863=35)),
    _c("FA", "Force control target", _S, 52, models=ONLY_863,
       arg=_REQ, arg_name="a force target", lo=-1000, hi=1024, **_on(c863=0),
       readings=(Reading(
           '§6.4 FA: "Range: 0 to 1024"; §4.1.5: "-1000 < n < +1000"',
           "-1000 to 1024 is accepted, what either section allows, so that no value "
           "the manual gives is refused; 0-999 satisfies both"),)),
    _c("FD", "Derivative gain, force control", _S, 53, models=ONLY_863, **_GAIN, **_on(c863=0)),
    _c("FI", "Integral gain, force control", _S, 54, models=ONLY_863, **_GAIN, **_on(c863=0)),
    _c("FL", "Integral limit, force control", _S, 55, models=ONLY_863, **_GAIN, **_on(c863=2000)),
    _c("FP", "Proportional gain, force control", _S, 57, models=ONLY_863, **_GAIN, **_on(c863=35)),
    _c("FM", "Control mode (0 position, 1 force, 2 both)", _S, 55, models=ONLY_863,
       arg=_REQ, arg_name="a control mode", lo=0, hi=2, **_on(c863=0)),
    _c("FN", "Notch filter frequency in Hz", _S, 56, models=ONLY_863,
       arg=_REQ, arg_name="a frequency", lo=40, hi=10_000, **_on(c863=10_000)),
    _c("FO", "Offset of the additional sensor input", _S, 57, models=ONLY_863,
       arg=_REQ, arg_name="an offset", lo=-2048, hi=2048, **_on(c863=0)),
    _c("FQ", "Notch filter edge times 100", _S, 58, models=ONLY_863,
       arg=_REQ, arg_name="an edge value", lo=0, hi=MAX_UINT16, **_on(c863=80)),
    _c("FS", "Force sign (0 positive, 1 negative)", _S, 59, models=ONLY_863,
       arg=_REQ, arg_name="a sign", lo=0, hi=1, **_on(c863=0)),
    _c("FT", "Low-pass filter frequency of the additional sensor in Hz", _S, 59,
       models=ONLY_863, arg=_REQ, arg_name="a frequency", lo=40, hi=10_000, **_on(c863=10_000)),
    _c("SB", "Trackball input filter", _S, 72, models=ONLY_863,
       arg=_REQ, arg_name="a filter count", lo=0, hi=MAX_UINT16, **_on(c863=0)),
    _c("SF", "Encoder input filter", _S, 73, models=ONLY_863,
       arg=_REQ, arg_name="a filter count", lo=0, hi=255, **_on(c863=0)),
    _c("SM", "Maximum following error", _S, 74, models=ONLY_863,
       arg=_REQ, arg_name="a following error", lo=0, hi=2**32, **_on(c863=2000),
       readings=(Reading(
           '§6.4 SM heads its range "0 < n < 32,767" and says "Range of n: 0 to 2^32" below',
           "0 to 2^32 is accepted, the text's range"),)),
    _c("WT", "Settle time in ms for on-target detection", _S, 86, models=ONLY_863,
       arg=_REQ, arg_name="a time in ms", lo=0, hi=MAX_UINT16, **_on(c863=0)),
    _c("WW", "Settle window in counts", _S, 86, models=ONLY_863,
       arg=_REQ, arg_name="a window", lo=0, hi=MAX_UINT16, **_on(c863=5)),
    _c("DC", "Drive current in mA", _S, 49, models=ONLY_663,
       arg=_REQ, arg_name="a current in mA", lo=0, hi=MAX_UINT16, **_on(c663=200)),
    _c("HC", "Hold current in mA", _S, 61, models=ONLY_663,
       arg=_REQ, arg_name="a current in mA", lo=0, hi=MAX_UINT16, **_on(c663=100)),
    _c("HT", "Hold time in ms", _S, 62, models=ONLY_663,
       arg=_REQ, arg_name="a time in ms", lo=0, hi=MAX_UINT16, **_on(c663=200)),
    # -- reports (§5.6, §6.1.3); reads: §6.2 "Corresponding Report Command", G* report the
    # D* settings; unsigned: the query's §6.4 example shows no sign ("FM:1", "JN:20000",
    # "WW:5"), the others show one ("JH:+250000", "ZP:+30000") --
    _c("CS", "Report checksum (firmware version)", _T, 49, report="C:"),
    _c("GD", "Report D-term, position control", _T, 60, models=ONLY_863, report="D:", reads="DD"),
    _c("GI", "Report I-term, position control", _T, 60, models=ONLY_863, report="I:", reads="DI"),
    _c("GL", "Report I-limit, position control", _T, 61, models=ONLY_863, report="M:", reads="DL"),
    _c("GP", "Report P-term, position control", _T, 61, models=ONLY_863, report="G:", reads="DP"),
    _c("TA", "Report analog input n (0 all, 1-4 inputs, 5 joystick, 6 joystick button)",
       _T, 75, arg=_OPT, arg_name="an analog channel", lo=0, hi=6, default=0, report="An:"),
    _c("TB", "Report board address", _T, 76, report="B:"),
    _c("TC", "Report digital input n (0 = all, as a hex digit)", _T, 76,
       arg=_OPT, arg_name="an input channel", lo=0, hi=4, default=0, report="H0n:"),
    _c("TD", "Report dynamic target", _T, 77, models=ONLY_863, report="N:"),
    _c("TE", "Report position error", _T, 77, models=ONLY_863, report="E:"),
    _c("TF", "Report following error", _T, 77, models=ONLY_863, report="F:"),
    _c("TI", "Report the current repeat counter", _T, 78, report="X:"),
    _c("TL", "Report programmed acceleration", _T, 78, report="L:", readings=(Reading(
        '§6.2 lists "T:" as the report identifier of TL; the examples of §6.1.3 and §6.4 TL '
        'report "L:+0000170000"',
        'the simulator and the emulator report "L:", as the examples do ("T:" is TT\'s)'),)),
    _c("TP", "Report position", _T, 79, report="P:"),
    _c("TR", "Report the additional (force) sensor", _T, 79, models=ONLY_863, report="R:"),
    _c("TS", "Report status", _T, 80, report="S:", readings=(Reading(
        "§6.4 TS does not say when its error code clears, and no command clears it",
        "reading it (TS or %) clears it to 00 in the simulator and the emulator, as ERR? "
        "does in PI's GCS commands (manual MS163E), which these controllers also take "
        "(§1.1); a code that never cleared would make every later TS report an old mistake"),)),
    _c("TT", "Report target position", _T, 83, report="T:"),
    _c("TV", "Report current profile velocity", _T, 83, report="V:"),
    _c("TY", "Report programmed velocity", _T, 83, report="Y:"),
    _c("VE", "Report firmware version", _T, 84),
    _c("TM", "Report macro n, or all but macro 0", _T, 78,
       arg=_OPT, arg_name="a macro number", lo=0, hi=31, default=0, report="MC",
       readings=(Reading(
           "§6.4 TM does not say how a listing of several macros is framed, nor what TMn "
           "answers for an empty slot",
           "the uploader takes CR LF after each line with one ETX at the end, or an ETX "
           "after every line, and an empty report or a bare MCnnn as an empty slot; "
           "`emulate --tm-framing` and `--empty-slot` serve each (docs/uploader.md, "
           "\"Reading macros back\")"),)),
    _c("TZ", "Report macro 0", _T, 84, report="MC"),
    _c("FA?", "Report force control target", _T, 52, models=ONLY_863, report="FA:"),
    _c("FD?", "Report force D-term", _T, 53, models=ONLY_863, report="FD:"),
    _c("FI?", "Report force I-term", _T, 55, models=ONLY_863, report="FI:"),
    _c("FL?", "Report force I-limit", _T, 55, models=ONLY_863, report="FL:"),
    _c("FM?", "Report control mode", _T, 56, models=ONLY_863, report="FM:", unsigned=True),
    _c("FN?", "Report notch filter frequency", _T, 56,
       models=ONLY_863, report="FN:", unsigned=True),
    _c("FO?", "Report force sensor offset", _T, 57, models=ONLY_863, report="FO:"),
    _c("FP?", "Report force P-term", _T, 58, models=ONLY_863, report="FP:"),
    _c("FQ?", "Report notch filter edge", _T, 58, models=ONLY_863, report="FQ:", unsigned=True),
    _c("FS?", "Report force sign", _T, 59, models=ONLY_863, report="FS:", unsigned=True),
    _c("FT?", "Report low-pass filter frequency", _T, 60,
       models=ONLY_863, report="FT:", unsigned=True),
    _c("JA?", "Report trackball increment (0 = off)", _T, 63, report="JA:", unsigned=True),
    _c("JB?", "Report joystick bias", _T, 63, report="JB:"),
    _c("JH?", "Report upper soft limit", _T, 64, report="JH:"),
    _c("JL?", "Report lower soft limit", _T, 65, report="JL:"),
    _c("JN?", "Report joystick velocity (0 = off)", _T, 65, report="JN:", unsigned=True),
    _c("SB?", "Report trackball filter", _T, 72, models=ONLY_863, report="SB:"),
    _c("SF?", "Report encoder filter", _T, 73, models=ONLY_863, report="SF:"),
    _c("SI?", "Report joystick table index", _T, 73, report="I0:", unsigned=True),
    _c("SJ?", "Report joystick table value", _T, 73, report="SJ:"),
    _c("SM?", "Report maximum following error", _T, 74, models=ONLY_863, report="SM:"),
    _c("WT?", "Report settle time", _T, 86, models=ONLY_863, report="WT:", unsigned=True),
    _c("WW?", "Report settle window", _T, 87, models=ONLY_863, report="WW:", unsigned=True),
    _c("ZI?", "Report trigger increment", _T, 88, report="ZI:"),
    _c("ZM?", "Report trigger mode", _T, 89, report="ZM:", unsigned=True),
    _c("ZP?", "Report trigger position", _T, 90, report="ZP:"),
    # -- macro management: not storable in a macro (§3.8.5, §6.4 RT) --
    _c("MD", "Define macro n (the rest of the line is stored)", _MM, 68,
       arg=_REQ, arg_name="a macro number", lo=0, hi=31, storable=False),
    _c("RM", "Remove macro n, or all but macro 0", _MM, 70,
       arg=_OPT, arg_name="a macro number", lo=0, hi=31, storable=False),
    _c("RMALL", "Remove all macros and reset parameters", _MM, 70, storable=False),
    _c("RZ", "Remove macro 0", _MM, 71, storable=False),
    _c("RT", "Reset, as after power-on", _MM, 71, storable=False),
)

COMMANDS: dict[str, Command] = {c.mnemonic: c for c in _TABLE}


class Mnemonic:
    """The table's mnemonics as named constants, made from it: `Mnemonic.EM == "EM"`,
    `Mnemonic.FA_Q == "FA?"`. Code that means one command names it so; a name that is
    no command of the table is an AttributeError (tests/test_command_table.py)."""

    @staticmethod
    def name(mnemonic: str) -> str:
        """The constant's name of a mnemonic: 'FA?' -> 'FA_Q'."""
        return mnemonic.replace("?", "_Q")


for _command in _TABLE:
    setattr(Mnemonic, Mnemonic.name(_command.mnemonic), _command.mnemonic)
del _command


class SingleChar(NamedTuple):
    """A single-character command (MS176E §6.3): sent without CR."""

    char: str
    equivalent: str | None
    report: str
    summary: str
    models: frozenset = BOTH


SINGLE_CHARS: dict[str, SingleChar] = {s.char: s for s in (
    SingleChar("+", "TE", "E:", "Tell position error", ONLY_863),
    SingleChar("(", "TF", "F:", "Tell following error", ONLY_863),
    SingleChar("%", "TS", "S:", "Tell status"),
    SingleChar("#", "TC", "H00:", "Tell channel"),
    SingleChar("'", "TP", "P:", "Tell position"),
    SingleChar("!", "AB", "", "Motor stop"),
    SingleChar("\\", None, "0 or 1", "Moving status"),
    SingleChar("/", "TA2", "A2:", "Tell analog 2"),
    SingleChar("&", "TA1", "A1:", "Tell analog 1"),
    SingleChar(")", "TA4", "A4:", "Tell analog 4"),
)}


def lookup(mnemonic: str) -> Command | None:
    """The command for a mnemonic in any case, or None."""
    return COMMANDS.get(mnemonic.upper())


def search(words: Iterable[str], model: str | None = None,
           guessed: Mapping[str, Iterable[str]] | None = None) -> list[Command]:
    """The commands (of `model`) that every word describes, best first: its mnemonic, then
    a natural guess for it (`guessed`: word -> mnemonics in the order meant; `sleep` -> WA,
    `position` -> MA, TP, DH), then a word of its summary before any ',', ':' or '('
    ("Move absolute to position n"), then elsewhere in its summary, argument or kind
    ("Derivative gain, position control"), then a word the manual has for it (SYNONYMS:
    `jog` is "joystick"), then the start of such a word (`veloc`); among equals, the one
    that says the words earliest ("Set velocity" before "Report programmed velocity"),
    then the table's order (the manual's kinds)."""
    words = [w.lower() for text in words for w in text.split()]
    found = []
    for index, c in enumerate(_TABLE):
        scores = [_score(c, w, guessed or {}) for w in words]
        if c.available_on(model) and None not in scores:
            found.append((sum(rank for rank, _ in scores), sum(at for _, at in scores), index))
    return [_TABLE[index] for *_, index in sorted(found)]


# Words users come with for what the manual calls otherwise, as words of the summaries:
# a search for one finds every command described so. Words only, no mnemonics; the words
# people write in a macro, with what to write instead, are compiler/guesses.py's.
SYNONYMS: dict[str, tuple[str, ...]] = {
    "jog": ("joystick",), "accelerate": ("acceleration",), "decelerate": ("deceleration",),
    "ramp": ("acceleration",), "speed": ("velocity",), "fast": ("velocity",),
    "slow": ("velocity",), "pushbutton": ("button",), "key": ("button",),
    "homing": ("home", "reference"), "zero": ("home",), "origin": ("home",),
    "pid": ("gain",), "tune": ("gain",), "get": ("report",), "query": ("report",),
    "read": ("report",), "delete": ("remove",), "erase": ("remove",), "run": ("execute",),
    "program": ("macro",), "pulse": ("trigger",),  # MS176E §4.5.2: trigger pulses
}


def _score(c: Command, word: str, guessed: Mapping[str, Iterable[str]]) -> tuple[int, int] | None:
    """How well `word` names `c`, and where its description says it (lower is better);
    None when it does not."""
    if word == c.mnemonic.lower():
        return 0, 0
    pointed = tuple(guessed.get(word, ()))
    if c.mnemonic in pointed:
        return 1, pointed.index(c.mnemonic)
    described = _described(c)
    at = _said(described, word)
    if at is not None:
        return (2 if at < _head(c) else 3), at
    said = [at for other in SYNONYMS.get(word, ()) if (at := _said(described, other)) is not None]
    if said:
        return 4, min(said)
    at = _first(described, lambda w: w.startswith(word)) if len(word) >= 3 else None
    return None if at is None else (5, at)


def _said(described: tuple[str, ...], word: str) -> int | None:
    """Where a description says `word` (`led` finds "LEDs" too)."""
    return _first(described, lambda w: w in (word, word + "s"))


@functools.cache
def _head(c: Command) -> int:
    """How many words of the description name what the command does: its summary up to a
    ',', ':' or '(' ("Derivative gain" of "Derivative gain, position control")."""
    return len(re.findall(r"[a-z0-9]+", re.split(r"[,:(]", c.summary.lower(), maxsplit=1)[0]))


def _first(words: tuple[str, ...], test) -> int | None:
    return next((i for i, w in enumerate(words) if test(w)), None)


@functools.cache
def _described(c: Command) -> tuple[str, ...]:
    """The words of a command's summary, argument and kind, lower case, in order."""
    return tuple(re.findall(r"[a-z0-9]+", f"{c.summary} {c.arg_name} {c.kind.value}".lower()))


@functools.lru_cache(maxsize=1024)  # a 1 MB line asks for the same few words (check_large)
def nearest(word: str) -> tuple[str, ...]:
    """The known mnemonics closest to an unknown one (at most 2 edits), for 'did you mean XF
    or XN?' (`XM`): of those as close, the ones with its first letter if any (two letters
    one edit apart are many: `XM` is as near to EM, FM, RM, SM, TM and ZM)."""
    near = candidates(word, COMMANDS, limit=2)
    if not near:
        return ()
    low = word.lower()
    best = [n for n in near if distance(low, n.lower()) == distance(low, near[0].lower())]
    first = [n for n in best if n[0] == word[:1].upper()]
    return tuple(first or best)
