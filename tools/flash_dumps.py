"""Write what `flash`, `pull`, `history` and `emulate` show for a fixed set of cases into a
folder, one file per case, so that two revisions can be compared byte for byte (`diff -r`),
as tools/dumps.py does for `sim` and `describe` (docs/architecture.md, "Changing the code
without changing what it shows").

    python tools/flash_dumps.py OUT            # with the mercmac that `import mercmac` finds
    PYTHONPATH=../old python tools/flash_dumps.py OLD && python tools/flash_dumps.py NEW && diff -r OLD NEW

Run it from outside the repository (an editable install would shadow PYTHONPATH there).
Each case serves virtual controllers (mercmac.emulator, one or a chain) on a real
pseudo-terminal in this process and runs mercmac as a separate process against it, as a user
would: a single file's flash, dry run, refusals (errors, wrong model, --force, silence,
nothing at any address, unwritable backups), retries, failures, signals (Ctrl-C, SIGTERM,
SIGHUP) and what `pull` and `history` say after; a two-controller rig's flash, dry run,
--only, refusals, failure and signal; `emulate` for one controller, a chain and a rig. Kept
for each: the exit code, standard output and error, the emulator's byte log, what each
virtual controller holds after, and every backup and history record written. Pty paths,
times and timestamps in file names are replaced by placeholders.
"""
from __future__ import annotations

import argparse
import io
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from contextlib import contextmanager
from pathlib import Path

HERE = Path(__file__).resolve().parent
RASTER = HERE.parent / "examples" / "rigs" / "raster"
PROGRAM = "target C-863\n[MC00] EM5\n[MC05] MR5000,WS100\n[MC06] XN1,MR-10\n[MC07] TP\n"
OLD = {0: "EM1", 1: "TP"}
NO_TARGET = "macro go { MR 200, WS 0 }\nautostart { goto go }\n"
ERRORS = "target C-863\n[MC03] FOO12\n"
ONLY_663 = "[MC03] DC100\n"  # DC is a C-663 command: an error for the C-863 that answers
FOR_663 = "target C-663\n[MC03] MR200\n"
FAST = ["--timeout", "3"]


class Cases:
    """The cases, each written to OUT/NAME.txt; the work folder is the same for both runs."""

    def __init__(self, out: Path, work: Path):
        self.out, self.work = out, work
        self.data = work / "data"
        self.paths: list[str] = []  # pty paths of this case, most specific first

    # -- serving and running -------------------------------------------------------------

    @contextmanager
    def serve(self, *vcs):
        """The virtual controllers VCS as a chain on one pty, with a byte log."""
        from mercmac.emulator.chain import Chain
        from mercmac.emulator.ptyserver import PtyServer

        log = io.StringIO()
        with PtyServer(Chain(list(vcs)), log) as server:
            self.paths.insert(0, server.path)
            server.log_text = log
            yield server

    def run(self, args: list[str], *, env: dict | None = None, signum: int | None = None,
            server=None, vc=None) -> str:
        """`mercmac ARGS` as a process: its exit code and output, normalised. With SIGNUM,
        the signal goes once VC has taken its first MD line (a flash is writing it)."""
        full = {k: v for k, v in os.environ.items() if k not in ("FORCE_COLOR", "MERCMAC_PORT")}
        full.update({"MERCMAC_DATA_DIR": str(self.data), "COLUMNS": "120", "NO_COLOR": "1"})
        full.update(env or {})
        proc = subprocess.Popen([sys.executable, "-m", "mercmac", *map(str, args)],
                                stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True, cwd=self.work, env=full)
        if signum is not None:
            end = time.monotonic() + 30
            while server.call(lambda _c: vc.md_count) < 1 and proc.poll() is None \
                    and time.monotonic() < end:
                time.sleep(0.005)
            proc.send_signal(signum)
        out, err = proc.communicate(timeout=120)
        shown = " ".join(str(a) for a in args)
        return self.norm(f"$ mercmac {shown}\nexit {proc.returncode}\n--- stdout\n{out}"
                         f"--- stderr\n{err}")

    def norm(self, text: str) -> str:
        for i, path in enumerate(self.paths):
            text = text.replace(path, f"<pty{i}>")
            tag = path.replace("/dev/", "").replace("/", "-")
            text = text.replace(tag, f"<pty{i}-tag>")
        text = text.replace(str(self.work), "<work>")
        # a vanished port is seen by the next write or by the read after it, as it happens
        text = re.sub(r"the port went away \([^)]*\)", "the port went away (...)", text)
        text = re.sub(r"/dev/pts/\d+", "<pty>", text)
        text = re.sub(r"\d{4}-\d\d-\d\d[T ]\d\d:\d\d(:\d\d)?([+-]\d\d:?\d\d|Z)?", "<time>", text)
        text = re.sub(r"\d{8}-\d{6}(-\d+)?", "<stamp>", text)
        return re.sub(r"^ *\d+\.\d{6} ", "<t> ", text, flags=re.M)  # the byte log's seconds

    # -- what is kept of a case ------------------------------------------------------------

    def case(self, name: str, *parts: str, server=None, vcs=()) -> None:
        text = "\n".join(parts)
        for vc in vcs:
            text += f"\n--- held at address {vc.address}: {json.dumps(vc.macros)}"
        if server is not None:
            text += "\n--- bytes on the line\n" + self.norm(_stream(server.log_text.getvalue()))
        text += self.files()
        (self.out / f"{name}.txt").write_text(text, encoding="utf-8")
        self.reset()

    def files(self) -> str:
        """Every file the case left in the data folder and the work folder's backups."""
        shown = []
        for folder in (self.data, self.work / "out"):
            for path in sorted(folder.rglob("*")) if folder.exists() else ():
                if path.is_file():
                    text = path.read_text(encoding="utf-8", errors="replace")
                    text = _stream(text) if path.suffix == ".log" else text  # emulate --log
                    shown.append(self.norm(f"\n--- file {path.relative_to(self.work)}\n{text}"))
        return "".join(sorted(shown))

    def reset(self) -> None:
        for folder in (self.data, self.work / "out"):
            shutil.rmtree(folder, ignore_errors=True)
        (self.work / "out").mkdir()
        self.paths = []

    def file(self, name: str, text: str) -> Path:
        path = self.work / name
        path.write_text(text, encoding="utf-8")
        return path


