"""`decompile FILE` decompiles what the file holds.

The flash history names what a *controller* holds; a file that was flashed once (the
program itself, or a raw pull of it) is still read for its own macros, not answered with
the recorded source. `--port` keeps using the history (tests/cli/test_inspect_cli.py,
tests/upload/test_hostile_history.py).
"""
from __future__ import annotations

import os
import subprocess
import sys

from helpers.cli import cli
from helpers.paths import FOUR_MODES
from mercmac.compiler import compile_file
from mercmac.upload import history


def _flashed(path, port: str = "/dev/ttyUSB0") -> None:
    """The record `flash` leaves after writing PATH's build to a controller."""
    program = compile_file(str(path)).program
    history.record(port=port, address=0, model="C-863", firmware="2.30", file=str(path),
                   source=path.read_text(), build=program.md_lines())


def _macros(path) -> dict[int, str]:
    compiled = compile_file(str(path))
    assert compiled.program is not None and not compiled.report.has_errors
    return {m.slot: m.line for m in compiled.program.macros.values()}


def _raw_pull(path, to) -> None:
    """PATH's build as `pull --raw` writes it: `[MCnn]` blocks, nothing else."""
    lines = _macros(path)
    to.write_text("target C-863\n" + "".join(f"[MC{s:02d}] {t}\n" for s, t in sorted(lines.items())))


def test_a_flashed_program_file_is_decompiled_not_recalled(tmp_path, data_dir):
    program = tmp_path / "four-modes.mcm"
    program.write_text(FOUR_MODES.read_text())
    _flashed(program)
    result = cli("decompile", program, "-o", tmp_path / "out.mcm")
    assert result.exit_code == 0, result.output
    out = (tmp_path / "out.mcm").read_text()
    assert out != program.read_text()  # the recorded source, given back unchanged before
    assert out.startswith(f"// Read from {program}.\n// Decompiled by mercmac")
    assert "holds four-modes.mcm" not in result.output
    assert _macros(tmp_path / "out.mcm") == _macros(program)


def test_a_flashed_raw_file_is_decompiled_to_a_program(tmp_path, data_dir):
    raw = tmp_path / "backup.mcm"
    _raw_pull(FOUR_MODES, raw)
    _flashed(raw)  # a raw file flashed as it is: its record's source is the raw file
    result = cli("decompile", raw)
    assert result.exit_code == 0, result.output
    assert result.stdout != raw.read_text()
    assert "every 20ms {" in result.stdout and "[MC02]" not in result.stdout
    assert "holds backup.mcm" not in result.output
    back = tmp_path / "back.mcm"
    back.write_text(result.stdout)
    assert _macros(back) == _macros(raw)


def test_the_history_of_another_file_with_that_build_is_not_used(tmp_path, data_dir):
    """A pull of a flashed program: the record names the program, the pull holds macros."""
    program = tmp_path / "four-modes.mcm"
    program.write_text(FOUR_MODES.read_text())
    _flashed(program)
    raw = tmp_path / "raw.mcm"
    _raw_pull(program, raw)
    shown = subprocess.run([sys.executable, "-m", "mercmac", "decompile", str(raw)],
                           capture_output=True, text=True, timeout=120,
                           env={**os.environ, "MERCMAC_DATA_DIR": str(data_dir)})
    assert shown.returncode == 0, shown.stderr
    assert shown.stdout != program.read_text() and "// Decompiled by mercmac" in shown.stdout
    assert "holds" not in shown.stderr and "four-modes.mcm, flashed" not in shown.stderr
