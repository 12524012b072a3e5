"""Re-checking on every keystroke in the language server (issue 10, `mercmac lsp`).

    python benchmarks/recheck_latency.py [--runs N]

In-process, as the server does it (mercmac.lsp.recheck): one document is checked, then
edited and re-checked N times, each edit changing one number in one block. Two documents:
the largest example in examples/macros/, and a generated program that fills all 32 slots.
Prints the median re-check beside the median full `compile_source` of the same texts.
Goal: median re-check at most 3 ms each.
"""
from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

EXAMPLES = ROOT / "examples" / "macros"


def full_program() -> str:
    """Autostart and 31 named macros of 16 commands each: all 32 slots, no errors."""
    lines = ["target C-863", "", "const STEP = 1000", ""]
    lines.append("autostart {\n    " + ", ".join(f"call m{i}" for i in range(1, 4))
                 + "\n    goto m31\n}")
    for i in range(1, 32):
        body = ", ".join(f"MR {i * 10 + k}" for k in range(13))
        lines.append(f"macro m{i} {{\n    {body}\n    MR STEP, WS 10, CP {i % 16}\n}}")
    return "\n".join(lines) + "\n"


def edits(text: str, runs: int) -> list[str]:
    """`runs` versions of `text`, each with one number of one line changed (a keystroke)."""
    lines = text.split("\n")
    places = [i for i, line in enumerate(lines)  # not `target C-863`: that would break it
              if any(ch.isdigit() for ch in line.split("//")[0]) and "target" not in line]
    out = []
    for n in range(runs):
        i = places[n % len(places)]
        code, sep, comment = lines[i].partition("//")
        at = max(k for k, ch in enumerate(code) if ch.isdigit())
        changed = code[:at] + str(n % 10) + code[at + 1:] + sep + comment
        out.append("\n".join(lines[:i] + [changed] + lines[i + 1:]))
    return out


def median_ms(work, texts: list[str]) -> float:
    times = []
    for text in texts:
        start = time.perf_counter()
        work(text)
        times.append(time.perf_counter() - start)
    return statistics.median(times) * 1000


def main() -> None:
    from mercmac.compiler import compile_source
    from mercmac.lsp.recheck import Rechecker
    from mercmac.source import Source

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=301)
    args = parser.parse_args()
    largest = max(EXAMPLES.glob("*.mcm"), key=lambda p: p.stat().st_size)
    example4 = EXAMPLES / "manual-example4-four-modes.mcm"
    cases = {p.name: p.read_text(encoding="utf-8", errors="replace") for p in (largest, example4)}
    cases.update({
        "32 slots (generated)": full_program()})
    for name, text in cases.items():
        texts = edits(text, args.runs)
        checker = Rechecker(name)
        checker.check(text)  # the document as opened
        recheck = median_ms(checker.check, texts)
        whole = median_ms(lambda s: compile_source(Source(name, s)), texts)
        print(f"{name}: re-check median {recheck:.2f} ms (goal <= 3), "
              f"full compile median {whole:.2f} ms")


if __name__ == "__main__":
    main()
