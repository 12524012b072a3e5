"""An unknown word gets "did you mean 'select'?" from the one measure (mercmac/suggest.py),
said alike wherever it is written: a setting, a rig file key or controller name, a scenario
key, a const, a rule or command for `explain`."""
from __future__ import annotations

import json
import re

import pytest

from helpers.cli import cli
from helpers.compiling import compile_text
from helpers.rigs import WIRES, controllers, write_rig
from mercmac import config
from mercmac.rig.load import read_rig
from mercmac.suggest import did_you_mean, question

ASKED = re.compile(r"did you mean '[^']+'\?")


@pytest.fixture
def folder(monkeypatch, tmp_path):
    monkeypatch.setattr(config, "_FOUND", {})
    monkeypatch.chdir(tmp_path)
    (tmp_path / "a.mcm").write_text("autostart { TP }\n", encoding="utf-8")
    return tmp_path


def test_the_phrase():
    assert did_you_mean("slect", ("target", "select", "ignore")) == "did you mean 'select'?"
    assert did_you_mean("zzzzzz", ("target", "select", "ignore")) == ""
    assert did_you_mean("ab", ("abc",), limit=0) == ""
    assert question(None) == "" and question("x") == "did you mean 'x'?"


@pytest.mark.parametrize("text, says", [
    ('slect = ["MM011"]\n', "unknown setting 'slect' in {}; did you mean 'select'?"),
    ('ignor = []\ntarge = "C-863"\n',
     "unknown settings 'ignor', 'targe' in {}; did you mean 'ignore' for 'ignor', 'target' "
     "for 'targe'?"),
    ("zzzzzz = 1\n", "unknown setting 'zzzzzz' in {}\n"),
])
def test_a_misspelt_setting_gets_the_key_meant(folder, text, says):
    (folder / "mercmac.toml").write_text(text, encoding="utf-8")
    result = cli("check", "--format", "json", "a.mcm", catch=True)
    assert result.exit_code == 2
    assert says.format(folder / "mercmac.toml") in result.output, result.output
    assert "mercmac knows target, select, ignore" in result.output


def test_a_misspelt_rig_key_gets_the_key_meant(tmp_path):
    path = write_rig(tmp_path, "box_butons = [1]\n" + WIRES + controllers() + "adress = 3\n")
    found = read_rig(str(path)).report.sorted()
    messages = [d.message for d in found if "unknown key" in d.message]
    assert messages == [
        "unknown key 'box_butons' at the top of the rig file: did you mean 'box_buttons'? the "
        "keys are name, box, box_buttons, wires, joystick, controllers",
        "unknown key 'adress' in [controllers.y]: did you mean 'address'? the keys are "
        "address, model, program"]


def test_every_reader_asks_alike(folder):
    (folder / "mercmac.toml").write_text('slect = ["MM011"]\n', encoding="utf-8")
    said = [cli("check", "a.mcm", catch=True).output,
            cli("explain", "nestedcall").output,
            compile_text("const FAR = 5\nautostart { MR FRA }\n").report.items[0].message,
            read_rig(str(write_rig(folder, 'wires = ["x.out1 -> z.in1"]\n' + controllers())))
            .report.items[0].message]
    (folder / "mercmac.toml").unlink()
    (folder / "s.toml").write_text('untill = "2s"\n', encoding="utf-8")
    said.append(cli("sim", "a.mcm", "--scenario", "s.toml", catch=True).output)
    for text in said:
        assert ASKED.search(text), text
    assert json.loads(cli("check", "--format", "json", "a.mcm").output)["diagnostics"] == []
