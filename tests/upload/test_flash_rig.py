"""`flash RIG`: every controller of a rig over one pty, against an emulated
daisy chain (mercmac.emulator.chain) — the library, the CLI in-process and as a process."""
from __future__ import annotations

import io
import re
import shutil
from contextlib import contextmanager
from pathlib import Path

import pytest

from helpers.cli import cli, mercmac_process
from helpers.emulator import FAST, FAST_TIMING, SEARCHING, emulating, eventually
from helpers.paths import ROOT
from mercmac.emulator.chain import Chain
from mercmac.emulator.ptyserver import PtyServer
from mercmac.emulator.virtual import Faults, VirtualController
from mercmac.upload import history
from mercmac.upload.errors import FlashFailed, NotChosen, Refused
from mercmac.upload.flasher import FlashOptions
from mercmac.upload.chain import State, flash_chain

RASTER = ROOT / "examples" / "rigs" / "raster"


@pytest.fixture
def rig(tmp_path) -> Path:
    """The raster example copied where a test may change it: two C-663, addresses 0 and 1."""
    folder = tmp_path / "raster"
    shutil.copytree(RASTER, folder)
    return folder / "raster.rig.toml"


@contextmanager
def chain(models=("C-663", "C-663"), faults=(None, None)):
    """A virtual daisy chain on one pty, its log in memory: yields (server, controllers, log)."""
    vcs = [VirtualController(model, address, faults=fault or Faults())
           for address, (model, fault) in enumerate(zip(models, faults))]
    log = io.StringIO()
    with PtyServer(Chain(vcs), log) as server:
        yield server, vcs, log


def written(log: io.StringIO | str) -> dict[int, list[str]]:
    """The MD/RM/RZ lines each address took, in order, from the emulator's log of host bytes."""
    text = log if isinstance(log, str) else log.getvalue()
    sent = b"".join(bytes.fromhex(m.group(1)) for m in
                    re.finditer(r"^\s*[\d.]+ -> ((?:[0-9a-f]{2} ?)+)", text, re.M))
    by_address, current = {}, None
    for part in re.split(rb"(\x01.)", sent):
        if part.startswith(b"\x01") and len(part) == 2:
            current = int(part[1:].decode(), 16)
            continue
        for line in part.split(b"\r"):
            if re.match(rb"(MD|RM|RZ)", line):
                by_address.setdefault(current, []).append(line.decode())
    return by_address


def md_counts(server, vcs) -> list[int]:
    return [server.call(lambda _c, vc=vc: vc.md_count) for vc in vcs]


def test_a_full_flash_writes_each_controller_at_its_address_macro_0_last(rig, data_dir):
    with chain() as (server, vcs, log):
        result = flash_chain(server.path, str(rig), timing=FAST_TIMING)
        held = [server.call(lambda _c, vc=vc: dict(vc.macros)) for vc in vcs]
    assert [p.state for p in result.parts] == [State.FLASHED, State.FLASHED]
    for part, macros in zip(result.parts, held):
        wanted = {s: m.line for s, m in part.compiled.program.macros.items()}
        assert set(macros) == set(wanted)
    lines = written(log)
    assert set(lines) == {0, 1}
    for address in (0, 1):
        assert lines[address][-1].startswith("MD0,"), lines[address]  # macro 0 last, each
        assert sum(line.startswith("MD0,") for line in lines[address]) == 1


def test_an_unchanged_rig_writes_nothing(rig, data_dir):
    with chain() as (server, vcs, log):
        flash_chain(server.path, str(rig), timing=FAST_TIMING)
        before = md_counts(server, vcs)
        again = flash_chain(server.path, str(rig), timing=FAST_TIMING)
        assert md_counts(server, vcs) == before
    assert again.changes_nothing
    assert [p.state for p in again.parts] == [State.UNCHANGED, State.UNCHANGED]