def _stream(log: str) -> str:
    """The emulator's byte log as what went each way, in turns: how the pty cut the bytes
    into reads, and so the per-read notes (who was selected, who answered), varies."""
    turns: list[list] = []
    for line in log.splitlines():
        m = re.match(r"^\s*[\d.]+ (->|<-) ((?:[0-9a-f]{2} )*[0-9a-f]{2})  ", line)
        if not m:
            turns.append([line, b""])
        elif turns and turns[-1][0] == m[1]:
            turns[-1][1] += bytes.fromhex(m[2])
        else:
            turns.append([m[1], bytes.fromhex(m[2])])
    return "\n".join(f"{way} {data!r}" if data else way for way, data in turns) + "\n"


def vc(model="C-863", address=0, macros=None, **faults):
    from mercmac.emulator.virtual import Faults, VirtualController

    return VirtualController(model, address, macros=dict(macros or {}), faults=Faults(**faults))


def singles(c: Cases) -> None:
    prog, out = c.file("p.mcm", PROGRAM), c.work / "out"
    with c.serve(v := vc(macros=OLD)) as s:
        runs = [c.run(["flash", s.path, prog, "--backup", out / "b.mcm", *FAST]),
                c.run(["flash", s.path, prog, "--backup", out / "b2.mcm", *FAST]),
                c.run(["pull", s.path, *FAST]), c.run(["pull", s.path, "--raw", *FAST]),
                c.run(["pull", s.path, "-o", out / "pulled.mcm", *FAST]),
                c.run(["history"]), c.run(["history", "--format", "json"]),
                c.run(["flash", s.path, out / "b.mcm", *FAST]),
                c.run(["flash", s.path, out / "b.mcm", "--erase-unused", *FAST])]
        c.case("single-flash-again-pull-history-restore", *runs, server=s, vcs=[v])
    for name, extra in (("dry-run", ["--dry-run"]), ("dry-run-reset", ["--dry-run", "--reset"]),
                        ("dry-run-erase", ["--dry-run", "--erase-unused"]),
                        ("reset", ["--reset"]), ("erase-unused", ["--erase-unused"]),
                        ("default-backup", [])):
        with c.serve(v := vc(macros=OLD)) as s:
            c.case(f"single-{name}", c.run(["flash", s.path, prog, *extra, *FAST]), server=s,
                   vcs=[v])
    with c.serve(v := vc(macros={5: "TP"})) as s:  # no macro 0: none runs when it is reached
        c.case("single-dry-run-unchanged",
               c.run(["flash", s.path, c.file("tp.mcm", "target C-863\n[MC05] TP\n"), "--dry-run",
                      "--reset", *FAST]), server=s, vcs=[v])
    cases = {"no-target": (NO_TARGET, []), "no-target-given": (NO_TARGET, ["--target", "C-863"]),
             "errors": (ERRORS, []), "errors-for-the-model": (ONLY_663, []),
             "errors-for-target": (ONLY_663, ["--target", "C-863"]),
             "wrong-model": (FOR_663, []), "wrong-model-force": (FOR_663, ["--force"])}
    for name, (text, extra) in cases.items():
        path = c.file(f"{name}.mcm", text)
        with c.serve(v := vc()) as s:
            c.case(f"single-{name}", c.run(["flash", s.path, path, *extra, *FAST]), server=s,
                   vcs=[v])
    faults = {"silent": dict(silent=True), "garbled": dict(garble=True),
              "retry": dict(drop_char={1: 4}), "mismatch": dict(always_drop_slot=6),
              "port-lost": dict(vanish_after_md=2),
              "unknown-model": dict(version="Mercury C-999 firmware 1.0")}
    for name, fault in faults.items():
        with c.serve(v := vc(macros=OLD, **fault)) as s:
            c.case(f"single-{name}", c.run(["flash", s.path, prog, *FAST]), vcs=[v],
                   server=None if "vanish_after_md" in fault else s)
    with c.serve(v := vc(version="Mercury C-999 firmware 1.0")) as s:
        c.case("single-unknown-model-no-target",
               c.run(["flash", s.path, c.file("nt.mcm", NO_TARGET), *FAST]), server=s, vcs=[v])
    with c.serve(v := vc(address=5, macros=OLD)) as s:
        c.case("single-search", c.run(["flash", s.path, prog]),
               c.run(["flash", s.path, prog, "--address", "5", *FAST]), server=s, vcs=[v])
    with c.serve(v := vc(silent=True)) as s:
        c.case("single-nothing-answers", c.run(["flash", s.path, prog]), server=s, vcs=[v])
    with c.serve(a := vc(address=2), b := vc(address=4)) as s:
        c.case("single-two-answer", c.run(["flash", s.path, prog]), server=s, vcs=[a, b])
    c.file("afile", "")
    unwritable = {"backup-folder": (["--backup", c.work], {}),
                  "backup-device": (["--backup", "/dev/null"], {}),
                  "data-folder-is-a-file": ([], {"MERCMAC_DATA_DIR": str(c.work / "afile")})}
    for name, (extra, env) in unwritable.items():
        with c.serve(v := vc(macros=OLD)) as s:
            c.case(f"single-{name}", c.run(["flash", s.path, prog, *extra, *FAST], env=env),
                   server=s, vcs=[v])
    with c.serve(v := vc(macros=OLD)) as s:
        c.data.mkdir(parents=True, exist_ok=True)
        (c.data / "history").write_text("not a folder")
        c.case("single-history-unwritable", c.run(["flash", s.path, prog, *FAST]), server=s,
               vcs=[v])
    c.case("single-port-is-a-file", c.run(["flash", c.work / "afile", prog, *FAST]))
    c.case("single-only-without-rig", c.run(["flash", "/dev/null", prog, "--only", "x"]))
    for signum in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        with c.serve(v := vc(macros=OLD, md_delay=0.2)) as s:
            c.case(f"single-signal-{signal.Signals(signum).name}",
                   c.run(["flash", s.path, prog, "--backup", c.work / "out" / "b.mcm", *FAST],
                         signum=signum, server=s, vc=v), vcs=[v])


