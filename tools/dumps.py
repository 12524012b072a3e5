"""Write what mercmac shows for a fixed corpus of programs and rigs into a folder, one file
per output, so that two revisions can be compared byte for byte (`diff -r`): a restructuring
that must not change a program's output proves it so (docs/architecture.md, "Changing the
code without changing what it shows").

    python tools/dumps.py OUT            # with the mercmac that `import mercmac` finds
    PYTHONPATH=../old python tools/dumps.py OLD && python tools/dumps.py NEW && diff -r OLD NEW

The corpus: every bundled example program under several button scripts and run lengths,
the simulator benchmark's programs, seeded random programs (the same ones on every run),
the bundled scenarios, the raster rig and seeded random wired rigs. For each: `sim` as
text (the story, -v, -vv, --trace), as JSON, its VCD and, for some, its plot (.svg and
.html, which holds the plot's data); `describe` as text, markdown and JSON.
Runs go through the CLI in this process (click's runner), as a user's would.
"""
from __future__ import annotations

import argparse
import os
import random
import re
import shutil
import tempfile
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
EXAMPLES = HERE.parent / "examples"
SCRIPTS = ["", "1@0-2s", "3@0-300ms,1@1s-1.2s", "2@0-500ms,1@1s-3s,4@5s",
           "4@0-300ms,2@400ms-2s,1@3s-3.5s"]
UNTILS = ["3s", "10s", "1h"]
LONG = "1500d"
RANDOM_PROGRAMS = 80
RANDOM_RIGS = 24
PLOTTED = 12  # runs that also get a plot (slow: a second or more each)

# the simulator benchmark's loops (benchmarks/sim_speed.py)
LOOPS = {
    "blink": "autostart {\n  every 500ms { CN 1, WA 500, CF 1 }\n}\n",
    "tt": "autostart {\n  every 20ms { TT }\n}\n",
    "jog": "autostart {\n  every 10ms { MR 1, WS 0 }\n}\n",
    "ts-jog": "autostart {\n  MA -3000, WS 0\n  every 10ms { MR 1, WS 0, TS }\n}\n",
    "chase": "target C-863\nmacro m { TT, MR 1, when 4 { goto fin }, goto m }\n"
             "macro fin { CN 1 }\nautostart { goto m }\n",
    "chase-663": "target C-663\nmacro m { TT, MR 1, when 4 { goto fin }, goto m }\n"
                 "macro fin { CN 1 }\nautostart { goto m }\n",
    "nine": "autostart {\n  every 30ms { " + ", ".join(f"TT, MR {i}" for i in range(1, 10))
            + " }\n}\n",
    "raw-loop": "[MC00] CN1,WA20,RP,RP\n",
    "pingpong": "macro a { goto b }\nmacro b { goto a }\nautostart { goto a }\n",
    "chase-target": "target C-863\nmacro chase { MR 500, TT, MR 25000, CN 1, WA 5, CF 1, "
                    "goto chase }\nautostart { goto chase }\n",
}

EFFECTS = ["MR {n}", "CN {k}", "CF {k}", "CP {p}", "SV {s}000", "WA {w}", "TP", "TT", "MA {n}",
           "WS {w}", "TS"]


def _effect(rnd: random.Random) -> str:
    return rnd.choice(EFFECTS).format(n=rnd.randint(-500, 500), k=rnd.randint(1, 4),
                                      p=rnd.randint(0, 15), s=rnd.randint(1, 9),
                                      w=rnd.randint(1, 30))


def _block(rnd: random.Random, depth: int, in_loop: bool) -> list[str]:
    out = []
    for _ in range(rnd.randint(1 if not depth else 0, 4)):
        kind = rnd.choice(["effect", "effect", "effect"]
                          + (["when", "repeat"] + ([] if in_loop else ["every"])
                             if depth < 2 else []))
        if kind == "effect":
            out.append(_effect(rnd))
        elif kind == "when":
            cond = ("not " if rnd.random() < 0.3 else "") + str(rnd.randint(1, 4))
            out.append(f"when {cond} {{ {', '.join(_block(rnd, depth + 1, in_loop))} }}")
        elif kind == "repeat":
            out.append(f"repeat {rnd.randint(1, 4)} {{ "
                       f"{', '.join(_block(rnd, depth + 1, True))} }}")
        else:
            out.append(f"every {rnd.randint(1, 40)}ms {{ "
                       f"{', '.join(_block(rnd, depth + 1, True))} }}")
    return out


