"""Hostile input through every command, the way a user or an attacker types it.

Each example runs the real click command in-process with mangled sources,
options and scenario files, and checks the three promises: no traceback (the
command ends with SystemExit and a known exit code), no hang (an alarm cuts an
example that takes too long), and no lost file (an output path keeps its old
text unless the command succeeded, and no temporary file is left behind).

The budget is fixed for CI; `MERCMAC_FUZZ_EXAMPLES=2000 pytest tests/cli/test_fuzz_cli.py`
searches harder.
"""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from helpers.budgets import fuzz_budget
from helpers.cli import KNOWN_EXITS, hang_guard
from helpers.files import leftovers
from helpers.paths import EXAMPLE4, EXAMPLE_FILES, JOG_BOX
from mercmac.cli import main

BUDGET = settings(
    max_examples=fuzz_budget(40),
    deadline=None,
    derandomize="MERCMAC_FUZZ_EXAMPLES" not in os.environ,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
OLD_TEXT = "old output, must survive a failed command\n"

EXAMPLE_TEXTS = [p.read_text(encoding="utf-8", errors="replace")
                 for p in EXAMPLE_FILES]

HOSTILE = st.sampled_from([
    "9" * 400, "9" * 5000, "-" + "9" * 30, "1.5", "0.0001", "nan", "inf", "1e308", "0x10",
    "\x1b]0;pwned\x07", "\x1b[2J", "\x00", "\ufeff", "ÄPFEL", "\u202e", "{", "}", ",", "@",
    "//", "/*", "[MC99]", "[MC00]", "[MC", "goto", "call", "when", "repeat", "every",
    "macro", "autostart", "const", "target", "not", "and", "or", "ms", "s", "min", "h", "d",
    "XN99", "EM", "EMxx", "RP", "RP,RP", "MD1,EM1", "SC", "JN", "WA 20ms", "\r", "\t",
])


@st.composite
def mangled_source(draw) -> str:
    """An example with random cuts, duplications and hostile tokens spliced in."""
    text = draw(st.sampled_from(EXAMPLE_TEXTS))
    for _ in range(draw(st.integers(0, 6))):
        at = draw(st.integers(0, len(text)))
        action = draw(st.sampled_from(["insert", "cut", "nest", "dup"]))
        if action == "insert":
            text = text[:at] + " " + draw(HOSTILE) + " " + text[at:]
        elif action == "cut":
            text = text[:at] + text[at + draw(st.integers(1, 40)):]
        elif action == "nest":
            depth = draw(st.sampled_from([3, 40, 300]))
            kind = draw(st.sampled_from(["when 1", "repeat 2", "every 5ms"]))
            text += "\nautostart { " + f"{kind} {{ " * depth + "TP" + " }" * depth + " }\n"
        else:
            text += text[at:at + draw(st.integers(0, 300))]
    return text


DURATION = st.one_of(
    st.sampled_from(["0", "1", "3", "10ms", "2s", "1.5min", "1h", "1500d", "-1s", "", "nan",
                     "inf", "1e9d", "9" * 400, "0.0001ms", "s", "10 s", "1d"]),
    st.text(max_size=8),
)
BUTTONS = st.one_of(
    st.sampled_from(["", "1@0-2s", "1@1s-2s,1@1.5s-3s", "2+3@5s-5.2s", "1@-1s", "7@0",
                     "1@2s-1s", "1@" + "9" * 400, "+@", "1@0-nan", "1@0," * 50]),
    st.lists(st.tuples(st.integers(-1, 7), DURATION, DURATION), max_size=4).map(
        lambda items: ",".join(f"{b}@{a}-{z}" for b, a, z in items)),
)
NUMBER = st.sampled_from(["1", "0", "-1", "0.5", "1000", "nan", "inf", "-inf", "1e308",
                          "9" * 400, "x", ""])
SCENARIO_VALUE = st.one_of(
    st.sampled_from(['"1s"', '"-1s"', "5", "true", '"x"', "[5]", '["x"]', "[1, 2]", "[]",
                     '"9' + "9" * 300 + 's"', "1.5", "{}"]),
)


def invoke(args: list[str], input: str | None = None):
    with hang_guard():
        result = CliRunner().invoke(main, args, input=input)
    assert isinstance(result.exception, (SystemExit, type(None))), (
        f"traceback for mercmac {' '.join(args)[:300]!r}: {result.exception!r}\n{result.output[-2000:]}")
    assert result.exit_code in KNOWN_EXITS, (args, result.exit_code, result.output[-2000:])
    return result


@BUDGET
@given(text=mangled_source(), target=st.sampled_from([[], ["--target", "C-663"], ["--target", "C-863"]]),
       fmt=st.sampled_from(["text", "json"]))
def test_check_and_build_never_trace_or_lose_output(text, target, fmt):
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        source = folder / "a.mcm"
        source.write_text(text, encoding="utf-8", errors="surrogateescape")
        other = folder / "b.mcm"
        other.write_text("autostart { MR 100 }\n", encoding="utf-8")
        checked = invoke(["check", str(source), str(other), "--format", fmt, *target])
        assert "b.mcm" in checked.output or fmt == "json" or checked.exit_code in (0, 1)

        out = folder / "out.md"
        out.write_text(OLD_TEXT, encoding="ascii")
        built = invoke(["build", str(source), "-o", str(out), *target])
        if built.exit_code != 0:
            assert out.read_text(encoding="ascii") == OLD_TEXT
        assert leftovers(folder) == []


@BUDGET
@given(text=st.one_of(mangled_source(), st.sampled_from(EXAMPLE_TEXTS)), until=DURATION,
       buttons=BUTTONS, cycle=NUMBER, fmt=st.sampled_from(["text", "json"]),
       trace=st.booleans(), vcd=st.booleans())
def test_sim_options_never_trace_or_hang(text, until, buttons, cycle, fmt, trace, vcd):
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        source = folder / "a.mcm"
        source.write_text(text, encoding="utf-8", errors="surrogateescape")
        args = ["sim", str(source), "--until", until, "--buttons", buttons, "--cycle", cycle,
                "--format", fmt]
        if trace:
            args.append("--trace")
        dump = folder / "run.vcd"
        if vcd:
            dump.write_text(OLD_TEXT, encoding="ascii")
            args += ["--vcd", str(dump)]
        result = invoke(args)
        if vcd and result.exit_code == 2:
            assert dump.read_text(encoding="ascii") == OLD_TEXT
        assert leftovers(folder) == []


@BUDGET
@given(until=st.one_of(SCENARIO_VALUE, st.just('"3s"')),
       steps=st.lists(st.dictionaries(
           st.sampled_from(["at", "press", "release", "expect", "step", "macro", "presss", "output"]),
           SCENARIO_VALUE, max_size=4), max_size=4),
       raw=st.one_of(st.none(), st.binary(max_size=64)))
def test_scenarios_never_trace(until, steps, raw):
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        scenario = folder / "s.toml"
        if raw is not None:
            scenario.write_bytes(b"\xff\xfe" + raw)
        else:
            body = [f"until = {until}"]
            for step in steps:
                body.append("[[step]]")
                body += [f"{key} = {value}" for key, value in step.items()]
            scenario.write_text("\n".join(body) + "\n", encoding="utf-8")
        example = EXAMPLE4
        invoke(["sim", str(example), "--scenario", str(scenario)])


@pytest.mark.parametrize("args", [
    ["explain", "\x1b[2J"], ["explain", "9" * 5000], ["explain", ""],
    ["check", "/nonexistent/x.mcm"], ["check", "/dev/null"], ["build", "/"],
    ["sim", "/nonexistent.mcm"],
])
def test_odd_arguments_never_trace(args):
    invoke(args)


@BUDGET
@given(command=st.sampled_from(["flash", "pull", "scan"]), timeout=NUMBER, baud=NUMBER,
       address=NUMBER, port=st.sampled_from(["/nonexistent/ttyUSB9", "socket://127.0.0.1:1",
                                             "COM3", "", "\x1b[2J", "examples/macros/jog-box.mcm"]),
       backup=st.sampled_from([None, "/dev/null", "/", "/nonexistent/dir/b.mcm"]))
def test_uploader_options_never_trace(command, timeout, baud, address, port, backup):
    args = [command, port]
    if command == "flash":
        args.append(str(JOG_BOX))
    args += ["--timeout", timeout, "--baud", baud]
    if command != "scan":
        args += ["--address", address]
    if backup and command == "flash":
        args += ["--backup", backup]
    elif backup and command == "pull":
        args += ["-o", backup]
    invoke(args)
    assert Path("/dev/null").is_char_device()
