"""The flash history's rig fields: a rig flash names the rig and the controller;
a single flash's record, and an older mercmac's, has none and stays readable."""
from __future__ import annotations

import json

from mercmac.upload import history


def test_a_rig_record_names_the_rig_and_a_single_one_does_not(tmp_path, data_dir):
    common = dict(port="/dev/ttyUSB0", address=1, model="C-663", firmware="2.30",
                  file=str(tmp_path / "y.mcm"), source="target C-663\n[MC01] MR500\n",
                  build=["MD1,MR500"])
    rig = history.record(**common, rig=history.InRig(str(tmp_path / "r.rig.toml"), "r", "y"))
    single = history.record(**common)
    assert {"rig", "rig_name", "controller"} <= json.loads(rig.read_text()).keys()
    assert not {"rig", "rig_name", "controller"} & json.loads(single.read_text()).keys()
    found = {r.controller: r for r in history.read().records}
    assert found["y"].rig == str(tmp_path / "r.rig.toml") and found["y"].rig_name == "r"
    assert found[None].rig is None  # the single flash: read with the defaults
    assert history.read().skipped == []
