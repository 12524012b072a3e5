"""Reading a rig file (mercmac/rig/load.py, locate.py): the Rig it describes, and every
problem of the file itself at its line and column."""
from __future__ import annotations

import pytest

from mercmac.rig.load import is_rig_path, read_rig
from mercmac.rig.model import LineKind
from helpers.rigs import RASTER, WIRES, X, controllers, write_rig


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
    assert rig.controller("x").span.line == 30  # its [controllers.x] header
    assert rig.joystick == {"X": "x", "Y": "y"}  # as the README shows it


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
    # more digits than int() reads, in TOML and in a wire
    (WIRES + controllers(x="9" * 5000), "MR001", 3, 11, "too many digits"),
    (f'wires = ["x.out{"9" * 5000} -> y.in1"]\n' + controllers(), "MR003", 1, 10, "numbered 1-4"),
    (f'wires = ["x.out1 -> y.in{"0" * 5000}"]\n' + controllers(), "MR003", 1, 10, "numbered 1-4"),
    # ASCII digits and names only; box_buttons twice, or without a box
    ('wires = ["x.out\u0661 -> y.in1"]\n' + controllers(), "MR003", 1, 10, "a wire is written"),
    ('wires = ["x.out1 -> y.in\uff11"]\n' + controllers(), "MR003", 1, 10, "a wire is written"),
    ('wires = ["x\u00e9.out1 -> y.in1"]\n' + controllers(), "MR003", 1, 10, "a wire is written"),
    ('box = "x"\nbox_buttons = [1, 3, 1]\n' + controllers(), "MR001", 2, 1,
     "button 1 is listed twice"),
    ("box_buttons = [1, 3]\n" + controllers(), "MR001", 1, 1, "the rig has no box"),
    (controllers().replace("controllers.x]", f"controllers.{'a' * 65}]") , "MR001", 1, 2,
     "at most 64 characters"),
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


def test_the_readme_shows_the_bundled_raster_rig_as_it_is():
    """The README showed the raster "with the [joystick] table added", which the bundled
    file had not: the joystick example of docs/rigs.md was refused on it."""
    from dataclasses import replace

    from helpers.readme import README
    from mercmac.rig.load import parse_rig
    from mercmac.source import Source

    toml = README.split("### Rigs", 1)[1].split("```toml\n", 1)[1].split("```", 1)[0]
    shown = parse_rig(Source(str(RASTER), toml)).rig
    bundled = read_rig(str(RASTER)).rig
    assert replace(shown, path="") == replace(bundled, path="")


@pytest.mark.parametrize("name", ["../../x", "/abs/x", "a/b", "..", "", "a b", "x\\y", "2x"])
def test_a_rig_name_is_a_name_never_a_path(tmp_path, name):
    """The name goes into file names (flash --backup DIR/, pull --rig), so
    it is refused at the `name` key as a controller's name is, in `check` as in the reader."""
    import json

    from helpers.cli import cli

    path = write_rig(tmp_path, f"# a rig\nname = {json.dumps(name)}\n" + WIRES + controllers())
    assert read_rig(str(path)).rig is None
    assert [f[:3] for f in _found(path)] == [("MR001", 2, 1)]
    result = cli("check", path, "--format", "json")
    assert result.exit_code == 1, result.output
    (found,) = json.loads(result.output)["diagnostics"]
    assert (found["code"], found["line"], found["column"]) == ("MR001", 2, 1)
    assert "is no rig name" in found["message"]


def test_a_rig_name_like_a_controller_name_is_taken(tmp_path):
    path = write_rig(tmp_path, 'name = "stage_1"\n' + WIRES + controllers())
    assert read_rig(str(path)).rig.name == "stage_1"


def test_a_name_of_64_characters_is_a_name(tmp_path):
    name = "a" * 64
    path = write_rig(tmp_path, controllers().replace("controllers.x]", f"controllers.{name}]"))
    assert [c.name for c in read_rig(str(path)).rig.controllers] == [name, "y"]


def test_box_buttons_are_kept_once_each_in_order(tmp_path):
    rig = read_rig(str(write_rig(tmp_path, 'box = "y"\nbox_buttons = [3, 1]\n' + controllers())))
    assert rig.rig.box_buttons == (3, 1)


