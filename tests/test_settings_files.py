"""Settings files under hostile or mistaken content: an empty
selection, the table in other TOML spellings, a byte-order mark, a file that cannot be
read or is no regular file - each said with the file's name, exit 2, never a traceback."""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

from helpers.cli import as_nobody, cli
from mercmac import config

WARNS = "[MC00] EM5,WS\n"  # undefined-macro (MM012, warning) and default-argument (info)
ROOT = os.geteuid() == 0 if hasattr(os, "geteuid") else False


@pytest.fixture(autouse=True)
def _fresh_settings(monkeypatch, tmp_path):
    monkeypatch.setattr(config, "_FOUND", {})
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("NO_COLOR", "1")
    (tmp_path / "a.mcm").write_text(WARNS, encoding="utf-8")


def _check(*args):
    """`check --format json ARGS a.mcm`, exceptions kept in the result (not raised)."""
    return cli("check", "--format", "json", *args, "a.mcm", catch=True)


def _rules(result) -> list[str]:
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exception
    return [d["rule"] for d in json.loads(result.output)["diagnostics"]]


def _refused(result, *words) -> None:
    """Exit 2 with a message holding WORDS, and no traceback."""
    assert isinstance(result.exception, SystemExit), repr(result.exception)
    assert result.exit_code == 2, result.output
    for word in words:
        assert word in result.output, (word, result.output)


# -- item 15: an empty selection --------------------------------------------------------------

@pytest.mark.parametrize("option", ["", ",,,", " , "])
def test_an_empty_select_option_is_refused(option):
    _refused(_check("--select", option), "--select", "no rule")


@pytest.mark.parametrize("setting", ["select = []", 'select = [""]', 'select = ""',
                                     'select = [",", " "]'])
def test_an_empty_select_setting_is_refused(tmp_path, setting):
    (tmp_path / "mercmac.toml").write_text(setting + "\n", encoding="utf-8")
    _refused(_check(), "mercmac.toml", "no rule")


def test_an_empty_ignore_still_means_ignore_nothing(tmp_path):
    (tmp_path / "mercmac.toml").write_text("ignore = []\n", encoding="utf-8")
    assert _rules(_check()) == ["undefined-macro", "default-argument"]


# -- item 15: the table in other spellings -----------------------------------------------------

@pytest.mark.parametrize("text", [
    'tool = {mercmac = {select = ["MM012"]}}\n',
    '[tool]\nmercmac = {select = ["MM012"]}\n',
    '[tool]\nmercmac.select = ["MM012"]\n',
    '[tool."mercmac"]\nselect = ["MM012"]\n',
])
def test_the_table_is_read_in_every_toml_spelling(tmp_path, text):
    (tmp_path / "pyproject.toml").write_text(text + '\n[project]\nname = "x"\n', encoding="utf-8")
    assert _rules(_check()) == ["undefined-macro"]


def test_an_array_of_tables_is_refused(tmp_path):
    (tmp_path / "pyproject.toml").write_text('[[tool.mercmac]]\nselect = ["MM012"]\n',
                                             encoding="utf-8")
    _refused(_check(), "pyproject.toml", "[[tool.mercmac]]", "array of tables")


def test_a_tool_table_in_mercmac_toml_is_explained(tmp_path):
    (tmp_path / "mercmac.toml").write_text('[tool.mercmac]\nselect = ["MM012"]\n',
                                           encoding="utf-8")
    _refused(_check(), "mercmac.toml", "top level")


# -- item 13: wrong types, deep nesting --------------------------------------------------------

@pytest.mark.parametrize("text, words", [
    # `[tool.mercmac]` stands in a string: the document's `tool` is a string
    ('tool = "x"\nnote = """\n[tool.mercmac]\n"""\n', ["pyproject.toml", "tool", "a string"]),
    ('[tool]\nmercmac = 3\n', ["pyproject.toml", "tool.mercmac", "an integer"]),
    ('[tool]\nmercmac = "MM011"\n', ["pyproject.toml", "tool.mercmac", "a string"]),
])
def test_a_tool_or_table_of_the_wrong_type_is_said(tmp_path, text, words):
    (tmp_path / "pyproject.toml").write_text(text, encoding="utf-8")
    _refused(_check(), *words)


@pytest.mark.parametrize("name, text", [
    ("mercmac.toml", "a = " + "[" * 5000 + "]" * 5000 + "\n"),
    ("mercmac.toml", "a = " + "{b = " * 3000 + "1" + "}" * 3000 + "\n"),
    ("pyproject.toml", "[tool.mercmac]\nselect = " + "[" * 5000 + "]" * 5000 + "\n"),
])
def test_deep_nesting_is_said_not_a_recursion_error(tmp_path, name, text):
    (tmp_path / name).write_text(text, encoding="utf-8")
    _refused(_check(), name, "nested too deeply")


# -- item 15: byte-order marks ----------------------------------------------------------------

