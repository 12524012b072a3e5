"""`pull --rig DIR` and `decompile --port --rig DIR`: a scanned chain becomes a
rig folder, names given back by the flash history, against an emulated chain on a pty."""
from __future__ import annotations

import shutil
from contextlib import contextmanager
from pathlib import Path

import pytest

from helpers.cli import cli, mercmac_process
from helpers.emulator import FAST, FAST_TIMING, SEARCHING, line_clock
from helpers.paths import ROOT
from mercmac.compiler import compile_file
from mercmac.emulator.chain import Chain
from mercmac.emulator.ptyserver import PtyServer
from mercmac.emulator.virtual import VirtualController
from mercmac.rig.load import read_rig
from mercmac.upload.chain import flash_chain

RASTER = ROOT / "examples" / "rigs" / "raster"
# what a controller mercmac never flashed may hold: MMCRun's raw lines (MS176E §3.8.6)
RAW = ({1: "CN1,WN2,CF1,WF2", 0: "SV20000,CP0,EM1"}, {0: "SV10000,WN1,MR500,WS10,CN2"})


@contextmanager
def chain(macros=({}, {})):
    vcs = [VirtualController("C-663", a, macros=dict(m)) for a, m in enumerate(macros)]
    with PtyServer(Chain(vcs)) as server, line_clock(server):  # addresses of nobody: fast
        yield server, vcs


@pytest.fixture
def rig(tmp_path) -> Path:
    folder = tmp_path / "raster"
    shutil.copytree(RASTER, folder)
    return folder / "raster.rig.toml"


def held(server, vcs) -> list[dict[int, str]]:
    return [server.call(lambda _c, vc=vc: dict(vc.macros)) for vc in vcs]


def test_pull_rig_gives_back_the_flashed_rig_and_it_round_trips(rig, tmp_path, data_dir):
    out = tmp_path / "pulled"
    with chain() as (server, vcs):
        flash_chain(server.path, str(rig), timing=FAST_TIMING)
        result = cli("pull", server.path, "--rig", out, *FAST)
        assert result.exit_code == 0, result.output
        before = [server.call(lambda _c, vc=vc: vc.md_count) for vc in vcs]
        again = flash_chain(server.path, str(out / "raster.rig.toml"), timing=FAST_TIMING)
        assert [server.call(lambda _c, vc=vc: vc.md_count) for vc in vcs] == before
    assert again.changes_nothing
    assert sorted(p.name for p in out.iterdir()) == ["raster.rig.toml", "x.mcm", "y.mcm"]
    assert (out / "x.mcm").read_text() == (rig.parent / "x.mcm").read_text()  # names, comments
    pulled = read_rig(str(out / "raster.rig.toml")).rig
    assert [(c.name, c.address, c.model) for c in pulled.controllers] == [("x", 0, "C-663"),
                                                                          ("y", 1, "C-663")]
    assert cli("check", out / "raster.rig.toml").exit_code == 0


def _wiring(rig_file: Path) -> tuple:
    """What a rig file says of the wiring: box, buttons, wires, joystick."""
    found = read_rig(str(rig_file)).rig
    return found.box, found.box_buttons, [str(w) for w in found.wires], dict(found.joystick)


def _flashed_then_pulled(rig_file: Path, out: Path):
    """`pull --rig OUT` of a chain that `rig_file` was flashed to (the history records it)."""
    with chain() as (server, vcs):
        flash_chain(server.path, str(rig_file), timing=FAST_TIMING)
        result = cli("pull", server.path, "--rig", out, *FAST)
    assert result.exit_code == 0, result.output
    return result


