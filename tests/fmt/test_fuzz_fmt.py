"""`mercmac fmt` on mutated files: byte-exact or refused, never other bytes.

The examples of examples/macros/ are re-encoded (UTF-8 with and without a BOM, UTF-16 and
UTF-32 in both byte orders, Windows-1252), their line ends mixed (LF, CRLF, CR) and random
bytes, line ends and byte-order marks spliced into the bytes. Each file goes through the
real `mercmac fmt` command. It either ends with exit 0 and the file holds exactly what
formatting those bytes gives - the same encoding, BOM and comments, no U+FFFD that was not
there, the same build, and formatting it again changes nothing - or it ends with exit 2
and the file is untouched. Never a traceback, never a temporary file left behind.

`MERCMAC_FUZZ_EXAMPLES=5000 pytest tests/fmt/test_fuzz_fmt.py` searches harder.
"""
from __future__ import annotations

import os
import re

from click.testing import CliRunner
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from helpers.budgets import fuzz_budget
from helpers.compiling import compile_text
from helpers.files import leftovers
from helpers.paths import EXAMPLE_FILES
from mercmac.cli import main
from mercmac.fmt import format_text, load
from mercmac.source import decode

BUDGET = settings(
    max_examples=fuzz_budget(200),
    deadline=None,
    derandomize="MERCMAC_FUZZ_EXAMPLES" not in os.environ,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                           HealthCheck.function_scoped_fixture],
)
EXAMPLE_TEXTS = [p.read_bytes().decode("utf-8") for p in EXAMPLE_FILES]
ENCODINGS = st.sampled_from([
    ("utf-8", b""), ("utf-8", b"\xef\xbb\xbf"), ("cp1252", b""),
    ("utf-16-le", b"\xff\xfe"), ("utf-16-be", b"\xfe\xff"), ("utf-16-le", b""),
    ("utf-32-le", b"\xff\xfe\x00\x00"), ("utf-32-be", b"\x00\x00\xfe\xff"),
])
SPLICES = st.one_of(
    st.binary(min_size=1, max_size=3),  # any bytes: half a character, 0x99, 0x81, NUL, ...
    st.sampled_from([b"\r", b"\n", b"\r\n", b"\xef\xbb\xbf", b"\xff\xfe", b"\xfe\xff",
                     b"\x00\xd8", b"\xd8\x00", b"\x99", b"\x81", b"\xc3", b"\x0c", b"\x85"]),
    st.sampled_from(["\u2122", "\u00e9", "\u2028", "\ufeff", "\U0001f600"]).map(
        lambda c: c.encode("utf-8")),
)
COMMENT = re.compile(r"//[^\r\n]*")
# The test's own view of byte-order marks (longest first) and of U+FFFD in each encoding.
BOMS = [(b"\xff\xfe\x00\x00", "utf-32-le"), (b"\x00\x00\xfe\xff", "utf-32-be"),
        (b"\xef\xbb\xbf", "utf-8"), (b"\xff\xfe", "utf-16-le"), (b"\xfe\xff", "utf-16-be")]
REPLACEMENT = ["\ufffd".encode(c) for c in ("utf-8", "utf-16-le", "utf-16-be", "utf-32-le",
                                             "utf-32-be")]


@st.composite
def mutated_files(draw) -> bytes:
    text = draw(st.sampled_from(EXAMPLE_TEXTS))
    ends = draw(st.lists(st.sampled_from(["\n", "\r\n", "\r"]), min_size=1, max_size=3))
    lines = text.split("\n")
    text = "".join(line + ends[i % len(ends)] for i, line in enumerate(lines[:-1])) + lines[-1]
    codec, bom = draw(ENCODINGS)
    data = bom + text.encode(codec, errors="replace")
    for _ in range(draw(st.integers(0, 4))):
        at = draw(st.integers(0, len(data)))
        cut = draw(st.integers(0, 2))
        data = data[:at] + draw(SPLICES) + data[at + cut:]
    return data


def build(text: str):
    """What formatting must never change: the MD lines and the rules found."""
    result = compile_text(text)
    md = result.program.md_lines() if result.program is not None else None
    return md, sorted(d.rule.name for d in result.report.items)


def comments(text: str) -> list[str]:
    return [c.rstrip() for c in COMMENT.findall(text)]


@BUDGET
@given(mutated_files())
def test_fmt_is_byte_exact_or_refuses(tmp_path_factory, data):
    folder = tmp_path_factory.mktemp("fuzz")
    path = folder / "a.mcm"
    path.write_bytes(data)
    result = CliRunner().invoke(main, ["fmt", str(path)])
    assert result.exception is None or isinstance(result.exception, SystemExit), \
        result.exception  # no traceback
    assert result.exit_code in (0, 2), result.output
    assert leftovers(folder) == []
    after = path.read_bytes()
    event(f"exit {result.exit_code}")
    if result.exit_code == 2:
        assert after == data, "a refused file was changed"
        return
    text, encoding = load(data)  # what fmt would produce from these bytes, to the byte
    assert after == encoding.write(format_text(text))
    bom, codec = next(((b, c) for b, c in BOMS if data.startswith(b)), (b"", None))
    assert after.startswith(bom), "the byte-order mark changed"
    if codec is not None:  # what the BOM says the file is: both read exactly, or exit 2
        data[len(bom):].decode(codec)  # UnicodeDecodeError: a byte was replaced, not refused
        after[len(bom):].decode(codec)
    assert all(after.count(r) <= data.count(r) for r in REPLACEMENT), "U+FFFD written"
    assert comments(decode(after)) == comments(decode(data))
    assert build(decode(after)) == build(decode(data))
    again = CliRunner().invoke(main, ["fmt", "--check", str(path)])
    assert again.exit_code == 0, again.output
