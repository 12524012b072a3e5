"""The pages of docs/ and their `## ` headings, in order, as the docs name them: code comments
cite a page and one of its headings, in parentheses. A new page or heading goes here and into
docs/ together (tests/project/test_docs.py, test_citations.py)."""
from __future__ import annotations

HEADINGS = {
    "architecture.md": ["The floors", "One way down", "One table, one model, one renderer",
                        "A program is a rig of one", "Where rigs live",
                        "Changing the code without changing what it shows"],
    "language.md": ["Programs and macros", "Statements", "Lowering", "Targets and settings"],
    "checks.md": ["How check reads a file", "Rules", "Fixes"],
    "simulator.md": ["Time", "Calls and the return point", "Repeat counters", "Conditions",
                     "Motion", "Outputs and reports", "Power-on", "Fast-forward",
                     "What sim writes"],
    "uploader.md": ["The serial link", "Reading macros back", "A flash, step by step",
                    "Backups and history", "Signals and lost ports"],
    "rigs.md": ["The rig file", "A program is a rig of one", "Wires", "One instant", "Dead-lock",
                "Flashing and pulling a rig"],
    "cli.md": ["Commands", "Exit codes", "JSON output", "Limits"],
}
