"""Re-checking on every keystroke in the language server (`mercmac lsp`).

    python benchmarks/recheck_latency.py [--runs N] [--big MB]

In-process, as the server does it (mercmac.lsp.recheck): one document is checked, then
edited and re-checked N times, each edit changing one number in one block. Two documents:
the largest example in examples/macros/, and a generated program that fills all 32 slots.
Prints the median re-check beside the median full `compile_source` of the same texts.
Goal: median re-check at most 3 ms each.

Then a large document (2.5 MB; once 11.3 s to the first diagnostics and 3.5 s per
edit) through a real `mercmac lsp` over pipes: the time from didOpen to the first
diagnostics, from each one-character didChange to its diagnostics, and for a burst of
edits sent at once, to the diagnostics of the last. Goal: linear, at most 2 s per MB.
Then what an editor asks of that document after each change besides diagnostics (semantic
tokens, folding, inlay hints of the whole text, code lenses): seconds to each answer, with
the same goal.
"""
from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tests"))  # helpers.lsp_wire: a client that frames LSP itself

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


def big_program(size: float) -> str:
    """About `size` MB: autostart and 31 macros of `MR k, WS 10  // step k` lines, far more
    than 32 slots hold (about 10,000 errors, of which the server sends the first 1,000)."""
    lines = ["target C-863", "", "autostart {", "    call m1", "}"]
    step = "    MR {k}, WS 10  // step {k}"
    per_macro = int(size * 1e6 / 31 / (len(step.format(k=500)) + 1))
    for i in range(1, 32):
        lines += [f"macro m{i} {{", *(step.format(k=k % 1000) for k in range(per_macro)), "}"]
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
    parser.add_argument("--big", type=float, default=2.5, help="MB of the large document")
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
    server_latency(big_program(args.big))


def server_latency(text: str, edits: int = 5, burst: int = 10) -> None:
    """The large document through a real `mercmac lsp`: seconds to each version's diagnostics."""
    from helpers.lsp_wire import INITIALIZE, Server, frame, notification

    uri, mb = "file:///big.mcm", len(text.encode()) / 1e6
    server = Server()
    try:
        server.write(frame(INITIALIZE) + frame(notification("initialized", {})))
        server.answer(1)
        opened = _timed(server, 1, notification("textDocument/didOpen", {"textDocument": {
            "uri": uri, "languageId": "mcm", "version": 1, "text": text}}))
        middle = text.count("\n") // 2
        per_edit = [_timed(server, v, _keystroke(uri, v, middle)) for v in range(2, 2 + edits)]
        versions = range(2 + edits, 2 + edits + burst)
        last = _timed(server, versions[-1], *(_keystroke(uri, v, middle) for v in versions))
        views = _views(server, uri, text.count("\n") + 1)
    finally:
        server.close()
    print(f"{mb:.1f} MB through `mercmac lsp`: first diagnostics {opened:.2f} s "
          f"({opened / mb:.2f} s/MB, goal <= 2), per edit median "
          f"{statistics.median(per_edit):.2f} s, {burst} edits at once {last:.2f} s")
    print("  then, of the same version: " + ", ".join(
        f"{name} {seconds:.2f} s ({seconds / mb:.2f} s/MB)" for name, seconds in views.items()))


# What an editor asks after a change besides diagnostics (VS Code asks each of them).
_VIEWS = {"semantic tokens": ("textDocument/semanticTokens/full", {}),
          "folding": ("textDocument/foldingRange", {}),
          "inlay hints": ("textDocument/inlayHint", None),
          "code lenses": ("textDocument/codeLens", {})}


def _views(server, uri: str, lines: int) -> dict[str, float]:
    """Seconds to the answer of each request of _VIEWS, one after the other."""
    from helpers.lsp_wire import frame, request

    out = {}
    for number, (name, (method, params)) in enumerate(_VIEWS.items(), start=100):
        params = dict(params if params is not None else {"range": {
            "start": {"line": 0, "character": 0}, "end": {"line": lines, "character": 0}}})
        params["textDocument"] = {"uri": uri}
        start = time.perf_counter()
        server.write(frame(request(number, method, params)))
        answer = server.wait(lambda m, n=number: m.get("id") == n and "method" not in m,
                             f"{name}", wait_s=600)
        assert answer is not None and "error" not in answer, answer
        out[name] = time.perf_counter() - start
    return out


def _keystroke(uri: str, version: int, line: int) -> dict:
    """A didChange typing one space at the start of `line`."""
    from helpers.lsp_wire import notification

    at = {"line": line, "character": 0}
    return notification("textDocument/didChange", {
        "textDocument": {"uri": uri, "version": version},
        "contentChanges": [{"range": {"start": at, "end": at}, "text": " "}]})


def _timed(server, version: int, *messages: dict) -> float:
    """Seconds from writing `messages` to the diagnostics of document `version`."""
    from helpers.lsp_wire import frame

    start = time.perf_counter()
    server.write(b"".join(frame(m) for m in messages))
    server.wait(lambda m: m.get("method") == "textDocument/publishDiagnostics"
                and m["params"].get("version") == version, f"diagnostics of version {version}",
                wait_s=600)
    return time.perf_counter() - start


if __name__ == "__main__":
    main()