def test_only_flashes_the_named_controllers(rig, data_dir):
    with chain() as (server, vcs, log):
        result = flash_chain(server.path, str(rig), only=["y"], timing=FAST_TIMING)
        counts = md_counts(server, vcs)
    assert counts[0] == 0 and counts[1] > 0
    assert [p.state for p in result.parts] == [State.LEFT_OUT, State.FLASHED]
    assert set(written(log)) == {1}


def test_only_with_a_name_the_rig_lacks_is_refused(rig, data_dir):
    with chain() as (server, vcs, log), pytest.raises(NotChosen, match="z"):
        flash_chain(server.path, str(rig), only=["z"], timing=FAST_TIMING)


def test_a_wrong_model_at_the_second_address_writes_nothing_and_says_so(rig, data_dir):
    with chain(models=("C-663", "C-863")) as (server, vcs, log), \
            pytest.raises(Refused) as stopped:
        flash_chain(server.path, str(rig), timing=FAST_TIMING)
        assert md_counts(server, vcs) == [0, 0]
    text = stopped.value.message
    assert "C-863" in text and "y" in text
    assert "x (address 0): untouched" in text and "y (address 1): untouched" in text


def test_a_failure_on_the_second_controller_says_what_each_holds(rig, data_dir):
    # every MD line for y's slot 1 loses a character: it never verifies
    with chain(faults=(None, Faults(always_drop_slot=1))) as (server, vcs, log), \
            pytest.raises(FlashFailed) as stopped:
        flash_chain(server.path, str(rig), timing=FAST_TIMING)
    text = stopped.value.message
    assert "stopped at y (address 1)" in text
    assert "x (address 0): flashed and verified" in text
    assert re.search(r"y \(address 1\): partly written; backup of what it held: \S+\.mcm", text)


def test_history_records_the_rig_and_each_controller(rig, data_dir):
    with chain() as (server, vcs, log):
        flash_chain(server.path, str(rig), timing=FAST_TIMING)
    found = sorted(history.records(), key=lambda r: r.address)
    assert [(r.address, r.controller, r.rig_name) for r in found] == [(0, "x", "raster"),
                                                                       (1, "y", "raster")]
    assert all(r.rig == str(rig) for r in found)


def test_backup_names_a_folder_or_a_prefix(rig, tmp_path, data_dir):
    with chain() as (server, vcs, log):
        flash_chain(server.path, str(rig), timing=FAST_TIMING,
                  options=FlashOptions(backup=f"{tmp_path}/saved/"))
        flash_chain(server.path, str(rig), timing=FAST_TIMING,
                  options=FlashOptions(backup=tmp_path / "before.mcm"))
    assert sorted(p.name for p in (tmp_path / "saved").iterdir()) == ["raster-x.mcm",
                                                                     "raster-y.mcm"]
    assert (tmp_path / "before-x.mcm").is_file() and (tmp_path / "before-y.mcm").is_file()


# -- the command line ---------------------------------------------------------------------------

def test_cli_flash_rig_prints_one_row_per_controller(rig, data_dir):
    with chain() as (server, vcs, log):
        result = cli("flash", server.path, rig, *FAST)
    assert result.exit_code == 0, result.output
    rows = [line for line in result.output.splitlines() if re.match(r"[xy]\s+[01]\s+C-663", line)]
    assert len(rows) == 2 and all("flashed and verified" in row for row in rows)


def test_cli_dry_run_shows_the_selection_codes_only_where_the_target_changes(rig, data_dir):
    with chain() as (server, vcs, log):
        result = cli("flash", server.path, rig, "--dry-run", *FAST)
        counts = md_counts(server, vcs)
    assert result.exit_code == 0, result.output
    assert counts == [0, 0]
    sent = [line.split()[1] for line in result.output.splitlines() if line.startswith("  -> ")]
    selections = [s for s in sent if s.startswith("<01>")]
    assert selections == ["<01>0", "<01>1"]
    assert sent[0] == "<01>0"


