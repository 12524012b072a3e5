"""What the flash history tests flash: a program whose source says more than its MD lines (a
named macro, a comment), so only a recorded source gives it back (docs/uploader.md,
"Backups and history")."""
from __future__ import annotations

PROGRAM = ("target C-863\n\nmacro step @5 {   // the step\n    MR 5000, WS 100\n}\n\n"
           "autostart { call step }\n")
