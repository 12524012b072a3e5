"""Every `mercmac ...` command the README shows runs as shown and does what its text says.

The commands are read from the README's indented code blocks. Each runs in-process in a fresh
folder that holds the tour's program as `prog.mcm` (taken from the README itself), the manual's
Example 4 (three warnings, for the CI commands on `.`), and whatever else the command names
(`big.mcm`, `src/`). A port such as /dev/ttyUSB0 is replaced by the pseudo-terminal of a
virtual controller, so `flash`, `pull` and `scan` talk to something real.
"""
from __future__ import annotations

import json
import re
import shlex
from pathlib import Path

import pytest

from helpers.cli import cli
from helpers.emulator import line_clock
from helpers.paths import EXAMPLE4
from helpers.readme import (HARDWARE_PORTS, README, commands, prepare, promise, served_commands,
                            tour_program)


@pytest.fixture(scope="module")
def port():
    """A virtual C-863 on a pseudo-terminal: the README's /dev/ttyUSB0."""
    from mercmac.emulator.chain import Chain
    from mercmac.emulator.ptyserver import PtyServer
    from mercmac.emulator.virtual import VirtualController

    # the commands' default timeouts on the line's clock: an answer is awaited however
    # loaded the machine, and the silent addresses of `scan` pass in milliseconds
    with PtyServer(Chain([VirtualController("C-863", 0)])) as server, line_clock(server):
        yield server.path


def run(command: str, port: str, folder: Path, monkeypatch):
    """Run a README command in `folder`: its port replaced, a `> FILE` redirect honoured."""
    monkeypatch.chdir(folder)
    monkeypatch.setenv("MERCMAC_DATA_DIR", str(folder / "data"))  # flash's backups stay here
    words = shlex.split(command)
    redirect = None
    if ">" in words:
        at = words.index(">")
        words, redirect = words[:at], words[at + 1]
    words = [port if w in HARDWARE_PORTS else w for w in words]
    assert words[0] == "mercmac"
    result = cli(*words[1:], catch=True)
    if redirect:
        (folder / redirect).write_text(result.stdout, encoding="utf-8")
    return result


COMMANDS = commands()


@pytest.mark.parametrize("command", served_commands())
def test_a_readme_command_that_serves_prints_its_address_and_serves_the_page(command):
    """`sim ... --web` from the top of the repository, as the README says: a process that
    prints its address, serves the page there and stops on Ctrl-C (exit 130)."""
    import os
    import signal
    import subprocess
    import sys
    import urllib.request

    from helpers.paths import ROOT

    process = subprocess.Popen([sys.executable, "-m", "mercmac", *shlex.split(command)[1:],
                                "--no-open"], cwd=ROOT, stderr=subprocess.PIPE, text=True,
                               stdout=subprocess.DEVNULL, stdin=subprocess.DEVNULL,
                               env={**os.environ, "DISPLAY": ""})
    try:
        url = re.search(r"http://127\.0\.0\.1:\d+/\?token=[\w-]+", process.stderr.readline())
        assert url, command
        with urllib.request.urlopen(url.group(), timeout=60) as page:
            assert page.status == 200 and b"mercmac sim" in page.read()
        process.send_signal(signal.SIGINT)
        assert process.wait(timeout=60) == 130
    finally:
        process.kill()
        process.wait()


def test_the_readme_shows_commands_and_the_tour_program():
    assert len(COMMANDS) >= 20
    assert "macro jog" in tour_program() and "const FAR" in tour_program()


@pytest.mark.parametrize("command", COMMANDS)
def test_readme_command_does_what_the_text_says(command, port, tmp_path, monkeypatch):
    prepare(tmp_path, command)
    result = run(command, port, tmp_path, monkeypatch)
    code, phrases = promise(command.replace("/dev/ttyUSB0", "PORT"))
    assert result.exception is None or isinstance(result.exception, SystemExit), result.output
    assert result.exit_code == code, result.output
    for phrase in phrases:
        assert phrase in result.output, f"{phrase!r} not in:\n{result.output}"


