"""`check` of a file whose name is not UTF-8, or holds control characters:
every output format says it without a crash; SARIF percent-encodes the name's bytes
(RFC 3986, as SARIF §3.4.3 asks), text and concise escape it as they escape control
characters."""
from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from helpers.cli import cli

pytestmark = pytest.mark.skipif(sys.platform in ("win32", "darwin"),
                                reason="names that are not UTF-8 need a POSIX file system")
NAME = b"b\xff\x1b[31m x.mcm"  # a byte that is not UTF-8, an ESC sequence and a space
FORMATS = ["text", "concise", "json", "github", "sarif"]


@pytest.fixture
def folder(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("NO_COLOR", "1")
    with open(os.fsencode(tmp_path) + b"/" + NAME, "wb") as f:
        f.write(b"[MC00] EM5,WS\n")  # a warning and an info
    return tmp_path


@pytest.mark.parametrize("fmt", FORMATS)
def test_every_format_takes_the_name(folder, fmt):
    result = cli("check", "--output-format", fmt, os.fsdecode(NAME), catch=True)
    assert result.exception is None and result.exit_code == 0, result.exception
    assert "\x1b" not in result.output or fmt in ("json", "github")  # JSON escapes it itself


def _uris(*args) -> set[str]:
    result = cli("check", "--output-format", "sarif", *args, catch=True)
    return {r["locations"][0]["physicalLocation"]["artifactLocation"]["uri"]
            for r in json.loads(result.output)["runs"][0]["results"]}


def test_sarif_uri_is_the_percent_encoded_bytes(folder):
    assert _uris(os.fsdecode(NAME)) == {"b%FF%1B%5B31m%20x.mcm"}  # relative stays relative
    [uri] = _uris(os.path.join(os.fsdecode(os.fsencode(folder)), os.fsdecode(NAME)))
    assert uri.startswith("file:///") and uri.endswith("/b%FF%1B%5B31m%20x.mcm")


@pytest.mark.parametrize("fmt", ["text", "concise"])
def test_text_escapes_the_name(folder, fmt):
    result = cli("check", "--output-format", fmt, os.fsdecode(NAME))
    assert "b\\xff\\x1b[31m x.mcm:1:8:" in result.output


@pytest.mark.parametrize("fmt", FORMATS)
def test_a_real_process_writes_every_format(folder, fmt):
    """Through a real standard output (UTF-8, strict), not CliRunner's buffer."""
    env = dict(os.environ, NO_COLOR="1", PYTHONIOENCODING="utf-8")
    done = subprocess.run([sys.executable, "-m", "mercmac", "check", "--output-format", fmt,
                           NAME], cwd=folder, capture_output=True, timeout=120, env=env)
    assert done.returncode == 0, done.stderr.decode(errors="replace")
    assert b"Traceback" not in done.stderr and done.stdout
