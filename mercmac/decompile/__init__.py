"""Reading stored macros back as a program: `decompile` (high-level source with an exact
round trip), `describe` (the program in plain words) and its call graph (issue 12)."""
from __future__ import annotations

from mercmac.decompile.lines import read_macros
from mercmac.decompile.prose import call_graph_dot, describe
from mercmac.decompile.source import decompile


__all__ = ["decompile", "describe", "call_graph_dot", "read_macros"]
