"""The pages of docs/ and their `## ` headings, in order, as the docs name them: code comments
cite a page and one of its headings, in parentheses. A new page or heading goes here and into
docs/ together (tests/project/test_docs.py, test_citations.py)."""
from __future__ import annotations

HEADINGS = {
    "architecture.md": ["The floors", "One way down", "One table, one model, one renderer",
                        "A program is a rig of one", "Where rigs live",
                        "Changing the code without changing what it shows"],
    "language.md": ["Programs and macros", "Statements", "Lowering", "Targets and settings"],
    "checks.md": ["How check reads a file", "Rules", "Turning rules off", "Fixes", "Check in CI"],
    "simulator.md": ["Time", "Calls and the return point", "Repeat counters", "Conditions",
                     "Motion", "Outputs and reports", "Power-on", "Fast-forward",
                     "What sim writes", "Hazards", "Scenarios and the live box"],
    "uploader.md": ["The serial link", "Reading macros back", "A flash, step by step",
                    "Backups and history", "Signals and lost ports", "The emulator"],
    "rigs.md": ["The rig file", "A program is a rig of one", "Checking a rig", "Wires",
                "One instant", "Dead-lock", "Simulating a rig", "Flashing and pulling a rig"],
    "cli.md": ["Commands", "Starting a program", "Files and settings", "Formatting",
               "Describe and decompile", "Names from outside", "Exit codes", "JSON output",
               "Limits"],
    "editors.md": ["The language server", "VS Code", "Neovim", "Emacs", "Pygments"],
    "rules.md": ["Program rules (MM)", "Rig rules (MR)", "Runtime hazards (MH)"],
}
