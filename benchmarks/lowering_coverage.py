"""How much of the high-level language the compiler fits.

Generates random high-level programs from a fixed seed (leaf macros, macros
that call and goto, modes, nested when/repeat/every, long bodies, loops at a
macro's start, big counts and periods), compiles each, and prints:

- the share accepted (no error), and the rules that rejected the rest;
- miscompilations: accepted programs whose MD lines, run on the firmware
  model (tests/helpers/semantics.py, docs/simulator.md), differ from the structured
  meaning of the source for any of the 16 combinations of held buttons 1-4;
- the slots used by the programs accepted.

`--save FILE` keeps the per-program results; `--compare FILE` prints how
many programs changed from rejected to accepted (and back) and the slots
saved on the programs both runs accepted.

    .venv/bin/python benchmarks/lowering_coverage.py --seed 8 --count 3400 \
        --compare benchmarks/lowering_coverage.before.json

`lowering_coverage.before.json` holds the results of the compiler before
it lowered nested calls and in-line loops (seed 8, 3400 programs): 1309 accepted
(38.5 %); rejected with nested-call 1910, syntax 1290, argument-range 396; 0 miscompiled;
8026 slots.
"""
from __future__ import annotations

import argparse
import json
import random
import sys
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "tests")]  # mercmac and the tests' helpers

from mercmac.compiler import compile_source  # noqa: E402
from mercmac.compiler.ast_builder import build  # noqa: E402
from mercmac.compiler.checks import check_module  # noqa: E402
from mercmac.compiler.parse import parse  # noqa: E402
from mercmac.diagnostics import Report, Severity  # noqa: E402
from mercmac.source import Source  # noqa: E402
from helpers.semantics import firmware_trace, high_level_trace, same_effects  # noqa: E402


class Gen:
    """One random program: leaves (effects only), subs (call leaves, may goto modes), modes."""

    def __init__(self, rng: random.Random):
        self.rng = rng
        self.leaves = [f"leaf{i}" for i in range(rng.randint(0, 2))]
        self.subs = [f"sub{i}" for i in range(rng.randint(0, 2))]
        self.modes = [f"mode{i}" for i in range(rng.randint(0, 2))]

    def effect(self) -> str:
        r = self.rng
        return r.choice([f"MR {r.randint(-50, 50)}", f"CN {r.randint(1, 4)}", f"CF {r.randint(1, 4)}",
                         f"CP {r.randint(0, 15)}", f"SV {r.randint(1, 9)}000", f"WA {r.randint(1, 9)}",
                         "TP", "TT"])

    def count(self) -> int:
        r = self.rng.random()
        if r < 0.02:
            return 0
        if r < 0.04:
            return self.rng.choice([40000, 65536, 100000])
        return self.rng.randint(1, 4)

    def period(self) -> str:
        if self.rng.random() < 0.04:
            return self.rng.choice(["2min", "70000ms", "100s"])
        return f"{self.rng.randint(0, 30)}ms"

    def block(self, depth: int, callees: list[str], in_loop: bool) -> list[str]:
        r = self.rng
        stmts: list[str] = []
        if r.random() < 0.08:  # a long straight run
            stmts += [self.effect() for _ in range(r.randint(12, 20))]
        for _ in range(r.randint(0 if depth else 1, 4)):
            kinds = ["effect"] * 3 + (["call"] if callees else [])
            if depth < 2:
                kinds += ["when", "repeat"] + ([] if in_loop else ["every"])
            kind = r.choice(kinds)
            if kind == "effect":
                stmts.append(self.effect())
            elif kind == "call":
                stmts.append(f"call {r.choice(callees)}")
            elif kind == "when":
                conds = " and ".join(("not " if r.random() < 0.3 else "") + str(r.randint(1, 4))
                                     for _ in range(r.randint(1, 2)))
                stmts.append(f"when {conds} {{ {', '.join(self.block(depth + 1, callees, in_loop))} }}")
            elif kind == "repeat":
                body = self.block(depth + 1, callees, True)
                stmts.append(f"repeat {self.count()} {{ {', '.join(body)} }}")
            else:
                body = self.block(depth + 1, callees, True)
                stmts.append(f"every {self.period()} {{ {', '.join(body)} }}")
        if self.modes and r.random() < 0.25:
            stmts.append(f"goto {r.choice(self.modes)}")
        return stmts

    def text(self) -> str:
        r, out = self.rng, []
        for name in self.leaves:
            body = [self.effect() for _ in range(r.randint(1, 6))]
            if r.random() < 0.3:
                body = [f"repeat {r.randint(2, 4)} {{ {', '.join(body[:3])} }}"] + body[3:]
            out.append(f"macro {name} {{ {', '.join(body)} }}")
        for name in self.subs:
            out.append(f"macro {name} {{\n  " + "\n  ".join(self.block(1, self.leaves, False)) + "\n}")
        callees = self.leaves + self.subs
        for name in self.modes:
            out.append(f"macro {name} {{\n  " + "\n  ".join(self.block(0, callees, False)) + "\n}")
        out.append("autostart {\n  " + "\n  ".join(self.block(0, callees, False)) + "\n}")
        return "\n".join(out) + "\n"