def test_cli_only_and_options_that_do_not_go_with_a_rig(rig, data_dir):
    assert cli("flash", "/dev/null", rig, "--address", "1").exit_code == 2
    assert cli("flash", "/dev/null", rig, "--only", "x,,y").exit_code == 2
    with chain() as (server, vcs, log):
        result = cli("flash", server.path, rig, "--only", "x", *FAST)
        assert result.exit_code == 0, result.output
        assert md_counts(server, vcs)[1] == 0
    assert "not in --only" in result.output


@pytest.mark.parametrize("only", [("--only", "x", "--only", "y"), ("--only", "y,x"),
                                  ("--only", "x", "--only", "x,y")])
def test_cli_only_repeated_or_comma_separated_flashes_every_name(rig, data_dir, only):
    """`--only x --only y` used to flash y alone and call x "untouched"; as `check
    --select`, the option takes names comma-separated, repeated, or both."""
    with chain() as (server, vcs, log):
        result = cli("flash", server.path, rig, *only, *FAST)
        counts = md_counts(server, vcs)
    assert result.exit_code == 0, result.output
    assert counts[0] > 0 and counts[1] > 0 and set(written(log)) == {0, 1}
    assert "not in --only" not in result.output and "untouched" not in result.output


def test_cli_only_repeated_with_an_empty_name_is_refused(rig, data_dir):
    result = cli("flash", "/dev/null", rig, "--only", "x", "--only", "y,")
    assert result.exit_code == 2 and "empty name" in result.output


def test_cli_a_failure_exits_1_and_names_each_controller(rig, data_dir):
    with chain(models=("C-663", "C-863")) as (server, vcs, log):
        result = cli("flash", server.path, rig, *FAST)
    assert result.exit_code == 1
    assert "x (address 0): untouched" in result.output
    assert "Traceback" not in result.output


def test_flash_rig_as_a_process_then_unchanged(rig, tmp_path, data_dir):
    with chain() as (server, vcs, log):
        first = mercmac_process("flash", server.path, str(rig), *FAST, cwd=tmp_path)
        before = md_counts(server, vcs)
        again = mercmac_process("flash", server.path, str(rig), *FAST, cwd=tmp_path)
        assert md_counts(server, vcs) == before
    assert first.returncode == 0, first.stderr
    assert again.returncode == 0, again.stderr
    assert "already holds its program" in again.stdout


def test_reset_starts_every_macro_0_once_all_are_verified(rig, data_dir):
    with chain() as (server, vcs, log):
        flash_chain(server.path, str(rig), timing=FAST_TIMING, options=FlashOptions(reset=True))
        # the emulator reads the last RT in its own thread
        assert eventually(server, lambda _c: all(vc.running for vc in vcs))
        # RT deselects (MS176E §3.1): so each RT had its own selection code before it
        assert not server.call(lambda c: c.selected())
        again = flash_chain(server.path, str(rig), timing=FAST_TIMING)
        assert again.changes_nothing  # the next flash selects each again and reads it back
    assert log.getvalue().count("52 54 0d") == 2  # 'RT<CR>', once to each (MS176E §6.4 RT)


def test_a_rig_with_errors_is_refused_before_the_port_is_touched(rig, data_dir):
    text = rig.read_text().replace("address = 1 ", "address = 0 ")
    rig.write_text(text)
    with chain() as (server, vcs, log):
        result = cli("flash", server.path, rig, *FAST)
        counts = md_counts(server, vcs)
    assert result.exit_code == 1
    assert counts == [0, 0] and not re.search(r"^\s*[\d.]+ -> ", log.getvalue(), re.M)
    assert "raster.rig.toml" in result.output and "nothing was flashed" in result.output


