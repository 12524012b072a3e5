"""Decompile speed on worst cases of 32 slots: wall time per program.

    python benchmarks/decompile_speed.py [--cap SECONDS] [CASE-PREFIX...]

(a) chains of conditional slots, `[MCi] XN1,EM(i+1),MR5`, of 16, 20, 24 and 32 slots
    (each folded `when` nests in its caller: before the fix 2^depth lowerings per check);
(b) a fan-out tree: slot i calls 2i+1 and 2i+2 under a condition;
(c) every slot calls the next 15 (the most EMs a 16-command line holds);
(d) a chain of hoisted loops, each calling the next and a rest macro;
(e) chains of 32 with random commands around each call (5 seeds);
(f) the slowest of 20 seeded random 32-slot programs.
Each case runs in a fresh interpreter (cut off at --cap, default 120 s), imports included,
and checks the exact round trip: the decompiled source builds to the same MD lines.
Goal: at most 2 s each.
"""
from __future__ import annotations

import random
import subprocess
import sys
import time

SLOTS = 32


def chain(n: int) -> dict[int, str]:
    """Slot i calls i+1 under a condition; slot 31 calls nothing (EM32 is no macro)."""
    return {i: f"XN1,EM{i + 1},MR5" if i + 1 < SLOTS else "XN1,MR5" for i in range(n)}


def fan_out() -> dict[int, str]:
    return {i: ",".join(["XN1"] + [f"EM{c}" for c in (2 * i + 1, 2 * i + 2) if c < SLOTS]
                        + ["MR5"]) for i in range(SLOTS)}


def everyone() -> dict[int, str]:
    return {i: ",".join(f"EM{(i + k) % SLOTS or 1}" for k in range(1, 16)) + ",MR5"
            for i in range(SLOTS)}


def loop_chain() -> dict[int, str]:
    """MCi runs loop MC(i+1) then rest MC(i+2); each loop calls its rest too."""
    out = {}
    for i in range(0, SLOTS - 2, 2):
        out[i] = f"MR{i + 1},EM{i + 1},EM{i + 2}"
        out[i + 1] = f"MR1,WS0,RP3,EM{i + 2}"
    out[SLOTS - 2], out[SLOTS - 1] = "MR5,EM31", "XN2,MR7"
    return out


_WORDS = ["MR5", "MA0", "WS0", "WA20", "CN1", "CF2", "TP", "SV9000", "RP3", "RP", "TI", "XN1",
          "XF2", "XN3", "DH", "GH", "AB1"]


def random_chain(seed: int) -> dict[int, str]:
    """A chain of 32 with random content: conditions, commands, EM(i+1), more commands."""
    rng = random.Random(seed)
    plain = [w for w in _WORDS if not w.startswith(("X", "RP", "TI"))]
    macros = {}
    for slot in range(SLOTS):
        ops = [rng.choice(["XN1", "XF2", "XN3"]) for _ in range(rng.randrange(1, 3))]
        ops += [rng.choice(plain) for _ in range(rng.randrange(0, 4))]
        ops += [f"EM{slot + 1}"] if slot + 1 < SLOTS else []
        macros[slot] = ",".join(ops + [rng.choice(plain) for _ in range(rng.randrange(1, 4))])
    return macros


def random_program(seed: int) -> dict[int, str]:
    rng = random.Random(seed)
    macros = {}
    for slot in range(SLOTS):
        ops = [rng.choice(_WORDS + [f"EM{rng.randrange(1, SLOTS)}"] * 6)
               for _ in range(rng.randrange(1, 17))]
        macros[slot] = ",".join(ops)
    return macros


CASES = {
    **{f"chain of {n} conditional slots": f"chain({n})" for n in (16, 20, 24, 32)},
    "fan-out tree of 32 slots": "fan_out()",
    "32 slots, each calling 15 others": "everyone()",
    "chain of 15 hoisted loops with rests": "loop_chain()",
    **{f"chain of 32, random commands, seed {s}": f"random_chain({s})" for s in range(5)},
    **{f"random 32-slot program, seed {s}": f"random_program({s})" for s in range(20)},
}

_RUN = """
import sys, time
sys.path.insert(0, HERE)
from decompile_speed import *
from mercmac.compiler import compile_source
from mercmac.decompile import decompile
from mercmac.mdtext import normal, split_md
from mercmac.source import Source
macros = EXPR
t = time.perf_counter()
text = decompile(macros)
seconds = time.perf_counter() - t
program = compile_source(Source("d.mcm", text)).program
want = {s: normal(m) for s, m in macros.items() if normal(m)}
got = {} if program is None else {s: normal(m) for s, m in map(split_md, program.md_lines())}
print(seconds, got == want or "NOT EXACT")
"""


def measure(expr: str, cap: float) -> tuple[float | None, str]:
    """(decompile seconds, round trip) in a fresh interpreter; None past `cap` seconds."""
    import os

    here = os.path.dirname(os.path.abspath(__file__))
    try:
        script = _RUN.replace("HERE", repr(here)).replace("EXPR", expr)
        done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                              timeout=cap)
    except subprocess.TimeoutExpired:
        return None, "cut off"
    if done.returncode:
        return None, done.stderr.strip().splitlines()[-1]
    seconds, exact = done.stdout.split(maxsplit=1)
    return float(seconds), "exact" if exact.strip() == "True" else exact.strip()


def main(argv: list[str]) -> None:
    cap = 120.0
    if argv[:1] == ["--cap"]:
        cap, argv = float(argv[1]), argv[2:]
    worst_random = (0.0, "")
    for name, expr in CASES.items():
        if argv and not any(name.startswith(a) for a in argv):
            continue
        started = time.perf_counter()
        seconds, exact = measure(expr, cap)
        if name.startswith("random") and seconds is not None and exact == "exact":
            worst_random = max(worst_random, (seconds, name))
            continue
        shown = f"> {cap:.0f} s" if seconds is None else f"{seconds:6.2f} s"
        print(f"{name:<42} {shown}  {exact}  ({time.perf_counter() - started:.1f} s with start-up)")
    if worst_random[1]:
        print(f"{'slowest ' + worst_random[1]:<42} {worst_random[0]:6.2f} s  exact")


if __name__ == "__main__":
    main(sys.argv[1:])