def test_pull_rig_gives_back_the_wiring_of_the_rig_flashed_to_the_chain(rig, tmp_path,
                                                                       data_dir):
    """It wrote `wires = []` (and no box, no joystick) although the history records the rig
    file each controller was flashed from, and that file still matched the chain."""
    out = tmp_path / "pulled"
    result = _flashed_then_pulled(rig, out)
    assert _wiring(out / "raster.rig.toml") == _wiring(rig)
    assert _wiring(rig)[2] and _wiring(rig)[3]  # the raster has wires and a joystick
    text = (out / "raster.rig.toml").read_text()
    said = "wires, box and joystick from the rig flashed on "
    assert said in text and str(rig) in text and "Wires cannot be read" not in text
    (line,) = [line for line in result.output.splitlines() if line.startswith("rig: ")]
    assert said in line and line.endswith(f": {rig})")
    assert "check: clean" in result.output


def test_a_rig_of_wires_alone_gives_back_its_wires_and_says_just_that(tmp_path, data_dir):
    from helpers.rigs import write_rig

    flashed = write_rig(tmp_path)  # two wired controllers, no box, no joystick
    out = tmp_path / "pulled"
    result = _flashed_then_pulled(flashed, out)
    assert _wiring(out / "r.rig.toml") == _wiring(flashed)
    text = (out / "r.rig.toml").read_text()
    assert "# wires from the rig flashed on " in text and "box" not in text
    assert "; wires from the rig flashed on " in result.output


def _edited(rig: Path) -> None:
    x = rig.parent / "x.mcm"
    x.write_text(x.read_text().replace("const LINE = 20000", "const LINE = 30000"))


@pytest.mark.parametrize("change, why", [
    (_edited, "x.mcm no longer builds to what x holds"),
    (lambda rig: rig.unlink(), "it cannot be read"),
    (lambda rig: rig.write_text(rig.read_text().replace("address = 1", "address = 2")),
     "its y at address 2 did not answer"),
])
def test_a_recorded_rig_that_no_longer_matches_gives_no_wires_and_says_why(
        rig, tmp_path, data_dir, change, why):
    out = tmp_path / "pulled"
    with chain() as (server, vcs):
        flash_chain(server.path, str(rig), timing=FAST_TIMING)
        change(rig)
        result = cli("pull", server.path, "--rig", out, *FAST)
    assert result.exit_code == 0, result.output
    text = (out / "raster.rig.toml").read_text()
    assert "wires = []" in text and "Wires cannot be read from controllers" in text
    assert _wiring(out / "raster.rig.toml") == (None, (1, 2, 3, 4), [], {})
    assert f"no longer matches: {why}" in text and f"no longer matches: {why}" in result.output


def test_a_chain_mercmac_never_flashed_is_named_by_address(tmp_path, data_dir):
    out = tmp_path / "bench"
    with chain(RAW) as (server, vcs):
        result = cli("pull", server.path, "--rig", out, *FAST)
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in out.iterdir()) == ["a0.mcm", "a1.mcm", "bench.rig.toml"]
    text = (out / "bench.rig.toml").read_text()
    assert "wires = []" in text and "Wires cannot be read from controllers" in text
    assert "no longer matches" not in text  # no rig was ever flashed there
    for address, macros in enumerate(RAW):
        program = compile_file(str(out / f"a{address}.mcm")).program
        assert {s: m.line for s, m in program.macros.items()} == macros


def test_decompile_rig_writes_sources_that_build_to_what_each_holds(tmp_path, data_dir):
    out = tmp_path / "sources"
    with chain(RAW) as (server, vcs):
        result = cli("decompile", "--port", server.path, "--rig", out, *FAST)
    assert result.exit_code == 0, result.output
    rig = read_rig(str(out / "sources.rig.toml")).rig
    for c, macros in zip(rig.controllers, RAW):
        text = Path(c.program).read_text()
        assert "[MC" not in text  # decompiled, not the raw blocks
        program = compile_file(c.program, c.model).program
        assert {s: m.line for s, m in program.macros.items()} == macros


