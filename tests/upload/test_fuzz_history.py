"""Hostile flash history records through `history`, `pull` and `decompile --port`.

Each example fills a fresh `MERCMAC_DATA_DIR/history` with one record a real flash wrote,
records that are fine although unusual (other UTC offsets, no model, no backup, odd file
names), and hostile files: fields of the wrong type or null, bad times, files that are no
JSON object, deep nesting, binary, too big, FIFOs, links to /dev/zero, folders. The
commands must never trace or hang, list every good record, and name each bad file in
exactly one warning (and no good one).

The budget is fixed for CI; `MERCMAC_FUZZ_EXAMPLES=500 pytest tests/upload/test_fuzz_history.py`
searches harder.
"""
from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path

import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mercmac.cli import main
from helpers.budgets import fuzz_budget
from helpers.cli import KNOWN_EXITS, hang_guard
from helpers.emulator import FAST, serve_clocked
from helpers.history import PROGRAM

pytestmark = pytest.mark.skipif(not (hasattr(os, "openpty") and hasattr(os, "mkfifo")),
                                reason="needs pseudo-terminals and FIFOs")

EXAMPLES = fuzz_budget(40)


def _budget(n: int):
    return settings(max_examples=n, deadline=None, suppress_health_check=list(HealthCheck),
                    derandomize="MERCMAC_FUZZ_EXAMPLES" not in os.environ)


# The record's fields as a flash writes them: which may be null, which are whole numbers
# and lists of text; every other is text (the oracle, written apart from the reader).
NULLABLE, WHOLE, LINES = {"model", "backup"}, {"address"}, {"build"}


def _fits(field: str, value) -> bool:
    if value is None:
        return field in NULLABLE
    if field in WHOLE:
        return type(value) is int
    if field in LINES:
        return isinstance(value, list) and all(isinstance(x, str) for x in value)
    return isinstance(value, str)


JSON_VALUES = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False) | st.text(max_size=8),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=4), inner,
                                                                max_size=3), max_leaves=6)
BAD_TIMES = st.sampled_from(["2026-01-01T10:00:00", "2026-01-01", "yesterday", "",
                             "2026-13-40T00:00:00+00:00", "10:00:00+00:00", "\x1b[2J",
                             "2026-01-01T10:00:00+25:00"])
GOOD_TIMES = st.sampled_from(["2026-01-01T10:00:00+05:30", "2025-06-30T23:59:59-07:00",
                              "2026-02-03T04:05:06Z", "2026-02-03T04:05:06.123456+00:00"])


@st.composite
def bad_record(draw, good: dict):
    """(kind, how to make the file) of a file that is no record."""
    kind = draw(st.sampled_from(["type", "surrogate", "time", "missing", "unknown", "format",
                                 "nested", "not-object", "binary", "huge", "fifo", "zero",
                                 "folder", "dangling"]))
    data = dict(good)
    if kind == "type":
        field = draw(st.sampled_from(sorted(set(good) - {"format"})))
        data[field] = draw(JSON_VALUES.filter(lambda v: not _fits(field, v)))
    elif kind == "surrogate":  # JSON's "\ud800": no file or terminal can hold it
        field = draw(st.sampled_from(["time", "port", "firmware", "file", "source", "model"]))
        data[field] = str(data[field]) + chr(draw(st.integers(0xD800, 0xDBFF)))
    elif kind == "time":
        data["time"] = draw(BAD_TIMES)
    elif kind == "missing":
        del data[draw(st.sampled_from(sorted(set(good) - {"format", "backup"})))]
    elif kind == "unknown":
        data[draw(st.text(min_size=1, max_size=8).filter(lambda k: k not in good))] = 1
    elif kind == "format":
        data["format"] = draw(JSON_VALUES.filter(lambda v: v != 1 or type(v) is not int))
    elif kind == "nested":
        depth = draw(st.integers(5_000, 250_000))
        return kind, lambda p: p.write_text(draw(st.sampled_from(["[", '{"a":'])) * depth)
    elif kind == "not-object":
        value = draw(JSON_VALUES.filter(lambda v: not isinstance(v, dict)))
        return kind, lambda p: p.write_text(json.dumps(value))
    elif kind == "binary":
        blob = draw(st.binary(min_size=1, max_size=64))
        return kind, lambda p: p.write_bytes(b"\xff" + blob)
    elif kind == "huge":
        data["source"] = "// " + "x" * 1_100_000
    elif kind == "fifo":
        return kind, lambda p: os.mkfifo(p)
    elif kind == "zero":
        return kind, lambda p: p.symlink_to("/dev/zero")
    elif kind == "folder":
        return kind, lambda p: p.mkdir()
    else:
        return kind, lambda p: p.symlink_to(p.parent / "nowhere" / "x.json")
    return kind, lambda p: p.write_text(json.dumps(data))


