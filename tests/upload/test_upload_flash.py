"""Flashing over a real pseudo-terminal: what is written, in which order, and the backup."""
from __future__ import annotations

import pytest

from helpers.compiling import program_of
from mercmac import mdtext
from mercmac.compiler import compile_file, compile_source
from mercmac.source import Source
from mercmac.emulator.virtual import Faults
from mercmac.upload.flasher import FlashOptions, flash
from mercmac.upload.plan import Fate
from mercmac.upload.connect import identify
from helpers.emulator import eventually, run_flash, serve
from helpers.paths import EXAMPLE4, ROOT


def stored_equals(vc, program) -> bool:
    return {s: mdtext.canonical(t) for s, t in vc.macros.items()} == \
        {s: mdtext.canonical(m.line) for s, m in program.macros.items()}


def test_example_4_to_an_empty_controller_then_again_unchanged(tmp_path):
    program = compile_file(str(EXAMPLE4)).program
    with serve() as (server, vc):
        result, _ = run_flash(server, program, tmp_path)
        assert stored_equals(vc, program)
        assert [line.split(",")[0] for line in vc.lines if line.startswith("MD")][-1] == "MD0"
        assert all(f is Fate.WRITTEN for f in result.plan.fates.values())
        md_before = vc.md_count
        again, _ = run_flash(server, program, tmp_path)
        assert vc.md_count == md_before  # an unchanged re-flash writes no macro
        assert again.plan.changes_nothing
        assert set(again.plan.fates.values()) == {Fate.UNCHANGED}


def test_backup_holds_what_was_there_before_the_first_write(tmp_path):
    old = {0: "EM3", 3: "MR100,WS10", 7: "TP"}
    with serve(macros=old) as (server, vc):
        run_flash(server, program_of("[MC03] MR200\n"), tmp_path)
        text = (tmp_path / "backup.mcm").read_text()
        assert "[MC00] EM3" in text and "[MC03] MR100,WS10" in text and "[MC07] TP" in text
        assert "target C-863" in text
        restored = compile_source(Source("backup.mcm", text)).program
        assert {s: m.line for s, m in restored.macros.items()} == old


def test_changed_autostart_is_removed_first_and_written_last(tmp_path):
    with serve(macros={0: "EM3", 3: "MR100"}) as (server, vc):
        run_flash(server, program_of("[MC00] EM4\n[MC03] MR100\n[MC04] GH\n"), tmp_path)
        writes = [line for line in vc.lines if line[:2] in ("MD", "RZ", "RM")]
        assert writes == ["RZ", "MD4,GH", "MD0,EM4"]
        assert vc.macros == {0: "EM4", 3: "MR100", 4: "GH"}


def test_only_differing_macros_are_written_and_others_kept(tmp_path):
    with serve(macros={3: "MR100", 5: "TP", 9: "GH"}) as (server, vc):
        result, _ = run_flash(server, program_of("[MC03] MR100\n[MC05] TT\n"), tmp_path)
        assert [line for line in vc.lines if line.startswith("MD")] == ["MD5,TT"]
        assert result.plan.fates == {3: Fate.UNCHANGED, 5: Fate.WRITTEN, 9: Fate.KEPT}
        assert vc.macros == {3: "MR100", 5: "TT", 9: "GH"}


def test_erase_unused(tmp_path):
    with serve(macros={0: "EM9", 3: "MR100", 9: "GH"}) as (server, vc):
        run_flash(server, program_of("[MC03] MR100\n"), tmp_path, erase_unused=True)
        assert vc.macros == {3: "MR100"}


def test_dry_run_reads_but_writes_nothing_and_lists_exact_bytes(tmp_path):
    with serve(macros={0: "EM3"}) as (server, vc):
        result, _ = run_flash(server, program_of("[MC00] EM4\n[MC04] GH\n"), tmp_path, dry_run=True)
        assert vc.macros == {0: "EM3"} and vc.md_count == 0
        assert not (tmp_path / "backup.mcm").exists()
        wire = [data for data, _ in result.wire(0)]
        assert wire == [b"\x010", b"RZ\r", b"TZ\r", b"MD4,GH\r", b"TM4\r", b"MD0,EM4\r", b"TZ\r"]