def test_decompile_rig_says_which_controllers_got_their_recorded_source_and_why(
        rig, tmp_path, data_dir):
    """It was documented to write decompiled sources, and wrote the recorded ones without a
    word of why: x holds a build the history records, the other controller does not."""
    out = tmp_path / "sources"
    with chain(({}, RAW[1])) as (server, vcs):
        flash_chain(server.path, str(rig), only=["x"], timing=FAST_TIMING)
        result = cli("decompile", "--port", server.path, "--rig", out, *FAST)
    assert result.exit_code == 0, result.output
    assert (out / "x.mcm").read_text() == (rig.parent / "x.mcm").read_text()  # as flashed
    assert "[MC" not in (out / "a1.mcm").read_text()  # decompiled
    lines = result.output.splitlines()
    assert "recorded source (x): each holds a build the flash history records" in result.output
    assert any(line.startswith("decompiled (a1): no flash in the history left exactly what it "
                               "holds: made from the stored macros") for line in lines)
    # y of the rig answered with macros flashed from nowhere: the rig's wires are not given
    assert "no longer matches: its y (address 1) holds no build flashed from it" in result.output


def test_rig_with_options_that_do_not_go_with_it_is_refused(tmp_path):
    assert cli("pull", "/dev/null", "--rig", tmp_path / "d", "-o", tmp_path / "x.mcm").exit_code == 2
    assert cli("pull", "/dev/null", "--rig", tmp_path / "d", "--address", "1").exit_code == 2
    assert cli("decompile", "--rig", tmp_path / "d").exit_code == 2


def test_pull_rig_as_a_process(rig, tmp_path, data_dir):
    out = tmp_path / "pulled"
    with chain() as (server, vcs):
        flash_chain(server.path, str(rig), timing=FAST_TIMING)
        done = mercmac_process("pull", server.path, "--rig", str(out), *SEARCHING, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "recorded source" in done.stderr
    assert (out / "y.mcm").read_text() == (rig.parent / "y.mcm").read_text()


# -- names from the history are never paths; DIR's files are not replaced silently ---------------

def _poison(data_dir: Path, rig_name: str, controller: str) -> None:
    """Every history record says the rig and the controller are called so."""
    import json

    for path in (data_dir / "history").glob("*.json"):
        record = json.loads(path.read_text())
        record.update(rig_name=rig_name, controller=controller)
        path.write_text(json.dumps(record))


@pytest.mark.parametrize("name", ["../../escaped", "/abs/escaped", "a/escaped", "..", "é"])
def test_a_poisoned_history_never_leads_out_of_the_folder(rig, tmp_path, data_dir, name):
    """Item 1: the rig's name in the history became DIR/NAME.rig.toml, '../../x' included."""
    out = tmp_path / "deep" / "er" / "pulled"
    with chain() as (server, vcs):
        flash_chain(server.path, str(rig), timing=FAST_TIMING)
        _poison(data_dir, name, name)
        result = cli("pull", server.path, "--rig", out, *FAST)
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in out.iterdir()) == ["a0.mcm", "a1.mcm", "pulled.rig.toml"]
    assert not list(tmp_path.rglob("*escaped*"))
    assert cli("check", out / "pulled.rig.toml").exit_code == 0


@pytest.mark.parametrize("where", ["fifo", "name\nwires = [\"x.out1 -> y.in2\"]\n"])
def test_a_poisoned_rig_path_in_the_history_is_read_safely_and_said_escaped(rig, tmp_path,
                                                                            data_dir, where):
    """The recorded rig file is a FIFO (never opened to block the pull) or a name holding a
    newline (which must not end the comment that quotes it and add a key)."""
    import json
    import os

    target = tmp_path / where
    if where == "fifo":
        os.mkfifo(target)
    out = tmp_path / "pulled"
    with chain() as (server, vcs):
        flash_chain(server.path, str(rig), timing=FAST_TIMING)
        for path in (data_dir / "history").glob("*.json"):
            record = json.loads(path.read_text())
            record["rig"] = str(target)
            path.write_text(json.dumps(record))
        result = cli("pull", server.path, "--rig", out, *FAST)
    assert result.exit_code == 0, result.output
    text = (out / "raster.rig.toml").read_text()
    assert "wires = []\n" in text and "no longer matches: it cannot be read" in text
    assert _wiring(out / "raster.rig.toml")[2] == []
    assert cli("check", out / "raster.rig.toml").exit_code == 0