def test_flash_then_pull_against_emulate_addresses_as_processes(rig, tmp_path, data_dir):
    log, out = tmp_path / "wire.log", tmp_path / "pulled"
    with emulating("--addresses", "0,1", "--target", "C-663", "--log", str(log)) as (_, path):
        flashed = mercmac_process("flash", path, str(rig), *FAST, cwd=tmp_path)
        pulled = mercmac_process("pull", path, "--rig", str(out), *SEARCHING, cwd=tmp_path)
    assert flashed.returncode == 0, flashed.stderr
    assert pulled.returncode == 0, pulled.stderr
    lines = written(log.read_text())
    assert [lines[a][-1][:4] for a in (0, 1)] == ["MD0,", "MD0,"]  # macro 0 last on each
    assert (out / "x.mcm").read_text() == (rig.parent / "x.mcm").read_text()
    assert (out / "raster.rig.toml").is_file()


# -- names are never paths; one rule for an unwritable backup folder ----------------------------

def _nothing_sent(log: io.StringIO) -> bool:
    return not re.search(r"^\s*[\d.]+ -> ", log.getvalue(), re.M)


@pytest.mark.parametrize("name", ["../../escaped", "/abs/escaped"])
def test_a_rig_named_like_a_path_writes_no_backup_outside_the_folder(rig, tmp_path, data_dir,
                                                                     name):
    """Item 1: `name = "../../x"` made `--backup DIR/` write DIR/../../x-x.mcm."""
    rig.write_text(rig.read_text().replace('name = "raster"', f'name = "{name}"'))
    saved = tmp_path / "deep" / "er" / "saved"
    with chain() as (server, vcs, log):
        result = cli("flash", server.path, rig, "--backup", f"{saved}/", *FAST)
        assert md_counts(server, vcs) == [0, 0] and _nothing_sent(log)
    assert result.exit_code == 1 and "is no rig name" in result.output
    assert not list(tmp_path.rglob("*escaped*")) and not saved.exists()


def test_backup_paths_never_lead_out_of_the_folder(rig, tmp_path):
    """Defence in depth: a Rig built in the library with a path for a name is refused too."""
    from dataclasses import replace

    from mercmac.outfile import OutputError
    from mercmac.rig.load import read_rig
    from mercmac.upload.rig import backup_paths

    good = read_rig(str(rig)).rig
    assert backup_paths(good, f"{tmp_path}/b/") == [tmp_path / "b" / "raster-x.mcm",
                                                   tmp_path / "b" / "raster-y.mcm"]
    assert backup_paths(good, tmp_path / "pre.mcm") == [tmp_path / "pre-x.mcm",
                                                       tmp_path / "pre-y.mcm"]
    for name in ("../../escaped", "/abs/escaped", "a/b"):
        with pytest.raises(OutputError, match="no plain file name"):
            backup_paths(replace(good, name=name), f"{tmp_path}/b/")


def _unwritable(data_dir: Path, how: str) -> None:
    """The data folder as a file, or a read-only folder (refused by its mode, even as root)."""
    if how == "file":
        data_dir.write_text("not a folder")
    else:
        data_dir.mkdir()
        data_dir.chmod(0o555)


@pytest.mark.parametrize("how", ["file", "read-only"])
def test_an_unwritable_data_folder_is_refused_before_the_port_as_backup_ro_is(rig, tmp_path,
                                                                              data_dir, how):
    """Item 15: it exited 1 once the port was open, where `--backup RO/` exits 2 before."""
    _unwritable(data_dir, how)
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    try:
        with chain() as (server, vcs, log):
            default = cli("flash", server.path, rig, *FAST)
            given = cli("flash", server.path, rig, "--backup", f"{ro}/", *FAST)
            single = cli("flash", server.path, rig.parent / "x.mcm", *FAST)
            assert md_counts(server, vcs) == [0, 0] and _nothing_sent(log)
    finally:
        ro.chmod(0o755)
        if data_dir.is_dir():
            data_dir.chmod(0o755)
    for result in (default, given, single):
        assert result.exit_code == 2, result.output
        assert "Traceback" not in result.output
    assert str(data_dir) in default.output and str(data_dir) in single.output
    assert "$MERCMAC_DATA_DIR" in default.output and "--backup" in single.output  # the hint
    assert str(ro) in given.output
    assert not list(tmp_path.rglob("*.json"))  # no history either