@st.composite
def unusual_record(draw, good: dict) -> dict:
    """A record that is fine: listed, and never warned about."""
    data = dict(good, time=draw(GOOD_TIMES))
    if draw(st.booleans()):
        data["model"] = None
    if draw(st.booleans()):
        data.pop("backup")
    if draw(st.booleans()):  # any name, a byte that is not UTF-8 included (os.fsdecode)
        name = draw(st.text(min_size=1, max_size=12) | st.binary(min_size=1, max_size=12).map(
            lambda b: os.fsdecode(b.replace(b"/", b"_").replace(b"\0", b"_"))))
        data["file"] = "/tmp/" + name + ".mcm"
    return data


@st.composite
def history_folders(draw, good: dict):
    """(bad file names, good record count, how to fill a history folder)."""
    bad = draw(st.lists(bad_record(good), min_size=1, max_size=4))
    fine = draw(st.lists(unusual_record(good), max_size=2))

    def fill(folder: Path) -> None:
        folder.mkdir(parents=True)
        (folder / "good.json").write_text(json.dumps(good))
        for n, data in enumerate(fine):
            (folder / f"fine-{n}.json").write_text(json.dumps(data))
        for n, (kind, make) in enumerate(bad):
            make(folder / f"bad-{n}-{kind}.json")

    return [f"bad-{n}-{kind}.json" for n, (kind, _) in enumerate(bad)], 1 + len(fine), fill


@pytest.fixture(scope="module")
def flashed(tmp_path_factory):
    """(emulator holding PROGRAM, the record its flash wrote) for the whole module."""
    home = tmp_path_factory.mktemp("flashed")
    (home / "prog.mcm").write_text(PROGRAM)
    with serve_clocked() as (server, vc):  # the silences of pull and decompile: fast
        done = _run(["flash", server.path, str(home / "prog.mcm"), "--backup",
                     str(home / "b.mcm"), *FAST], home / "data")
        assert done.exit_code == 0, done.output
        (record,) = (home / "data" / "history").glob("*.json")
        yield server, json.loads(record.read_text())


def _run(args: list[str], data_dir: Path):
    with hang_guard():
        result = CliRunner().invoke(main, args, env={"MERCMAC_DATA_DIR": str(data_dir),
                                                     "NO_COLOR": "1"})
    assert isinstance(result.exception, (SystemExit, type(None))), (
        f"traceback for mercmac {' '.join(args)}: {result.exception!r}\n{result.output[-2000:]}")
    assert result.exit_code in KNOWN_EXITS, (args, result.output[-2000:])
    return result


def _warned(output: str, bad: list[str]) -> None:
    """Each bad file is named in exactly one warning, and no other file in any."""
    warnings = [line for line in output.splitlines() if line.startswith("warning:")]
    for name in bad:
        assert sum(name in line for line in warnings) == 1, (name, warnings)
    assert len(warnings) == len(bad), warnings


def _in_a_folder(case, check) -> None:
    bad, good, fill = case
    with tempfile.TemporaryDirectory() as home:
        fill(Path(home) / "history")
        check(Path(home), bad, good)


@_budget(EXAMPLES)
@given(data=st.data())
def test_history_lists_the_good_and_names_each_bad_file_once(flashed, data):
    server, record = flashed

    def check(home: Path, bad: list[str], good: int) -> None:
        table = _run(["history"], home)
        assert table.exit_code == 0
        assert len(table.stdout.splitlines()) == 1 + good and "\x1b" not in table.stdout
        _warned(table.stderr, bad)
        as_json = _run(["history", "--format", "json"], home)
        assert as_json.exit_code == 0 and len(json.loads(as_json.stdout)["flashes"]) == good
        _warned(as_json.stderr, bad)

    _in_a_folder(data.draw(history_folders(record)), check)


@pytest.mark.slow
@_budget(max(EXAMPLES // 4, 5))
@given(data=st.data())
def test_pull_and_decompile_give_back_the_source_past_bad_files(flashed, data):
    server, record = flashed

    def check(home: Path, bad: list[str], good: int) -> None:
        for args in (["pull", server.path, *FAST], ["decompile", "--port", server.path, *FAST]):
            done = _run(args, home)
            assert done.exit_code == 0, done.output
            assert done.stdout == PROGRAM
            _warned(done.stderr, bad)

    _in_a_folder(data.draw(history_folders(record)), check)