def rigs(c: Cases) -> None:
    folder = c.work / "raster"
    shutil.copytree(RASTER, folder, dirs_exist_ok=True)
    rig, out = folder / "raster.rig.toml", c.work / "out"

    def chain(**faults_y):
        return vc("C-663", 0, {0: "EM1", 1: "TP"}), vc("C-663", 1, {0: "EM2"}, **faults_y)

    with c.serve(*(vs := chain())) as s:
        runs = [c.run(["flash", s.path, rig, "--backup", f"{out}/", *FAST]),
                c.run(["flash", s.path, rig, "--backup", out / "pre", *FAST]),
                c.run(["history"]), c.run(["pull", s.path, "--rig", out / "pulled", *FAST]),
                c.run(["pull", s.path, "--rig", out / "pulled", *FAST])]
        c.case("rig-flash-again-history-pull", *runs, server=s, vcs=vs)
    for name, extra in (("dry-run", ["--dry-run"]), ("dry-run-reset", ["--dry-run", "--reset"]),
                        ("reset", ["--reset"]), ("only-y", ["--only", "y"]),
                        ("only-unknown", ["--only", "z"]), ("default-backup", []),
                        ("erase-unused", ["--erase-unused"]),
                        ("address", ["--address", "1"]), ("force", ["--force"])):
        with c.serve(*(vs := chain())) as s:
            c.case(f"rig-{name}", c.run(["flash", s.path, rig, *extra, *FAST]), server=s, vcs=vs)
    with c.serve(x := vc("C-663", 0), y := vc("C-863", 1)) as s:
        c.case("rig-wrong-model", c.run(["flash", s.path, rig, *FAST]), server=s, vcs=[x, y])
    with c.serve(x := vc("C-663", 0)) as s:
        c.case("rig-missing", c.run(["flash", s.path, rig, *FAST]), server=s, vcs=[x])
    for name, fault in (("mismatch", dict(always_drop_slot=3)),
                        ("port-lost", dict(vanish_after_md=1))):
        with c.serve(*(vs := chain(**fault))) as s:
            c.case(f"rig-{name}", c.run(["flash", s.path, rig, *FAST]), vcs=vs,
                   server=None if "vanish_after_md" in fault else s)
    for signum in (signal.SIGINT, signal.SIGTERM):
        with c.serve(*(vs := chain(md_delay=0.2))) as s:
            c.case(f"rig-signal-{signal.Signals(signum).name}",
                   c.run(["flash", s.path, rig, *FAST], signum=signum, server=s, vc=vs[1]),
                   vcs=vs)
    bad = c.work / "bad"
    shutil.copytree(RASTER, bad, dirs_exist_ok=True)
    (bad / "y.mcm").write_text(ERRORS.replace("C-863", "C-663"), encoding="utf-8")
    with c.serve(*(vs := chain())) as s:
        c.case("rig-errors", c.run(["flash", s.path, bad / "raster.rig.toml", *FAST]),
               c.run(["emulate", "--rig", bad / "raster.rig.toml"]), server=s, vcs=vs)


