"""Decompile raw macros and build the source again: the round trip every decompiler test
holds, the stored lines equal (docs/cli.md, "Commands": `decompile`)."""
from __future__ import annotations

from mercmac import mdtext
from mercmac.compiler import compile_source
from mercmac.decompile import decompile
from mercmac.source import Source


def build(text: str, name: str = "x.mcm"):
    """The compilation of a source that must build."""
    comp = compile_source(Source(name, text))
    assert comp.program is not None, [d.message for d in comp.report.items]
    return comp


def stored(program) -> dict[int, str]:
    """slot -> the normal text of the MD line a controller would store."""
    return {m.slot: mdtext.normal(m.line) for m in program.macros.values()}


def round_trip(macros: dict[int, str]) -> str:
    """The decompiled source of `macros`, after checking that it builds back to them."""
    source = decompile(macros)
    comp = build(source)
    assert stored(comp.program) == {s: mdtext.normal(t) for s, t in macros.items()}, source
    return source