def test_a_rig_reads_without_tomllib(monkeypatch, tmp_path):
    """Python 3.10 has no tomllib: the rig is read with tomli, whose
    errors carry their place alike."""
    from helpers.python310 import without_tomllib

    without_tomllib(monkeypatch)
    assert read_rig(str(write_rig(tmp_path))).rig.name == "r"
    assert _found(write_rig(tmp_path, "wires = [\n"))[0][:3] == ("MR001", 2, 1)


# -- a program lies in the rig's folder or below it, and ends in .mcm ---------------------------

SECRET = "aws_secret_access_key = hunter2\n"


@pytest.fixture
def outside(tmp_path):
    """A rig folder `rig/` beside a folder `home/` that holds a secret and a .mcm file."""
    (tmp_path / "home").mkdir()
    (tmp_path / "home" / "credentials").write_text(SECRET, encoding="utf-8")
    (tmp_path / "home" / "p.mcm").write_text(X, encoding="utf-8")
    (tmp_path / "rig").mkdir()
    return tmp_path


def _program_rig(folder, program: str):
    return write_rig(folder, WIRES + controllers().replace('"x.mcm"', program))


@pytest.mark.parametrize("program, why", [
    ('"../home/credentials"', "leads out of the rig file's folder"),
    ('"../home/p.mcm"', "leads out of the rig file's folder"),
    ('"sub/../../home/p.mcm"', "leads out of the rig file's folder"),
    ('"/etc/passwd"', "absolute path"),
    ('"/proc/self/environ"', "absolute path"),
    ("'{home}/p.mcm'", "absolute path"),
    ('"x.txt"', "does not end in .mcm"),
    ('"r.rig.toml"', "does not end in .mcm"),
    ('"."', "does not end in .mcm"),
    ('"x\\u0000.mcm"', "NUL character"),
])
def test_a_program_path_the_rig_may_not_name_is_an_error_at_its_key(outside, program, why):
    path = _program_rig(outside / "rig", program.format(home=outside / "home"))
    found = _found(path)
    assert found == [("MR001", 5, 1, "the program of x must be a .mcm file in the rig file's "
                                     f"folder or below it: {found[0][3].split(': ', 1)[1]}")]
    assert why in found[0][3] and "hunter2" not in found[0][3]
    assert read_rig(str(path)).rig is None


@pytest.mark.parametrize("link, program", [
    ("p.mcm", "p.mcm"),  # a file link that leads out of the folder
    ("sub", "sub/p.mcm"),  # a folder link that does
    ("c.mcm", "c.mcm"),  # to a file that is no .mcm, out of the folder
])
def test_a_link_that_leads_out_of_the_folder_is_refused(outside, link, program):
    target = outside / "home" / ("credentials" if link == "c.mcm" else
                                 "" if link == "sub" else "p.mcm")
    (outside / "rig" / link).symlink_to(target)
    found = _found(_program_rig(outside / "rig", f'"{program}"'))
    assert [f[:3] for f in found] == [("MR001", 5, 1)] and "leads out" in found[0][3]


def test_a_link_that_stays_in_the_folder_is_taken(outside):
    folder = outside / "rig"
    (folder / "lib").mkdir()
    (folder / "lib" / "p.mcm").write_text(X, encoding="utf-8")
    (folder / "p.mcm").symlink_to("lib/p.mcm")
    (folder / "notes.txt").write_text(X, encoding="utf-8")
    (folder / "n.mcm").symlink_to("notes.txt")
    rig = read_rig(str(_program_rig(folder, '"p.mcm"'))).rig
    assert rig.controller("x").program == str(folder / "p.mcm")
    assert read_rig(str(_program_rig(folder, '"lib/p.mcm"'))).rig is not None
    found = _found(_program_rig(folder, '"n.mcm"'))  # stays in, but is no .mcm file
    assert [f[:3] for f in found] == [("MR001", 5, 1)] and "link to a file" in found[0][3]


def test_a_rig_in_a_linked_folder_takes_its_programs(outside):
    (outside / "via").symlink_to(outside / "rig")
    write_rig(outside / "rig")
    assert read_rig(str(outside / "via" / "r.rig.toml")).rig is not None