def test_sarif_written_by_the_readme_command(port, tmp_path, monkeypatch):
    (command,) = [c for c in COMMANDS if "sarif" in c]
    prepare(tmp_path, command)
    run(command, port, tmp_path, monkeypatch)
    sarif = json.loads((tmp_path / "mercmac.sarif").read_text(encoding="utf-8"))
    assert sarif["version"] == "2.1.0" and sarif["runs"][0]["results"]


def test_build_to_a_file_and_pull_to_a_file(port, tmp_path, monkeypatch):
    # pull reads back what the README's flash wrote: flash here, not in an earlier test (the
    # suite's workers do not keep the order of tests, and each has its own `port`); in a
    # folder of its own, as that test did, so pull finds no flash record of its source
    (flash,) = [c for c in COMMANDS if c.startswith("mercmac flash")]
    (tmp_path / "flashed").mkdir()
    prepare(tmp_path / "flashed", flash)
    run(flash, port, tmp_path / "flashed", monkeypatch)
    for command in COMMANDS:
        if " -o " in command and (command.startswith("mercmac build")
                                  or command.startswith("mercmac pull")):
            prepare(tmp_path, command)
            assert run(command, port, tmp_path, monkeypatch).exit_code == 0
    assert (tmp_path / "prog.md").read_text(encoding="ascii").endswith("MD0,XN1,SV70000,EM1\n")
    assert "[MC00]" in (tmp_path / "saved.mcm").read_text(encoding="utf-8")


def test_the_tour_sim_presses_buttons_the_program_handles():
    """The sim example's buttons are ones the tour's program tests (`when N`)."""
    (command,) = [c for c in COMMANDS if c.startswith("mercmac sim prog.mcm")]
    script = shlex.split(command)[shlex.split(command).index("--buttons") + 1]
    pressed = {int(press.split("@")[0]) for press in script.split(",")}
    handled = {int(n) for n in re.findall(r"when (\d)", tour_program())}
    assert pressed <= handled


def test_the_readme_points_to_no_document_outside_the_repository():
    assert "SPEC" not in README


# -- the uploader's messages that the README describes ------------------------------------

def test_flash_shows_warnings_and_flashes(port, tmp_path, monkeypatch):
    """Example 4's three nested-call warnings are shown on stderr; the flash still verifies."""
    monkeypatch.setenv("MERCMAC_DATA_DIR", str(tmp_path))
    result = cli("flash", port, EXAMPLE4)
    assert result.exit_code == 0, result.output
    assert result.stderr.count("warning[MM011 nested-call]") == 3


@pytest.mark.parametrize("command", ["check", "build", "sim"])
def test_a_missing_file_is_reported_in_one_wording(command, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    result = cli(command, "nope.mcm")
    assert result.exit_code == 2
    assert "mercmac: cannot read nope.mcm: No such file or directory" in result.stderr


def test_a_unitless_until_is_milliseconds_and_says_so(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "prog.mcm").write_text(tour_program(), encoding="utf-8")
    result = cli("sim", "prog.mcm", "--until", "3")
    assert result.exit_code == 0 and result.stdout.splitlines()[0].endswith("until 3 ms")
    assert "milliseconds" in cli("sim", "--help").stdout


def test_a_too_long_repeat_counts_what_the_user_wrote():
    """`repeat 3 { 16 commands }`: the user wrote 16; the RP the loop adds makes 17."""
    from helpers.compiling import compile_text

    body = ", ".join(["TI"] * 16)
    (d,) = [d for d in compile_text(f"autostart {{\n    repeat 3 {{ {body} }}\n}}\n").report.items
            if d.rule.name == "too-many-commands"]
    assert "holds 16 commands as written" in d.message and "adds 1 RP" in d.message
    assert "goto" not in d.message and d.span.line == 2
