"""`mercmac history` shows rigs: the controllers of one rig flash stand under
a line that names the rig; JSON says for each flash which rig and controller it was."""
from __future__ import annotations

import datetime as dt
import json

from helpers.cli import cli
from mercmac.upload import history

PORT = "/dev/ttyUSB0"
T0 = dt.datetime(2026, 11, 25, 1, 0, 0, tzinfo=dt.timezone.utc)


def _flash(address: int, file: str, seconds: int, rig: history.InRig | None = None) -> None:
    history.record(port=PORT, address=address, model="C-663", firmware="1.10", file=file,
                   source="[MC00] MR5\n", build=["MD0,MR5"],
                   when=T0 + dt.timedelta(seconds=seconds), rig=rig)


def _raster(controller: str) -> history.InRig:
    return history.InRig("/lab/raster.rig.toml", "raster", controller)


def test_a_rigs_controllers_stand_under_its_name(data_dir):
    _flash(3, "/lab/alone.mcm", 0)
    _flash(0, "/lab/x.mcm", 10, _raster("x"))
    _flash(1, "/lab/y.mcm", 11, _raster("y"))
    result = cli("history")
    assert result.exit_code == 0, result.output
    lines = result.stdout.splitlines()
    assert lines[0].split()[:2] == ["time", "port"]
    assert lines[1] == "rig raster (/lab/raster.rig.toml): 2 controllers"
    assert lines[2].startswith("  2026-") and "y: /lab/y.mcm" in lines[2]
    assert lines[3].startswith("  2026-") and "x: /lab/x.mcm" in lines[3]
    assert lines[4].startswith("2026-") and "/lab/alone.mcm" in lines[4]
    # the columns stay aligned across rig rows and single flashes
    assert lines[2].index("/dev/ttyUSB0") == lines[4].index("/dev/ttyUSB0")


def test_two_flashes_of_one_rig_are_two_groups(data_dir):
    for start in (0, 100):
        _flash(0, "/lab/x.mcm", start, _raster("x"))
        _flash(1, "/lab/y.mcm", start + 1, _raster("y"))
    lines = cli("history").stdout.splitlines()
    assert [line for line in lines if line.startswith("rig ")] == [
        "rig raster (/lab/raster.rig.toml): 2 controllers"] * 2


def test_json_names_the_rig_and_controller(data_dir):
    _flash(3, "/lab/alone.mcm", 0)
    _flash(0, "/lab/x.mcm", 10, _raster("x"))
    flashes = json.loads(cli("history", "--format", "json").stdout)["flashes"]
    assert flashes[0]["rig"] == {"file": "/lab/raster.rig.toml", "name": "raster",
                                 "controller": "x"}
    assert flashes[1]["rig"] is None


def test_a_rig_name_is_escaped_like_every_recorded_text(data_dir):
    _flash(0, "/lab/x.mcm", 0, history.InRig("/lab/r.rig.toml", "ra\x1b[2Jster\nx", "x"))
    out = cli("history").stdout
    assert "\x1b" not in out and "\n" not in out.split("rig ", 1)[1].split(":")[0]