def emulated(c: Cases) -> None:
    """`emulate` as a process: its first lines, a flash through it, Ctrl-C, its log."""
    prog = c.file("p.mcm", PROGRAM)
    rig = c.work / "raster" / "raster.rig.toml"
    runs = {"one": (["--address", "3"], ["flash", prog, "--address", "3"]),
            "state": (["--state", c.work / "out" / "state.json"], ["flash", prog]),
            "addresses": (["--addresses", "0,1", "--target", "C-663"], ["flash", rig]),
            "rig": (["--rig", rig], ["flash", rig])}
    for name, (args, flash) in runs.items():
        log = c.work / "out" / "emulate.log"
        proc = subprocess.Popen([sys.executable, "-m", "mercmac", "emulate", *map(str, args),
                                 "--log", str(log)], stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True, cwd=c.work)
        first = proc.stdout.readline()
        path = proc.stdout.readline().strip()
        c.paths.insert(0, path)
        said = c.run([flash[0], path, *flash[1:], *FAST])
        proc.send_signal(signal.SIGINT)
        try:
            rest, err = proc.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            proc.kill()
            rest, err = proc.communicate()
            err += "\n!! still serving 30 s after SIGINT: killed\n"
        c.case(f"emulate-{name}", c.norm(f"$ mercmac emulate {' '.join(map(str, args))}\n"
                                         f"exit {proc.returncode}\n--- stdout\n{first}{path}\n"
                                         f"{rest}--- stderr\n{err}"), said)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--work", type=Path, default=None,
                        help="where the cases' files are written (default: a new temporary "
                             "folder; its path shows as <work> in the outputs)")
    args = parser.parse_args()
    out = args.out.resolve()
    out.mkdir(parents=True, exist_ok=True)
    work = (args.work or Path(tempfile.mkdtemp(prefix="mercmac-flash-dumps-"))).resolve()
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    c = Cases(out, work)
    c.reset()
    singles(c)
    rigs(c)
    emulated(c)
    print(f"{len(list(out.glob('*')))} files in {out}", file=sys.stderr)


if __name__ == "__main__":
    main()