def random_program(rnd: random.Random) -> str:
    target = rnd.choice(["C-863", "C-663"])
    modes = rnd.randint(0, 2)
    text = [f"target {target}"]
    for i in range(modes):
        body = _block(rnd, 0, False) + ([f"goto mode{rnd.randint(0, modes - 1)}"]
                                        if rnd.random() < 0.5 else [])
        text.append(f"macro mode{i} {{\n  " + "\n  ".join(body) + "\n}")
    body = _block(rnd, 0, False) + ([f"goto mode{rnd.randint(0, modes - 1)}"]
                                    if modes and rnd.random() < 0.7 else [])
    text.append("autostart {\n  " + "\n  ".join(body) + "\n}")
    return "\n".join(text) + "\n"


def random_script(rnd: random.Random) -> str:
    presses = []
    t = 0
    for _ in range(rnd.randint(0, 5)):
        t += rnd.randint(0, 3000)
        length = rnd.randint(1, 2000)
        presses.append(f"{rnd.randint(1, 4)}@{t}-{t + length}")
        t += length
    return ",".join(presses)


def random_rig(rnd: random.Random, folder: Path) -> Path:
    """Two or three controllers passing tokens over wires (a ring), seeded."""
    names = ["x", "y", "z"][:rnd.randint(2, 3)]
    wires = []
    for i, name in enumerate(names):
        nxt = names[(i + 1) % len(names)]
        wires.append(f'"{name}.out{rnd.randint(1, 4)} -> {nxt}.in{rnd.randint(1, 4)}"')
    lines = [f"wires = [{', '.join(wires)}]"]
    if rnd.random() < 0.5:  # the box's buttons on the inputs no wire drives
        wired = {int(w.split(".in")[1][0]) for w in wires if f"-> {names[0]}.in" in w}
        free = [n for n in range(1, 5) if n not in wired]
        lines += [f'box = "{names[0]}"', f"box_buttons = {free}"]
    for i, name in enumerate(names):
        model = rnd.choice(["C-863", "C-663"])
        outs = [w for w in wires if w.startswith(f'"{name}.')]
        ins = [w for w in wires if f"-> {name}.in" in w]
        out_n = outs[0].split(".out")[1][0]
        in_n = ins[0].split(".in")[1][0]
        first = i == 0
        body = [f"MR {rnd.randint(-900, 900)}", "WS 0"]
        token = [f"CN {out_n}", f"WN {in_n}", f"CF {out_n}", f"WF {in_n}"] if first else \
            [f"WN {in_n}", f"CN {out_n}", f"WF {in_n}", f"CF {out_n}"]
        extra = [_effect(rnd) for _ in range(rnd.randint(0, 2))]
        (folder / f"{name}.mcm").write_text(
            f"target {model}\nmacro go {{ {', '.join(body + extra + token)}, goto go }}\n"
            "autostart { goto go }\n", encoding="utf-8")
        lines += ["", f"[controllers.{name}]", f"address = {i + 1}", f'model = "{model}"',
                  f'program = "{name}.mcm"']
    path = folder / "r.rig.toml"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


