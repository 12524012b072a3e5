"""SIGTERM and SIGHUP while `flash` writes are answered as Ctrl-C is (docs/cli.md):
what each controller holds, where its backup is, exit 128+N; and the backup puts it back.

Each flash is a real process against the virtual controller (or chain) on a pty; the signal
goes when the emulator has taken the first MD of the controller being written."""
from __future__ import annotations

import io
import os
import re
import select
import shutil
import signal
import subprocess
import sys
import threading
import time
from contextlib import contextmanager
from pathlib import Path

import pytest

from helpers.cli import cli, on_a_terminal
from helpers.emulator import FAST, FAST_TIMING, eventually, serve
from helpers.paths import ROOT
from mercmac.emulator.chain import Chain
from mercmac.emulator.ptyserver import PtyServer
from mercmac.emulator.virtual import Faults, VirtualController
from mercmac.errors import interrupt
from mercmac.upload.errors import FlashInterrupted
from mercmac.upload.flasher import Event, EventKind
from mercmac.upload.chain import Watch, flash_chain

pytestmark = pytest.mark.skipif(not hasattr(os, "openpty") or not hasattr(signal, "SIGHUP"),
                                reason="needs pseudo-terminals and POSIX signals")

PROGRAM = "target C-863\n[MC00] EM5\n[MC05] MR5000,WS100\n[MC06] XN1,MR-10\n[MC07] TP\n"
OLD = {0: "EM1", 1: "TP"}  # what the controller held before the flash
SIGNALS = [signal.SIGTERM, signal.SIGHUP]
ALIKE = [signal.SIGINT, *SIGNALS]  # Ctrl-C's KeyboardInterrupt, and Signalled for the others
RASTER = ROOT / "examples" / "rigs" / "raster"


