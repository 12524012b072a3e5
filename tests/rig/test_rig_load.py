"""Reading a rig file (mercmac/rig/load.py, locate.py): the Rig it describes, and every
problem of the file itself at its line and column (issue 18)."""
from __future__ import annotations

import pytest

from mercmac.rig.load import is_rig_path, read_rig
from mercmac.rig.model import LineKind
from helpers.rig_files import RASTER, WIRES, controllers, write_rig


def _found(path) -> list[tuple[str, int, int, str]]:
    return [(d.rule.code, d.span.line, d.span.column, d.message)
            for d in read_rig(str(path)).report.sorted()]


def test_the_raster_rig_reads_whole():
    rig = read_rig(str(RASTER)).rig
    assert rig.name == "raster" and rig.box == "x" and rig.box_buttons == (1, 3)
    assert [(c.name, c.address, c.model) for c in rig.controllers] == [("x", 0, "C-663"),
                                                                     ("y", 1, "C-663")]
    assert rig.controller("y").program == str(RASTER.parent / "y.mcm")
    assert [str(w) for w in rig.wires] == ["x.out1 -> y.in1", "y.out2 -> x.in2"]
    assert rig.drivers("y", 1)[0].source.kind is LineKind.OUT
    assert rig.by_address(1).name == "y" and rig.by_address(7) is None
    assert rig.controller("x").span.line == 23  # its [controllers.x] header


def test_rig_paths_are_named_so_in_any_case():
    assert is_rig_path("a/B.RIG.TOML") and is_rig_path("r.rig.toml")
    assert not is_rig_path("r.toml") and not is_rig_path("rig.mcm")


def test_the_name_defaults_to_the_file_stem(tmp_path):
    assert read_rig(str(write_rig(tmp_path))).rig.name == "r"


@pytest.mark.parametrize("end", [b"\r\n", b"\r"])
def test_a_bom_and_crlf_or_cr_line_ends_are_read(tmp_path, end):
    path = write_rig(tmp_path, WIRES + controllers(y="1\nadress = 2"))
    path.write_bytes(b"\xef\xbb\xbf" + path.read_bytes().replace(b"\n", end))
    assert [f[:3] for f in _found(path)] == [("MR001", 8, 1)]


@pytest.mark.parametrize("toml,code,line,column,words", [
    ("wires = [\n", "MR001", 2, 1, "not valid TOML"),
    (WIRES + controllers() + "adress = 3\n", "MR001", 10, 1, "unknown key 'adress'"),
    ("colour = 1\n" + WIRES + controllers(), "MR001", 1, 1, "unknown key 'colour'"),
    (WIRES + controllers().replace("address = 1\n", ""), "MR001", 6, 2, "needs 'address'"),
    (WIRES + controllers(x='"zero"'), "MR001", 3, 1, "'address' in [controllers.x] must be"),
    (WIRES + controllers(model="C-999"), "MR001", 4, 1, "C-663 or C-863"),
    ('wires = ["x.out1 -> y.in1",\n  "x.out1 => y.in2"]\n' + controllers(), "MR003", 2, 3,
     "a wire is written"),
    ('wires = ["x.out5 -> y.in1"]\n' + controllers(), "MR003", 1, 10, "numbered 1-4"),
    ('wires = ["x.in1 -> y.out1"]\n' + controllers(), "MR003", 1, 10, "from an output to an input"),
    ('wires = ["x.out1 -> x.in2"]\n' + controllers(), "MR003", 1, 10, "to itself"),
    ('wires = ["x.out1 -> z.in1"]\n' + controllers(), "MR001", 1, 10, "did you mean"),
    ('box = "w"\n' + controllers(), "MR001", 1, 1, "box names 'w'"),
    ('box_buttons = [1, 5]\n' + controllers(), "MR001", 1, 1, "no button 5"),
    ('[joystick]\nW = "x"\n' + controllers(), "MR001", 2, 1, "no branch 'W'"),
    ('[joystick]\nX = "q"\n' + controllers(), "MR001", 2, 1, "joystick branch X names 'q'"),
    ('[controllers.2x]\naddress = 0\nmodel = "C-663"\nprogram = "x.mcm"\n', "MR001", 1, 2,
     "no controller name"),
    ("name = 'r'\n", "MR001", 1, 1, "names no controller"),
])
def test_a_problem_of_the_file_is_reported_where_it_stands(tmp_path, toml, code, line, column,
                                                           words):
    path = write_rig(tmp_path, toml)
    rig_file = read_rig(str(path))
    assert rig_file.rig is None
    found = _found(path)
    assert any(c == code and (ln, col) == (line, column) and words in m
               for c, ln, col, m in found), found


def test_a_file_that_is_not_utf8_is_a_diagnostic(tmp_path):
    path = write_rig(tmp_path)
    path.write_bytes(b'name = "r\xe9"\n')
    assert _found(path)[0][:3] == ("MR001", 1, 1)
    assert "not UTF-8" in _found(path)[0][3]


def test_a_missing_rig_file_is_an_os_error(tmp_path):
    with pytest.raises(OSError):
        read_rig(str(tmp_path / "none.rig.toml"))


def test_the_readme_documents_the_keys_of_a_rig_file():
    from helpers.readme import README
    from mercmac.rig.load import parse_rig
    from mercmac.source import Source

    section = README.split("### Rigs", 1)[1]
    toml = section.split("```toml\n", 1)[1].split("```", 1)[0]
    rig_file = parse_rig(Source(str(RASTER.parent / "readme.rig.toml"), toml))
    assert rig_file.report.items == [] and rig_file.rig.joystick == {"X": "x", "Y": "y"}
