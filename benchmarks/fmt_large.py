"""`mercmac fmt` on large files: wall time and peak memory (slow at worst, never stuck).

    python benchmarks/fmt_large.py [--size MB] [--timeout S]

Four generated files of about 1 MB each, written the way people do not (lower case, no
blanks), so that every one is rewritten, each formatted in a fresh interpreter:
(a) one line: a macro of `mr 1` commands on a single line (once 38 s);
(b) many lines: short high-level macros, one per line;
(c) one raw line: `[MC01] mr1,mr1,...` on a single line;
(d) many raw lines: MMCRun blocks, one per line.
Formatting must be linear in the file size. Goal: at most 2 s per MB.
"""
from __future__ import annotations

from check_large import main

CASES = {
    "one line": lambda n: "macro a {" + "mr 1," * (n // 5) + "mr 1}\n",
    "many lines": lambda n: "macro a{mr 1,ws 10}\n" * (n // 20),
    "one raw line": lambda n: "[MC01] " + "mr1," * (n // 4) + "\n",
    "many raw lines": lambda n: "[mc 1] mr 5000,ws 100\n" * (n // 22),
}


if __name__ == "__main__":
    main(CASES, "fmt", __doc__)  # the same fresh-interpreter runs and figures as check_large