@pytest.mark.parametrize("folder,name", [("2026", "_2026"), ("my rig-1", "my_rig_1"),
                                         ("été", "t"), ("--", "rig")])
def test_a_rig_named_after_its_folder_checks_clean(tmp_path, data_dir, folder, name):
    """The name made from the folder's is a name `check` takes (it made '2026' before)."""
    out = tmp_path / folder
    with chain(RAW) as (server, vcs):
        result = cli("pull", server.path, "--rig", out, *FAST)
    assert result.exit_code == 0, result.output
    assert (out / f"{name}.rig.toml").is_file()
    assert cli("check", out / f"{name}.rig.toml").exit_code == 0


def _files(folder: Path) -> dict[str, str]:
    return {p.name: p.read_text() for p in sorted(folder.iterdir()) if p.is_file()}


@pytest.mark.parametrize("command", [("pull", "{port}"), ("decompile", "--port", "{port}")])
def test_pulling_into_the_rigs_own_folder_needs_force(rig, data_dir, command):
    """Item 2: it replaced raster.rig.toml (wires, box, comments gone) and an edited x.mcm."""
    folder = rig.parent
    (folder / "x.mcm").write_text((folder / "x.mcm").read_text() + "// edited, not flashed\n")
    before = _files(folder)
    with chain() as (server, vcs):
        flash_chain(server.path, str(rig), timing=FAST_TIMING)
        (folder / "x.mcm").write_text(before["x.mcm"] + "// edited again\n")
        before = _files(folder)
        args = [a.format(port=server.path) for a in command]
        refused = cli(*args, "--rig", folder, *FAST)
        assert _files(folder) == before
        forced = cli(*args, "--rig", folder, "--force", *FAST)
    assert refused.exit_code == 2, refused.output
    said = refused.output
    assert all(name in said for name in ("raster.rig.toml", "x.mcm", "y.mcm"))
    assert "--force" in said and "nothing was written" in said
    assert forced.exit_code == 0, forced.output
    # the rig file replaced was the one flashed: its wiring was read before it was replaced
    assert "read by mercmac" in (folder / "raster.rig.toml").read_text()
    assert _wiring(folder / "raster.rig.toml")[2] == ["x.out1 -> y.in1", "y.out2 -> x.in2"]


def test_every_target_is_checked_before_the_first_is_written(tmp_path, data_dir):
    """Item 2: `y.mcm -> /dev/null` left x.mcm written and no rig file."""
    out = tmp_path / "bench"
    out.mkdir()
    (out / "a1.mcm").symlink_to("/dev/null")
    with chain(RAW) as (server, vcs):
        plain = cli("pull", server.path, "--rig", out, *FAST)
        forced = cli("pull", server.path, "--rig", out, "--force", *FAST)
    for result in (plain, forced):
        assert result.exit_code == 2, result.output
        assert "a1.mcm" in result.output and "symbolic link" in result.output
        assert sorted(p.name for p in out.iterdir()) == ["a1.mcm"]
    assert (out / "a1.mcm").is_symlink()


def test_a_link_in_the_folder_is_never_followed_even_with_force(tmp_path, data_dir):
    """Item 2: DIR/a0.mcm, a link to a file elsewhere, got that file overwritten."""
    out, elsewhere = tmp_path / "bench", tmp_path / "precious.txt"
    out.mkdir()
    elsewhere.write_text("keep me\n")
    (out / "a0.mcm").symlink_to(elsewhere)
    with chain(RAW) as (server, vcs):
        result = cli("pull", server.path, "--rig", out, "--force", *FAST)
    assert result.exit_code == 2, result.output
    assert "a0.mcm" in result.output and "symbolic link" in result.output
    assert elsewhere.read_text() == "keep me\n" and (out / "a0.mcm").is_symlink()
    assert sorted(p.name for p in out.iterdir()) == ["a0.mcm"]