def outcome(text: str) -> dict:
    result = compile_source(Source("gen.mcm", text))
    errors = sorted({d.rule.name for d in result.report.items if d.severity is Severity.ERROR})
    if errors:
        return {"accepted": False, "errors": errors}
    stored = {s: [(op.mnemonic, op.arg) for op in m.ops] for s, m in result.program.macros.items()}
    report = Report("gen.mcm")
    module = build(parse(text, report))
    env = check_module(module, report, None)
    wrong = sum(not same_effects(firmware_trace(stored, inputs), high_level_trace(module, env, inputs))
                for inputs in ({n for n in range(1, 5) if mask >> (n - 1) & 1} for mask in range(16)))
    return {"accepted": True, "slots": len(stored), "miscompiled": wrong > 0}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=8)
    parser.add_argument("--count", type=int, default=3400)
    parser.add_argument("--save")
    parser.add_argument("--compare")
    parser.add_argument("--show", metavar="RULE", help="print a few programs rejected by RULE")
    args = parser.parse_args()
    rng = random.Random(args.seed)
    texts = [Gen(rng).text() for _ in range(args.count)]
    results = [outcome(t) for t in texts]
    accepted = [r for r in results if r["accepted"]]
    print(f"seed {args.seed}: {len(accepted)} of {len(results)} programs accepted "
          f"({100 * len(accepted) / len(results):.1f} %)")
    rejected = Counter(rule for r in results if not r["accepted"] for rule in r["errors"])
    for rule, n in rejected.most_common():
        print(f"  rejected with {rule}: {n}")
    print(f"  miscompiled: {sum(r['miscompiled'] for r in accepted)}")
    print(f"  slots used by accepted programs: {sum(r['slots'] for r in accepted)}")
    if args.show:
        shown = [t for t, r in zip(texts, results) if args.show in r.get("errors", ())][:3]
        print("\n---\n".join(shown))
    if args.save:  # per program: the slots used, or the list of rules that rejected it
        compact = [r["slots"] if r["accepted"] else r["errors"] for r in results]
        Path(args.save).write_text(json.dumps(compact, separators=(",", ":")), encoding="utf-8")
    if args.compare:
        before = [{"accepted": True, "slots": r} if isinstance(r, int) else
                  {"accepted": False, "errors": r}
                  for r in json.loads(Path(args.compare).read_text(encoding="utf-8"))]
        gained = sum(not b["accepted"] and a["accepted"] for b, a in zip(before, results))
        lost = [(b, a) for b, a in zip(before, results) if b["accepted"] and not a["accepted"]]
        both = [(b, a) for b, a in zip(before, results) if b["accepted"] and a["accepted"]]
        print(f"compared with {args.compare}: {gained} newly accepted, {len(lost)} newly rejected "
              f"({Counter(rule for _, a in lost for rule in a['errors'])})")
        saved = sum(b["slots"] - a["slots"] for b, a in both)
        print(f"  on the {len(both)} programs accepted by both: {saved} slots saved "
              f"({sum(b['slots'] > a['slots'] for b, a in both)} programs use fewer slots, "
              f"{sum(b['slots'] < a['slots'] for b, a in both)} more)")


if __name__ == "__main__":
    main()
