"""Reading stored macros back as a program: `decompile` (high-level source with an exact
round trip), `describe` (the program in plain words) and its call graph, and
the same for a rig of several controllers."""
from __future__ import annotations

from mercmac.decompile.lines import read_macros
from mercmac.decompile.prose import call_graph_dot, describe
from mercmac.decompile.rig import Stored, describe_rig, rig_graph_dot
from mercmac.decompile.source import decompile


__all__ = ["decompile", "describe", "call_graph_dot", "read_macros", "describe_rig",
           "rig_graph_dot", "Stored"]