@pytest.mark.parametrize("inside", [False, True])
def test_a_read_only_folder_is_refused_by_its_mode_even_as_root(tmp_path, data_dir, inside):
    """Item 2: root ignores permission bits; a 0555 folder still says it is not to change.
    Refused before any controller is read (reading stops a running macro): rig_folder."""
    ro = tmp_path / "ro"
    ro.mkdir()
    out = ro / "bench" if inside else ro
    ro.chmod(0o555)
    try:
        with chain(RAW) as (server, vcs):
            result = cli("pull", server.path, "--rig", out, *FAST)
    finally:
        ro.chmod(0o755)
    assert result.exit_code == 2, result.output
    assert str(ro) in result.output and "Traceback" not in result.output
    assert list(ro.iterdir()) == []


# -- two controllers at one address -------------------------------------------------------------

@contextmanager
def shared_address(macros=RAW):
    """Two controllers set to address 0 (and none at 1): the Chain refuses equal addresses
    when it is built, so the second one's DIP switches are changed afterwards."""
    with chain(macros) as (server, vcs):
        server.call(lambda _c: setattr(vcs[1], "address", 0))
        yield server, vcs


def test_scan_says_that_two_controllers_answered_at_one_address(data_dir):
    with shared_address() as (server, vcs):
        result = cli("scan", server.path, "--stop", *FAST)
    assert result.exit_code == 0, result.output
    (row,) = [line for line in result.output.splitlines() if line.lstrip().startswith("0 ")]
    assert "two controllers answered" in row
    assert not any(line.lstrip().startswith("1 ") for line in result.output.splitlines())


def test_scan_of_one_controller_per_address_says_nothing_of_it(data_dir):
    with chain(RAW) as (server, vcs):
        result = cli("scan", server.path, "--stop", *FAST)
    assert result.exit_code == 0 and "two controllers" not in result.output


@pytest.mark.parametrize("command", [("pull", "{port}"), ("decompile", "--port", "{port}")])
def test_pull_rig_does_not_merge_two_controllers_at_one_address(tmp_path, data_dir, command):
    out = tmp_path / "bench"
    with shared_address() as (server, vcs):
        result = cli(*[a.format(port=server.path) for a in command], "--rig", out, *FAST)
    assert result.exit_code == 1, result.output
    assert "two controllers answered at address 0" in result.output
    assert "DIP switches" in result.output and not out.exists()


def test_a_history_name_like_another_address_does_not_merge_two_controllers(tmp_path, data_dir):
    """The history names address 0 `a1`; address 1, never flashed, is a1 by its address:
    each still gets its own file and table."""
    from helpers.rigs import X, write_rig

    toml = ('[controllers.a1]\naddress = 0\nmodel = "C-663"\nprogram = "x.mcm"\n'
            '[controllers.y]\naddress = 1\nmodel = "C-663"\nprogram = "y.mcm"\n')
    rig = write_rig(tmp_path, toml)
    out = tmp_path / "bench"
    with chain(({}, RAW[1])) as (server, vcs):
        flash_chain(server.path, str(rig), only=["a1"], timing=FAST_TIMING)
        result = cli("pull", server.path, "--rig", out, *FAST)
    assert result.exit_code == 0, result.output
    assert sorted(p.name for p in out.iterdir()) == ["a1.mcm", "a1_.mcm", "r.rig.toml"]
    assert (out / "a1.mcm").read_text() == X
    assert cli("check", out / "r.rig.toml").exit_code == 0


