"""Shared test helpers: compile text, run the CLI in-process, write files, find the examples."""
from __future__ import annotations

import signal
from pathlib import Path

import pytest
from click.testing import CliRunner

from mercmac.compiler import compile_source
from mercmac.source import Source

# A suite started as a background job (`pytest &`) or by some CI runners inherits SIGINT as
# ignored, and so would every process it starts: the Ctrl-C tests could not interrupt the
# mercmac they run. This process takes Python's own handler instead; exec resets a handled
# signal to the default in each child (an ignored one would stay ignored).
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples" / "macros"


def compile_text(text: str, target: str | None = None):
    """Compile a snippet as file 'test.mcm'."""
    return compile_source(Source("test.mcm", text), target)


def rules(text: str, target: str | None = None) -> list[str]:
    """The rule names a snippet triggers, in report order."""
    return [d.rule.name for d in compile_text(text, target).report.sorted()]


def program_of(text: str, target: str | None = None):
    """The lowered program of a snippet that must compile without errors."""
    result = compile_text(text, target)
    assert result.program is not None and not result.report.has_errors, \
        [d.message for d in result.report.items]
    return result.program


def cli(*args, catch: bool = False, **kw):
    """Run `mercmac ARGS...` in-process through the real click group; with `catch`, an
    exception is kept in the result (so a traceback shows as one) instead of raised."""
    from mercmac.cli import main

    return CliRunner().invoke(main, [str(a) for a in args], catch_exceptions=catch, **kw)


def sim(*args):
    """`mercmac sim ARGS...` in-process; an exception is kept in the result."""
    return cli("sim", *args, catch=True)


def leftovers(folder: Path) -> list[Path]:
    """The temporary files an interrupted whole-or-nothing write would leave in `folder`."""
    from mercmac import outfile

    return sorted(folder.glob(f"{outfile.TEMP_PREFIX}*{outfile.TEMP_SUFFIX}"))


@pytest.fixture
def write(tmp_path):
    """`write(text_or_bytes, name="p.mcm")`: a new file in tmp_path, as a str path."""
    def make(text: str | bytes, name: str = "p.mcm") -> str:
        path = tmp_path / name
        if isinstance(text, bytes):
            path.write_bytes(text)
        else:
            path.write_text(text, encoding="utf-8")
        return str(path)
    return make


@pytest.fixture
def program_file(tmp_path, request):
    """The test module's PROGRAM written to tmp_path/prog.mcm."""
    path = tmp_path / "prog.mcm"
    path.write_text(request.module.PROGRAM)
    return path


@pytest.fixture
def examples_dir() -> Path:
    return EXAMPLES


@pytest.fixture(autouse=True)
def _private_data_dir(tmp_path_factory, monkeypatch):
    """Backups and flash history go to a fresh folder, never the user's data directory."""
    monkeypatch.delenv("MERCMAC_DATA_DIR", raising=False)
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path_factory.mktemp("xdg-data")))


def observed(record) -> dict:
    """What a simulation run recorded, as plain data to compare two runs (fast-forward on/off)."""
    return {
        "reports": [(r.t, r.text) for r in record.reports],
        "outputs": [(o.t, o.pattern) for o in record.outputs],
        "dropped": (record.dropped["reports"], record.dropped["outputs"]),
        "hazards": [(h.t, h.rule, h.where) for h in record.hazards],
        "ended": record.ended_at,
    }