class Dumper:
    def __init__(self, out: Path, work: Path):
        from click.testing import CliRunner

        from mercmac.cli import main

        self.out, self.work, self.main, self.runner = out, str(work), main, CliRunner()
        self.plotted = 0

    def cli(self, name: str, args: list[str], stdin: str | None = None) -> None:
        result = self.runner.invoke(self.main, args, input=stdin, catch_exceptions=True)
        text = result.output
        if result.exception is not None and not isinstance(result.exception, SystemExit):
            text += f"\n!! {type(result.exception).__name__}: {result.exception}\n"
        text = f"exit {result.exit_code}\n{text}".replace(self.work, "<work>")
        (self.out / f"{name}.txt").write_text(text, encoding="utf-8")

    def sim(self, name: str, file: str, args: list[str], *, plot: bool = False,
            views: bool = True) -> None:
        base = ["sim", file, *args]
        self.cli(f"{name}.text", base)
        self.cli(f"{name}.json", base + ["--format", "json"])
        if views:
            self.cli(f"{name}.v", base + ["-v"])
            self.cli(f"{name}.vv", base + ["-vv"])
        self._written(f"{name}.vcd", base + ["--vcd-limit", "20", "--vcd"])
        if plot and self.plotted < PLOTTED:
            self.plotted += 1
            for kind in ("svg", "html"):
                self._written(f"{name}.{kind}", base + ["--plot"])

    def _written(self, name: str, args: list[str]) -> None:
        """A run that writes a file (--vcd, --plot): written under a fixed name in the work
        folder (the name shows in messages), then kept as NAME."""
        kind = name.rsplit(".", 1)[1]
        self.cli(f"{name}-run", [*args, f"out.{kind}"])
        if not os.path.exists(f"out.{kind}"):
            return
        if kind in ("svg", "html"):  # matplotlib's clip-path ids differ from run to run
            text = Path(f"out.{kind}").read_text(encoding="utf-8").replace(self.work, "<work>")
            Path(f"out.{kind}").write_text(re.sub(r"\bp[0-9a-f]{10}\b", "pID", text),
                                          encoding="utf-8")
        os.replace(f"out.{kind}", self.out / name)

    def describe(self, name: str, file: str) -> None:
        for fmt in ("text", "markdown", "json"):
            self.cli(f"{name}.describe-{fmt}", ["describe", file, "--format", fmt])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--quick", action="store_true", help="a smaller corpus")
    parser.add_argument("--work", type=Path, default=None,
                        help="where the corpus's files are written (default: a new temporary "
                             "folder; its path shows as <work> in the outputs)")
    args = parser.parse_args()
    out: Path = args.out.resolve()
    out.mkdir(parents=True, exist_ok=True)
    # the programs' paths show in outputs: written as <work>, two runs compare wherever they ran
    work = (args.work or Path(tempfile.mkdtemp(prefix="mercmac-dumps-"))).resolve()
    work.mkdir(parents=True, exist_ok=True)
    os.chdir(work)
    os.environ.setdefault("COLUMNS", "120")
    d = Dumper(out, work)
    rnd = random.Random(2711)
    examples = work / "examples"  # the bundled ones, copied: their paths show in messages
    shutil.rmtree(examples, ignore_errors=True)
    shutil.copytree(EXAMPLES, examples)
    examples = sorted((examples / "macros").glob("*.mcm"))
    for path in examples:
        stem = path.stem
        d.describe(f"ex-{stem}", str(path))
        for i, script in enumerate(SCRIPTS):
            for until in UNTILS:
                d.sim(f"ex-{stem}.b{i}.{until}", str(path),
                      ["--buttons", script, "--until", until],
                      plot=until == "10s" and i in (0, 2), views=until != "1h")
        d.sim(f"ex-{stem}.trace", str(path), ["--buttons", SCRIPTS[2], "--until", "300ms",
                                             "--trace"], views=False)
        d.sim(f"ex-{stem}.long", str(path), ["--buttons", "1@0", "--until", LONG], views=False)
    for scenario in sorted((work / "examples" / "scenarios").glob("*.toml")):
        program = work / "examples" / "macros" / (scenario.name.split(".")[0] + ".mcm")
        d.sim(f"scenario-{scenario.stem}", str(program), ["--scenario", str(scenario)],
              views=False)
    failing = work / "failing.toml"
    failing.write_text('until = "2s"\n[[step]]\nat = "0ms"\npress = [3]\n'
                       '[[step]]\nat = "300ms"\nrelease = [3]\n'
                       '[[expect]]\nat = "1s"\noutputs = 15\n', encoding="utf-8")
    d.sim("scenario-failing", str(work / "examples" / "macros" / "manual-example4-four-modes.mcm"),
          ["--scenario", str(failing)], views=False)
    for name, text in LOOPS.items():
        path = work / f"{name}.mcm"
        path.write_text(text, encoding="utf-8")
        for until in ("10s", "10min", "1h") if not args.quick else ("10s",):
            d.sim(f"loop-{name}.{until}", str(path), ["--buttons", "4@9min", "--until", until],
                  plot=until == "10min", views=until != "1h")
        d.describe(f"loop-{name}", str(path))
    for i in range(RANDOM_PROGRAMS // (4 if args.quick else 1)):
        path = work / f"random{i}.mcm"
        path.write_text(random_program(rnd), encoding="utf-8")
        script = random_script(rnd)
        until = rnd.choice(["2s", "20s", "5min"])
        d.sim(f"random{i:03}", str(path), ["--buttons", script, "--until", until],
              plot=i % 10 == 0)
        d.describe(f"random{i:03}", str(path))
    raster = work / "examples" / "rigs" / "raster" / "raster.rig.toml"
    for until in ("12s", "1h"):
        d.sim(f"rig-raster.{until}", str(raster), ["--buttons", "x:1@0-100ms", "--until", until],
              plot=until == "12s", views=until == "12s")
    d.describe("rig-raster", str(raster))
    for i in range(RANDOM_RIGS // (4 if args.quick else 1)):
        folder = work / f"rig{i}"
        folder.mkdir(exist_ok=True)
        path = random_rig(rnd, folder)
        d.sim(f"rig{i:02}", str(path), ["--until", rnd.choice(["3s", "1min"])])
        d.describe(f"rig{i:02}", str(path))
    print(f"{len(list(out.glob('*')))} files in {out}", file=sys.stderr)


if __name__ == "__main__":
    main()