def flashing(*args: str) -> subprocess.Popen:
    """`mercmac flash ARGS` as a process, as a user (or a supervisor) starts it."""
    return subprocess.Popen([sys.executable, "-m", "mercmac", "flash", *args, *FAST],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def once_written(proc: subprocess.Popen, server, vc) -> None:
    """Return once VC has taken an MD line: the flash is writing it."""
    end = time.monotonic() + 20
    while server.call(lambda _c: vc.md_count) < 1 and proc.poll() is None \
            and time.monotonic() < end:
        time.sleep(0.005)
    assert proc.poll() is None, proc.communicate()


def signal_once_written(proc: subprocess.Popen, server, vc, signum: int) -> tuple[str, str]:
    """Send SIGNUM once VC has taken an MD line; the output."""
    once_written(proc, server, vc)
    proc.send_signal(signum)
    return proc.communicate(timeout=20)


def settled(server, vcs) -> bool:
    """Whether every controller has read what the stopped flash sent it: a late answer of one
    would come amid the next flash's exchange."""
    return eventually(server, lambda _c: not any(vc.waiting for vc in vcs), seconds=10)


def restores(server, backup: str, address: int, old: dict[int, str], vc) -> bool:
    """Whether flashing BACKUP with --erase-unused puts back exactly what VC held (OLD)."""
    result = cli("flash", server.path, backup, "--address", address, "--erase-unused", *FAST)
    assert result.exit_code == 0, result.output
    return server.call(lambda _c: dict(vc.macros)) == old


@pytest.mark.parametrize("signum", SIGNALS, ids=lambda s: signal.Signals(s).name)
def test_a_signal_while_a_file_is_flashed_says_what_the_controller_holds(signum, program_file,
                                                                         tmp_path):
    backup = tmp_path / "b.mcm"
    with serve(macros=dict(OLD), faults=Faults(md_delay=0.2)) as (server, vc):
        proc = flashing(server.path, str(program_file), "--backup", str(backup))
        out, err = signal_once_written(proc, server, vc, signum)
        assert proc.returncode == 128 + signum, out + err
        name = signal.Signals(signum).name
        assert f"mercmac: flash stopped: interrupted ({name})" in err
        assert "written and verified: MC00 (autostart removed)" in err
        assert "in progress, state unknown: MC05" in err and "not written: MC06, MC07" in err
        assert "macro 0: removed before the first write" in err
        assert f"backup of the controller as it was: {backup}" in err
        assert "Traceback" not in err and "Exception ignored" not in err
        assert 0 not in server.call(lambda _c: dict(vc.macros))  # no half-written autostart
        assert settled(server, [vc]) and restores(server, str(backup), 0, OLD, vc)


@pytest.mark.parametrize("second", ALIKE, ids=lambda s: signal.Signals(s).name)
def test_a_second_signal_at_once_keeps_the_report_of_the_first(second, program_file, tmp_path):
    """SIGTERM, then at once another signal (a supervisor's, a closing terminal's): the second
    may cut the tidy-up short, never the report. Two signals pending together are handled in
    the order of their numbers (Python's), so the report names the lower one, and its code
    is the exit code."""
    backup = tmp_path / "b.mcm"
    with serve(macros=dict(OLD), faults=Faults(md_delay=0.2)) as (server, vc):
        proc = flashing(server.path, str(program_file), "--backup", str(backup))
        once_written(proc, server, vc)
        proc.send_signal(signal.SIGTERM)
        proc.send_signal(second)
        out, err = proc.communicate(timeout=20)
    named = re.search(r"mercmac: flash stopped: interrupted \((Ctrl-C|SIG\w+)\)", err)
    assert named and str(backup) in err, err
    signum = signal.SIGINT if named[1] == "Ctrl-C" else signal.Signals[named[1]]
    assert signum in (signal.SIGTERM, second) and proc.returncode == 128 + signum
    assert "Traceback" not in err and "Exception ignored" not in err


@pytest.fixture
def rig(tmp_path) -> Path:
    """The raster example where a test may write beside it: two C-663, addresses 0 and 1."""
    folder = tmp_path / "raster"
    shutil.copytree(RASTER, folder)
    return folder / "raster.rig.toml"


@pytest.mark.parametrize("signum", SIGNALS, ids=lambda s: signal.Signals(s).name)
def test_a_signal_while_a_rig_is_flashed_says_what_each_controller_holds(signum, rig, data_dir):
    old = [{0: "EM1", 1: "TP"}, {0: "EM2", 2: "TP"}]
    vcs = [VirtualController("C-663", 0, macros=dict(old[0])),
           VirtualController("C-663", 1, macros=dict(old[1]), faults=Faults(md_delay=0.2))]
    with PtyServer(Chain(vcs), io.StringIO()) as server:
        proc = flashing(server.path, str(rig))
        out, err = signal_once_written(proc, server, vcs[1], signum)  # x is done, y is begun
        assert proc.returncode == 128 + signum, out + err
        assert "Traceback" not in err and "Exception ignored" not in err
        name = signal.Signals(signum).name
        assert f"rig flash stopped at y (address 1): flash stopped: interrupted ({name})" in err
        held = dict(re.findall(r"^  (\w) \(address \d\): (.*)$", err, re.M))
        assert held["x"].startswith("flashed and verified; backup of what it held: ")
        assert held["y"].startswith("partly written; backup of what it held: ")
        backups = {n: state.split("backup of what it held: ")[1] for n, state in held.items()}
        assert f"backup of the controller as it was: {backups['y']}" in err
        assert f"`mercmac flash {server.path} {backups['y']} --address 1 --erase-unused` puts " \
               "the old program back" in err  # y's backup goes back to y, not to x at 0
        assert 0 not in server.call(lambda _c: dict(vcs[1].macros))
        assert settled(server, vcs)
        for address, (n, vc) in enumerate(zip("xy", vcs)):
            assert restores(server, backups[n], address, old[address], vc), n


def test_a_terminal_that_hangs_up_while_flashing_gets_the_report_where_stderr_goes(
        program_file, tmp_path):
    """The progress bar's terminal is gone (writes fail, SIGHUP comes): the report still goes
    to standard error (here a file, as `2>flash.log`), exit 129, no half-written autostart."""
    import pty  # POSIX only, as this module is

    backup, log = tmp_path / "b.mcm", tmp_path / "flash.log"
    with serve(macros=dict(OLD), faults=Faults(md_delay=0.2)) as (server, vc), \
            open(log, "w") as err:
        master, slave = pty.openpty()
        proc = subprocess.Popen([sys.executable, "-m", "mercmac", "flash", server.path,
                                 str(program_file), "--backup", str(backup), *FAST],
                                stdin=slave, stdout=slave, stderr=err,
                                preexec_fn=on_a_terminal(slave))
        os.close(slave)
        end = time.monotonic() + 20
        while server.call(lambda _c: vc.md_count) < 1 and time.monotonic() < end:
            if select.select([master], [], [], 0.01)[0]:  # the bar is drawn: read it away
                os.read(master, 65536)
        os.close(master)  # the terminal hangs up
        assert proc.wait(timeout=20) == 128 + signal.SIGHUP, log.read_text()
        said = log.read_text()
        assert "mercmac: flash stopped: interrupted (SIGHUP)" in said, said
        assert "in progress, state unknown: MC05" in said  # it was writing when it hung up
        assert f"backup of the controller as it was: {backup}" in said and "Traceback" not in said
        assert 0 not in server.call(lambda _c: dict(vc.macros))
        assert settled(server, [vc]) and restores(server, str(backup), 0, OLD, vc)


# -- the library: a Signalled (SIGTERM, SIGHUP) wherever a KeyboardInterrupt is answered --------

class SignalledAt(Watch):
    """A rig flash's watch whose notify raises what SIGNUM raises in a command (mercmac.errors
    .interrupt) at the first event of KIND, while meeting the controllers or writing them."""

    def __init__(self, kind: EventKind, signum: int):
        self.kind, self.signum = kind, signum

    def _notify(self, event: Event) -> None:
        if event.kind is self.kind:
            raise interrupt(self.signum)

    @contextmanager
    def meeting(self, part):
        yield self._notify

    @contextmanager
    def writing(self, part):
        yield self._notify


@pytest.mark.parametrize("signum", ALIKE, ids=lambda s: signal.Signals(s).name)
def test_a_signal_while_a_rig_is_backed_up_writes_nothing_and_exits_128_plus_n(signum, rig,
                                                                               data_dir):
    vcs = [VirtualController("C-663", address) for address in (0, 1)]
    with PtyServer(Chain(vcs), io.StringIO()) as server, \
            pytest.raises(FlashInterrupted) as caught:
        flash_chain(server.path, str(rig), timing=FAST_TIMING,
                  watch=SignalledAt(EventKind.BACKUP, signum))
    assert caught.value.exit_code == 128 + signum
    assert caught.value.message.startswith("x: interrupted before the first write; nothing was "
                                           "written; backup: ")
    assert "x (address 0): untouched" in caught.value.message
    assert [vc.md_count for vc in vcs] == [0, 0]


@pytest.mark.parametrize("signum", ALIKE, ids=lambda s: signal.Signals(s).name)
def test_a_signal_while_a_rig_is_written_names_the_signal_and_exits_128_plus_n(signum, rig,
                                                                              data_dir):
    vcs = [VirtualController("C-663", address) for address in (0, 1)]
    with PtyServer(Chain(vcs), io.StringIO()) as server, \
            pytest.raises(FlashInterrupted) as caught:
        flash_chain(server.path, str(rig), timing=FAST_TIMING,
                  watch=SignalledAt(EventKind.VERIFIED, signum))
    how = "Ctrl-C" if signum == signal.SIGINT else signal.Signals(signum).name
    assert caught.value.exit_code == 128 + signum
    assert f"rig flash stopped at x (address 0): flash stopped: interrupted ({how})" \
        in caught.value.message
    assert "x (address 0): partly written; backup of what it held: " in caught.value.message


def test_a_signal_while_the_port_closes_waits_until_it_is_closed():
    """A second signal used to land inside pyserial's close, after the descriptor went back and
    before pyserial forgot it: at exit its __del__ closed it again ("Exception ignored ... Bad
    file descriptor"), or closed whatever file had taken the number since."""
    from mercmac.errors import Signalled
    from mercmac.upload.transport import Transport

    master, slave = os.openpty()
    port = Transport(os.ttyname(slave))
    whole = port._serial.close

    def close_with_a_signal_amid():
        signal.pthread_kill(threading.get_ident(), signal.SIGTERM)  # as a supervisor's lands
        whole()

    def signalled(signum, _frame):
        raise Signalled(signum)

    port._serial.close = close_with_a_signal_amid
    before = signal.signal(signal.SIGTERM, signalled)
    try:
        with pytest.raises(Signalled):
            port.close()
        assert port._serial.fd is None and not port._serial.is_open
    finally:
        del port._serial.close  # pyserial's own again: its __del__ must not signal later
        signal.signal(signal.SIGTERM, before)
        os.close(master)
        os.close(slave)
