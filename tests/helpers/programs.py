"""Random well-formed high-level programs (Hypothesis strategies) for the property tests."""
from __future__ import annotations

from hypothesis import strategies as st

EFFECTS = st.one_of(
    st.integers(-50, 50).map(lambda n: f"MR {n}"),
    st.integers(1, 4).map(lambda n: f"CN {n}"),
    st.integers(1, 4).map(lambda n: f"CF {n}"),
    st.integers(0, 15).map(lambda n: f"CP {n}"),
    st.integers(1, 9).map(lambda n: f"SV {n}000"),
    st.integers(1, 9).map(lambda n: f"WA {n}"),
    st.just("TP"),
)
CONDITION = st.tuples(st.booleans(), st.integers(1, 6)).map(
    lambda c: ("not " if c[0] else "") + str(c[1]))


@st.composite
def block(draw, depth: int, leaves: int, modes: int, in_loop: bool, nested: bool):
    """A statement list; calls only to leaf macros, never from blocks nested in a loop."""
    stmts = []
    for _ in range(draw(st.integers(0 if depth else 1, 4))):
        options = ["effect", "effect"]
        if leaves and not (in_loop and nested):
            options.append("call")
        if depth < 2:
            options += ["when", "repeat"] + ([] if in_loop else ["every"])
        kind = draw(st.sampled_from(options))
        if kind == "effect":
            stmts.append(draw(EFFECTS))
        elif kind == "call":
            stmts.append(f"call leaf{draw(st.integers(0, leaves - 1))}")
        elif kind == "when":
            conds = " and ".join(draw(st.lists(CONDITION, min_size=1, max_size=2)))
            body = draw(block(depth + 1, leaves, modes, in_loop, True))
            stmts.append(f"when {conds} {{ {', '.join(body)} }}")
        elif kind == "repeat":
            body = draw(block(depth + 1, leaves, modes, True, in_loop))
            stmts.append(f"repeat {draw(st.integers(1, 3))} {{ {', '.join(body)} }}")
        else:
            body = draw(block(depth + 1, leaves, modes, True, in_loop))
            stmts.append(f"every {draw(st.integers(0, 30))}ms {{ {', '.join(body)} }}")
    if modes and draw(st.booleans()) and not in_loop:
        stmts.append(f"goto mode{draw(st.integers(0, modes - 1))}")
    return stmts


@st.composite
def programs(draw):
    leaves = draw(st.integers(0, 2))
    modes = draw(st.integers(0, 2))
    text = []
    for i in range(leaves):
        text.append(f"macro leaf{i} {{ {', '.join(draw(st.lists(EFFECTS, min_size=1, max_size=8)))} }}")
    for i in range(modes):
        text.append(f"macro mode{i} {{\n  " + "\n  ".join(draw(block(0, leaves, modes, False, False))) + "\n}")
    text.append("autostart {\n  " + "\n  ".join(draw(block(0, leaves, modes, False, False))) + "\n}")
    return "\n".join(text) + "\n"

# Raw native commands for the decompiler's raw programs (MS176E §6): moves, waits, I/O
# conditions, repeats; an EM to another slot is drawn beside them.
RAW_COMMANDS = st.sampled_from([
    "MR5000", "MR-200", "MA100", "WS10", "WA20", "CP3", "CN1", "CF2", "SV9000", "AB1", "GH",
    "WF1", "WN2", "XN1", "XF2", "XN3", "RP", "RP3", "TP", "DH", "ZM1"])
