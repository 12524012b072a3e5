"""The one TOML reader (mercmac/tomlfile.py): settings, scenarios and rigs
are read with the same guards, each failure a TomlError with its place, never a traceback;
on Python 3.10, which has no tomllib, tomli reads them."""
from __future__ import annotations

import os
import sys

import pytest

from helpers.python310 import without_tomllib
from mercmac import tomlfile
from mercmac.source import MAX_BYTES, SourceError

HUGE = "9" * 5000  # int() refuses more than 4300 digits (sys.get_int_max_str_digits)


@pytest.mark.parametrize("text, line, column, words", [
    ("a = 1\nb = [\n", 3, 1, "not valid TOML"),  # at the end of the document
    ("a = 1\nb = ?\n", 2, 5, "not valid TOML"),
    ("a = 1\rb = ?\r", 2, 5, "not valid TOML"),  # a lone CR ends a line (docs/cli.md)
    (f"a = 1\nb = [1, {HUGE}]\n", 2, 9, "too many digits"),
    (f"a = 1\n[t]\nb = -{HUGE}\n", 3, 6, "too many digits"),
])
def test_a_text_that_is_no_toml_is_said_with_its_place(text, line, column, words):
    with pytest.raises(tomlfile.TomlError) as caught:
        tomlfile.loads(text)
    assert (caught.value.line, caught.value.column) == (line, column)
    assert words in caught.value.why


@pytest.mark.parametrize("text", ["a = " + "[" * 5000 + "]" * 5000,
                                  "a = " + "{b = " * 3000 + "1" + "}" * 3000])
def test_deep_nesting_is_a_toml_error(text):
    with pytest.raises(tomlfile.TomlError, match="nested too deeply"):
        tomlfile.loads(text)


def test_a_lone_cr_ends_a_line():
    assert tomlfile.loads("a = 1\rb = 2\r\nc = 3\n") == {"a": 1, "b": 2, "c": 3}


@pytest.mark.parametrize("data", [
    b'a = "\xc3\xa9"\n',
    b'\xef\xbb\xbfa = "\xc3\xa9"\n',  # a UTF-8 byte-order mark is read past
    'a = "\u00e9"\n'.encode("utf-16"),  # UTF-16 after its mark (Notepad's "Unicode")
    b"\xfe\xff" + 'a = "\u00e9"\n'.encode("utf-16-be"),
])
def test_utf8_and_marked_utf16_are_read(tmp_path, data):
    (tmp_path / "f.toml").write_bytes(data)
    assert tomlfile.read(str(tmp_path / "f.toml")).table == {"a": "\u00e9"}


def test_bytes_that_are_not_utf8_are_located():
    with pytest.raises(tomlfile.TomlError) as caught:
        tomlfile.decode(b"a = 1\n# \x99\n")
    assert "0x99 at line 2 is not UTF-8" in caught.value.why and caught.value.line == 2


def test_utf16_that_does_not_read_says_so():
    with pytest.raises(tomlfile.TomlError, match="UTF-16 byte-order mark"):
        tomlfile.decode(b"\xff\xfe" + "a = 1".encode("utf-16-le") + b"\x00\xd8")


def test_only_a_regular_file_of_at_most_the_cap_is_read(tmp_path):
    fifo = tmp_path / "f.toml"
    os.mkfifo(fifo)
    with pytest.raises(SourceError, match="not a regular file"):
        tomlfile.read(str(fifo))  # opened without blocking: no writer, no hang
    big = tmp_path / "big.toml"
    with open(big, "wb") as f:
        f.truncate(MAX_BYTES + 1)  # sparse: nothing is written, nothing must be read
    with pytest.raises(SourceError, match="larger than"):
        tomlfile.read(str(big))


def test_python_3_10_reads_with_tomli(monkeypatch):
    """No tomllib (Python 3.10): tomli, which pyproject.toml depends on there, reads the
    file, and its errors are TomlErrors alike (helpers.python310: where tomli is not
    installed, a stand-in of that name shows which module is used)."""
    tomli = without_tomllib(monkeypatch)
    assert tomlfile._tomllib() is tomli
    assert tomlfile.loads("a = 1\r") == {"a": 1}
    with pytest.raises(tomlfile.TomlError) as caught:
        tomlfile.loads("a = 1\nb = ?\n")
    assert (caught.value.line, caught.value.column) == (2, 5)


def test_settings_scenarios_and_rigs_read_through_it(monkeypatch, tmp_path):
    """Every reader of TOML goes through tomlfile.loads: one set of guards, one fallback."""
    from mercmac import config
    from mercmac.rig.load import parse_rig
    from mercmac.sim import scenario
    from mercmac.source import Source

    seen = []
    real = tomlfile.loads
    monkeypatch.setattr(tomlfile, "loads", lambda text: seen.append(text) or real(text))
    (tmp_path / "mercmac.toml").write_text('target = "C-863"\n', encoding="utf-8")
    monkeypatch.setattr(config, "_FOUND", {})
    assert config.settings_for(str(tmp_path / "a.mcm")).target == "C-863"
    (tmp_path / "s.toml").write_text('until = "1s"\n', encoding="utf-8")
    assert scenario.load(str(tmp_path / "s.toml")).until_ms == 1000
    parse_rig(Source("r.rig.toml", 'name = "r"\n'))
    assert seen == ['target = "C-863"\n', 'until = "1s"\n', 'name = "r"\n']


def test_check_of_a_program_does_not_import_tomllib(tmp_path):
    """`check` starts quickly (benchmarks/check_latency.py): no TOML parser for .mcm files
    (in a folder without settings)."""
    import subprocess

    code = ("import sys; from click.testing import CliRunner; from mercmac.cli import main; "
            "import mercmac.tomlfile, mercmac.config; "
            "CliRunner().invoke(main, ['check', '-'], input='[MC00] EM1\\n'); "
            "print(sorted(m for m in ('tomllib', 'tomli') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, cwd=tmp_path, env={**os.environ, "PYTHONPATH": _root()})
    assert out.stdout.strip() == "[]"


def _root() -> str:
    import mercmac

    return os.path.dirname(os.path.dirname(mercmac.__file__))