# -- a --timeout given is the wait at each address too ----------------------------------------

@pytest.mark.parametrize("given, search", [((), 0.3), (("--timeout", "2"), 2.0),
                                            (("--timeout", "0.1"), 0.1)])
@pytest.mark.parametrize("command", [("pull", "--rig", "pulled"), ("flash", "prog.mcm")])
def test_a_given_timeout_is_the_wait_at_each_address_searched(tmp_path, monkeypatch, given,
                                                              search, command):
    """`pull --rig` scanned, and `flash` without --address searched, at 0.3 s an address
    whatever --timeout said: a slow link (an emulator on a loaded machine, a serial server
    across a network) could not be given room. The default stays 0.3 s (16 addresses)."""
    from mercmac.upload import survey

    shutil.copy(ROOT / "examples" / "macros" / "jog-box.mcm", tmp_path / "prog.mcm")
    scan, waits = survey.scan, []

    def watched(transport, *args, **kw):
        waits.append(transport.timing.timeout)
        return scan(transport, *args, **kw)

    monkeypatch.setattr(survey, "scan", watched)
    monkeypatch.chdir(tmp_path)
    # one controller, at 2: `flash` finds nobody at 0 and searches 1-15
    with PtyServer(Chain([VirtualController("C-663", 2)])) as server, line_clock(server):
        result = cli(command[0], server.path, *command[1:], *given)
    assert result.exit_code == 0, result.output
    assert waits == [search]


def test_pull_rig_says_whether_the_folder_it_wrote_checks(tmp_path, data_dir):
    """The rig written is read back as every command reads a rig (rig.open): its check."""
    from mercmac.emulator.faults import Faults

    with chain(({0: "SV20000,CP3"}, {0: "MR500,WS10,CN2"})) as (server, vcs):
        clean = cli("pull", server.path, "--rig", tmp_path / "clean", *FAST)
    with chain(RAW) as (server, vcs):  # each waits on an input no wire drives yet: MR011
        waits = cli("pull", server.path, "--rig", tmp_path / "waits", *FAST)
    unknown = [VirtualController("C-663", 0, macros=dict(RAW[0])),
               VirtualController("C-663", 1, macros=dict(RAW[1]),
                                 faults=Faults(version="(c)2026 a controller Ver. 9.99"))]
    with PtyServer(Chain(unknown)) as server, line_clock(server):
        said = cli("pull", server.path, "--rig", tmp_path / "unknown", *FAST)
    assert clean.exit_code == 0 and "check: clean" in clean.output
    assert cli("check", tmp_path / "clean" / "clean.rig.toml").exit_code == 0
    assert waits.exit_code == 0 and "check: 2 warnings, 2 infos; `mercmac check" in waits.output
    assert said.exit_code == 0, said.output
    line = next(line for line in said.output.splitlines() if line.startswith("check: "))
    assert line.startswith("check: 1 error") and "unknown.rig.toml` lists them" in line
    assert cli("check", tmp_path / "unknown" / "unknown.rig.toml").exit_code == 1


def test_pull_rig_that_check_cannot_run_on_is_pulled_and_says_why(tmp_path, data_dir):
    """A settings file above the folder that `check` refuses: the pull is done (exit 0, every
    file written), and its last line says why the rig was not checked."""
    (tmp_path / "mercmac.toml").write_text('select = ["no-such-rule"]\n', encoding="utf-8")
    with chain(({0: "SV20000,CP3"}, {0: "MR500,WS10,CN2"})) as (server, vcs):
        said = cli("pull", server.path, "--rig", tmp_path / "bench", *FAST)
    assert said.exit_code == 0, said.output
    assert sorted(p.name for p in (tmp_path / "bench").iterdir()) == [
        "a0.mcm", "a1.mcm", "bench.rig.toml"]
    line = said.output.splitlines()[-1]
    assert line.startswith("check: not run: ") and "no-such-rule" in line
