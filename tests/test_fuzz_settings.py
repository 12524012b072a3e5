"""Hostile settings files through the real `mercmac check`: random TOML-ish text,
deep nesting, wrong types, byte-order marks and binary as `mercmac.toml` or as
`pyproject.toml`. Whatever the file holds, `check` ends with 0, 1 or 2; a 2 names the
settings file; never a traceback."""
from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from helpers.budgets import budget
from helpers.cli import cli
from mercmac import config

NAMES = ["mercmac.toml", "pyproject.toml"]
# Pieces a settings file is made of, and a few it should not hold.
WORDS = ["[tool.mercmac]", "[[tool.mercmac]]", "[tool]", "tool", "mercmac", "tool.mercmac",
         "select", "ignore", "target", "=", " = ", "[", "]", "{", "}", ",", ".", "\"", "'",
         '"""', "'''", "\n", "\r\n", "\r", "#", " ", "\t", "MM011", '"MM012"', '"nested-call"',
         '"C-863"', '"C-999"', '""', "[]", "{}", "1", "-0", "1e999", "nan", "true",
         "1979-05-27T07:32:00Z", "1979-02-30", "0x", "\\u0000", "\\", "\ufeff", "\x00", "\x1b[2J",
         "\u202e", "\udcff"]
VALUES = st.recursive(
    st.one_of(st.none(), st.booleans(), st.integers(), st.floats(), st.text(max_size=20)),
    lambda inner: st.one_of(st.lists(inner, max_size=4),
                            st.dictionaries(st.text(max_size=8), inner, max_size=4)),
    max_leaves=12)
KEYS = st.sampled_from(["select", "ignore", "target", "tool", "mercmac", "other"])


def _toml_value(value) -> str:
    """VALUE written as TOML (None as a string: TOML has no null)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(value)  # inf and nan are TOML too
    if isinstance(value, list):
        return "[" + ", ".join(map(_toml_value, value)) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f'"{k}" = {_toml_value(v)}' for k, v in value.items()) + "}"
    text = "None" if value is None else value
    return '"' + text.encode("unicode_escape").decode("ascii").replace('"', '\\"') + '"'


TYPED = st.builds(lambda table, pairs: table + "".join(f"{k} = {_toml_value(v)}\n"
                                                     for k, v in pairs),
                  st.sampled_from(["", "[tool.mercmac]\n", "[tool]\n", "[[tool.mercmac]]\n"]),
                  st.lists(st.tuples(KEYS, VALUES), max_size=4))
NESTED = st.builds(lambda key, open_, close, n: f"{key} = {open_ * n}{close * n}\n",
                   st.sampled_from(["a", "select", "tool.mercmac.select"]),
                   st.sampled_from(["[", "{b = "]), st.sampled_from(["]", "}"]),
                   st.integers(1, 6000)).map(lambda t: t.replace("{b = }", "{b = 1}"))
TEXT = st.lists(st.sampled_from(WORDS), max_size=40).map("".join)
DOCUMENTS = st.one_of(
    TEXT.map(lambda t: t.encode("utf-8", "surrogateescape")),
    TYPED.map(str.encode),
    NESTED.map(str.encode),
    st.tuples(st.sampled_from([b"\xef\xbb\xbf", b"\xff\xfe", b"\xfe\xff", b"\x00\x00\xfe\xff"]),
              TYPED.map(str.encode)).map(b"".join),
    st.binary(max_size=200),
)


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    """One folder for every example: a.mcm, and the settings file each example writes."""
    path = tmp_path_factory.mktemp("settings")
    (path / "a.mcm").write_text("[MC00] EM5,WS\n", encoding="utf-8")
    return path


@settings(max_examples=budget(300), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(name=st.sampled_from(NAMES), data=DOCUMENTS)
@example(name="pyproject.toml", data=b'tool = "x"\nnote = """\n[tool.mercmac]\n"""\n')
@example(name="mercmac.toml", data=b"a = " + b"[" * 5000 + b"]" * 5000 + b"\n")
@example(name="mercmac.toml", data=b'\xef\xbb\xbfselect = ["MM012"]\n')
@example(name="mercmac.toml", data=b"select = []\n")
@example(name="pyproject.toml", data=b'[[tool.mercmac]]\nselect = ["MM012"]\n')
def test_any_settings_file_ends_in_0_1_or_2_naming_the_file(folder, name, data):
    for other in NAMES:
        (folder / other).unlink(missing_ok=True)
    (folder / name).write_bytes(data)
    config._FOUND.clear()
    result = cli("check", "--format", "json", folder / "a.mcm", catch=True, env={"NO_COLOR": "1"})
    assert result.exception is None or isinstance(result.exception, SystemExit), \
        f"{type(result.exception).__name__}: {result.exception}"
    assert result.exit_code in (0, 1, 2), result.output
    assert "Traceback" not in result.output
    if result.exit_code == 2:
        assert name in result.output, result.output
        assert "\x1b" not in result.output and "\udcff" not in result.output  # escaped