def test_a_utf8_byte_order_mark_is_read_past(tmp_path):
    """As ruff and Cargo read one (TOML 1.0 does not forbid it; Windows editors write it)."""
    (tmp_path / "mercmac.toml").write_bytes(b'\xef\xbb\xbfselect = ["MM012"]\n')
    assert _rules(_check()) == ["undefined-macro"]
    (tmp_path / "mercmac.toml").unlink()
    config._FOUND.clear()
    (tmp_path / "pyproject.toml").write_bytes(b'\xef\xbb\xbf[tool.mercmac]\nignore = ["MM012"]\n')
    assert _rules(_check()) == ["default-argument"]


@pytest.mark.parametrize("data", [
    '\ufeffselect = ["MM012"]\n'.encode("utf-16-le"),
    '\ufeffselect = ["MM012"]\n'.encode("utf-16-be"),
])
def test_a_utf16_file_with_its_mark_is_read(tmp_path, data):
    """Settings, scenarios and rigs are read by one reader
    (mercmac.tomlfile), and a scenario in Notepad's "Unicode" was always read."""
    (tmp_path / "mercmac.toml").write_bytes(data)
    assert _rules(_check()) == ["undefined-macro"]


def test_utf16_that_does_not_read_is_named_as_such(tmp_path):
    (tmp_path / "mercmac.toml").write_bytes(b"\xff\xfe" + "select = 1".encode("utf-16-le")
                                            + b"\x00\xd8")  # a lone surrogate
    _refused(_check(), "mercmac.toml", "UTF-16 byte-order mark", "TOML files are UTF-8")


def test_lone_cr_line_ends_are_read(tmp_path):
    """Settings are read by the one TOML reader (mercmac.tomlfile), which
    reads LF, CRLF and lone CR line ends alike, as every other file (docs/cli.md)."""
    (tmp_path / "mercmac.toml").write_bytes(b'target = "C-863"\rselect = ["MM012"]\r')
    assert _rules(_check()) == ["undefined-macro"]


def test_a_number_of_thousands_of_digits_is_said(tmp_path):
    (tmp_path / "mercmac.toml").write_text("a = 1\nb = " + "9" * 5000 + "\n", encoding="utf-8")
    _refused(_check(), "mercmac.toml", "too many digits", "line 2, column 5")


def test_a_byte_that_is_not_utf8_is_located(tmp_path):
    (tmp_path / "mercmac.toml").write_bytes(b'ignore = ["MM012"]\n# \x99 MMCRun\n')
    _refused(_check(), "mercmac.toml", "0x99", "line 2", "not UTF-8")


# -- items 13 and 15: files that are not regular or cannot be read ------------------------------

@pytest.mark.parametrize("name", ["mercmac.toml", "pyproject.toml"])
def test_a_fifo_settings_file_is_named_not_waited_on(tmp_path, name):
    os.mkfifo(tmp_path / name)
    _refused(_check(), name, "FIFO")


@pytest.mark.parametrize("name", ["mercmac.toml", "pyproject.toml"])
def test_a_link_to_a_device_is_named_not_read(tmp_path, name):
    (tmp_path / name).symlink_to("/dev/zero")
    _refused(_check(), name, "character device")


def test_a_settings_file_over_the_cap_is_refused_unread(tmp_path):
    from mercmac.source import MAX_BYTES

    with open(tmp_path / "pyproject.toml", "wb") as f:
        f.truncate(MAX_BYTES + 1)  # sparse: nothing is written, nothing must be read
    _refused(_check(), "pyproject.toml", "larger than")


@pytest.mark.skipif(os.name != "posix", reason="file modes")
def test_an_unreadable_settings_file_is_worded():
    """`cannot read the settings in PATH: Permission denied`, not `[Errno 13] ...`. Run as
    a process of its own, and as `nobody` when the tests run as root (root reads anything)."""
    folder = Path(tempfile.mkdtemp())
    try:
        folder.chmod(0o755)
        (folder / "a.mcm").write_text(WARNS, encoding="utf-8")
        (folder / "a.mcm").chmod(0o644)
        (folder / "mercmac.toml").write_text('select = ["MM012"]\n', encoding="utf-8")
        (folder / "mercmac.toml").chmod(0)
        result = _as_user(["check", str(folder / "a.mcm")])
        assert result.returncode == 2, result.stderr
        assert f"cannot read the settings in {folder / 'mercmac.toml'}: Permission denied" \
            in result.stderr
        assert "Errno" not in result.stderr and "Traceback" not in result.stderr
    finally:
        (folder / "mercmac.toml").chmod(0o644)
        for p in folder.iterdir():
            p.unlink()
        folder.rmdir()


def _as_user(args: list[str]) -> subprocess.CompletedProcess:
    """`mercmac ARGS` in a process of its own, as `nobody` (uid 65534) when we are root."""
    prefix = as_nobody()
    env = dict(os.environ, NO_COLOR="1")
    return subprocess.run([*prefix, sys.executable, "-m", "mercmac", *args], capture_output=True,
                          text=True, timeout=120, env=env, cwd="/")
