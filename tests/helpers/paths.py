"""The one place that names the repository's folders and the example files tests use."""
from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "mercmac"
TESTS = ROOT / "tests"
GOLDEN = TESTS / "golden"  # expected outputs, rewritten with MERCMAC_UPDATE_GOLDEN=1
DATA = TESTS / "data"  # third-party files the tests read (the SARIF schema)

EXAMPLES = ROOT / "examples" / "macros"
SCENARIOS = ROOT / "examples" / "scenarios"
EXAMPLE_FILES = sorted(EXAMPLES.glob("*.mcm"))

EXAMPLE3 = EXAMPLES / "manual-example3-operator-moves.mcm"
EXAMPLE4 = EXAMPLES / "manual-example4-four-modes.mcm"  # the manual's four modes (MS176E §3.9)
FOUR_MODES = EXAMPLES / "four-modes.mcm"  # the README's pushbutton program
JOG_BOX = EXAMPLES / "jog-box.mcm"
EXAMPLE4_MODE2 = SCENARIOS / "manual-example4-four-modes.mode2.toml"