@pytest.mark.parametrize("framing", ["etx-per-line", "one-etx"])
@pytest.mark.parametrize("empty", ["empty", "bare"])
def test_both_tm_framings_and_both_empty_slot_answers(tmp_path, framing, empty):
    old = {1: "TP", 2: "TT", 4: "GH"}
    program = program_of("[MC00] EM1\n[MC01] TP\n[MC02] TY\n[MC05] MR5\n")
    with serve(macros=old, faults=Faults(tm_framing=framing, empty_slot=empty)) as (server, vc):
        result, _ = run_flash(server, program, tmp_path)
        assert result.plan.before == old  # the listing was read whole, in either framing
        assert result.plan.fates == {0: Fate.WRITTEN, 1: Fate.UNCHANGED, 2: Fate.WRITTEN,
                                     4: Fate.KEPT, 5: Fate.WRITTEN}
        assert vc.macros == {0: "EM1", 1: "TP", 2: "TY", 4: "GH", 5: "MR5"}


@pytest.mark.parametrize("address", range(10, 16))
def test_addresses_a_to_f(tmp_path, address):
    with serve(address=address) as (server, vc):
        run_flash(server, program_of("[MC02] MR7\n"), tmp_path, address=address)
        assert vc.macros == {2: "MR7"}


def test_reset_starts_macro_0(tmp_path):
    with serve() as (server, vc):
        run_flash(server, program_of("[MC00] WA5000\n"), tmp_path, reset=True)
        assert eventually(server, lambda _c: vc.lines[-1] == "RT")
        assert server.call(lambda _c: vc.running)  # macro 0 runs after RT (MS176E §6.4 RT)
        assert not server.call(lambda _c: vc.selected)  # and RT deselected it (§3.1)
        again, _ = run_flash(server, program_of("[MC00] WA5000\n"), tmp_path)
        assert again.plan.changes_nothing  # the next flash selects it again and reads it back


def test_byte_goals_of_the_benchmark(capsys):
    """Bytes, not timings: an unchanged re-flash writes nothing, a full flash <= 1.15x minimum."""
    import importlib.util
    import sys

    path = ROOT / "benchmarks" / "flash_bytes.py"
    spec = importlib.util.spec_from_file_location("flash_bytes", path)
    bench = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = bench  # dataclasses look their module up there
    spec.loader.exec_module(bench)
    for framing in ("etx-per-line", "one-etx"):
        ratios = bench.main(EXAMPLE4, framing)
        assert ratios["unchanged_writes"] == 0
        assert ratios["full"] <= bench.GOAL_FULL
    assert "ratio" in capsys.readouterr().out


def test_a_socket_url_works_like_a_port(tmp_path):
    """PORT may be any pyserial URL (docs/cli.md, "Commands"): here socket:// to a TCP
    bridge of the emulator."""
    import select
    import socket
    import threading
    import time

    from mercmac.emulator.virtual import VirtualController

    vc = VirtualController(macros={2: "TP"})
    listener = socket.socket()
    listener.bind(("127.0.0.1", 0))
    listener.listen(1)

    def bridge():
        conn, _ = listener.accept()
        t0 = time.monotonic()
        with conn:
            while True:
                ready, _, _ = select.select([conn], [], [], 0.002)
                data = conn.recv(4096) if ready else b""
                if ready and not data:
                    return
                vc.receive(data, time.monotonic() - t0)
                if out := vc.take():
                    conn.sendall(out)

    threading.Thread(target=bridge, daemon=True).start()
    url = f"socket://127.0.0.1:{listener.getsockname()[1]}"
    from mercmac.upload.connect import open_controller

    from helpers.emulator import FAST_TIMING

    with open_controller(url, 0, timing=FAST_TIMING) as c:
        who = identify(c)
        flash(c, who, program_of("[MC02] TP\n[MC03] GH\n"), FlashOptions(backup=tmp_path / "b.mcm"))
    listener.close()
    assert vc.macros == {2: "TP", 3: "GH"}
