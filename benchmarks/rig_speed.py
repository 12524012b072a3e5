"""Rigs of many controllers, and a stage chasing its target, run to their end: wall time and
peak memory.

    python benchmarks/rig_speed.py [--give-up SECONDS]

Each case is `mercmac sim RIG --until T --format json` in a fresh interpreter (start-up
included, as sim_speed.py measures), given up after GIVE_UP seconds ("over"); its peak memory
is the child's maximum resident set (os.wait4). A run's memory is bounded by its programs and
its listing caps (10,000 reports, LED changes and events per controller), not by how long it
runs. Goals (docs/simulator.md, "Fast-forward"): every case at most 2 s of wall time; (d), (e)
and (f) at most 150 MB (sixteen controllers list sixteen times as much).

(a) 16 controllers, unwired, each `macro spin { CN 1, CF 1, TP x i, goto spin }` (i = 0-15):
    loops of 16 lengths, which a rig skips only when each controller skips on its own;
    1 h and 1500 d;
(b) the same 16 programs wired in eight handshake pairs (a raster-like four-phase handshake
    between the two of each pair): 1 h;
(c) the raster example (examples/rigs/raster/) and 14 unwired busy controllers: 1 h;
(d) three C-863/C-663 controllers in a token ring of raw macros (w3): to 3600 s;
(e) two controllers, one driving the other's input, each looping RP3000 (slow): to 3600 s;
(f) `macro chase { MR 500, TT, MR 25000, CN 1, WA 5, CF 1, goto chase }`, a program (a rig of
    one) on the C-863 and the C-663: the target runs ahead to the soft limit, then the stage
    cruises to it, each pass commanding the move it is on again; 1 h and 1500 d.
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
RASTER = HERE.parent / "examples" / "rigs" / "raster"
GIVE_UP = 120  # s of wall time for one run

SPIN = "target C-863\nmacro spin {{ CN 1, CF 1{tps}, goto spin }}\nautostart {{ goto spin }}\n"
# a four-phase handshake: the leader moves, raises out1 and waits for the follower's out2
LEADER = ("target C-863\nmacro go {{ MR 100, WS 0, CN 1, WN 2, CF 1, WF 2{tps}, goto go }}\n"
          "autostart {{ goto go }}\n")
FOLLOWER = ("target C-863\nmacro go { WN 1, MR 10, WS 0, CN 2, WF 1, CF 2, goto go }\n"
            "autostart { goto go }\n")
W3 = {  # (address, model, raw macros)
    "left": (7, "C-863", "[MC00] EM10\n[MC10] CN1,WN3,EM29,CF4,CF1,WF3,RP250\n"
                         "[MC29] TT,TT,XF3\n"),
    "z": (9, "C-663", "[MC00] EM12\n[MC12] WN2,CF4,TC1,CN1,WF2,EM20,TT,CF1,MA3917,RP250\n"
                      "[MC20] XN2\n"),
    "b2": (8, "C-863", "[MC00] EM7\n[MC07] WN1,MA-4531,CN2,WF1,MR2530,EM31,CF2,RP250\n"
                       "[MC31] XF1,XF2,TT,MA4425\n"),
}
W3_WIRES = ["z.out1 -> left.in3", "left.out1 -> b2.in1", "b2.out2 -> z.in2"]
SLOW = {
    "x": (1, "C-863", "[MC00] WA2,EM17\n[MC07] MA-4796\n"
                      "[MC17] WF1,EM7,CP10,EM24,CP10,MR-2716,CN3,RP3000\n[MC24] MR-1904\n"),
    "v": (9, "C-863", "[MC00] WA2,EM3\n[MC03] WA0,CF3,TT,TT,TT,WA0,WA0,CN3,RP3000\n"),
}
SLOW_WIRES = ["v.out3 -> x.in1"]


def _tps(i: int) -> str:
    return "".join(", TP" for _ in range(i))


def write_rig(folder: Path, programs: dict[str, tuple[int, str, str]], wires: list[str],
              extra: str = "") -> Path:
    """NAME.mcm per controller and r.rig.toml in FOLDER: {name: (address, model, source)}."""
    lines = [f"wires = {json.dumps(wires)}", extra]  # a JSON list of strings is TOML's
    for name, (address, model, source) in programs.items():
        text = source if source.startswith("target") else f"target {model}\n{source}"
        (folder / f"{name}.mcm").write_text(text, encoding="utf-8")
        lines += [f"[controllers.{name}]", f"address = {address}", f'model = "{model}"',
                  f'program = "{name}.mcm"', ""]
    path = folder / "r.rig.toml"
    path.write_text("\n".join(lines), encoding="utf-8")
    return path


CHASE = ("target {model}\nmacro chase {{\n  MR 500, TT, MR 25000, CN 1, WA 5, CF 1, goto chase\n}}\n"
         "autostart {{ goto chase }}\n")


def chase(model: str):
    """The chase loop as a program file on `model`."""
    def make(folder: Path) -> Path:
        path = folder / "chase.mcm"
        path.write_text(CHASE.format(model=model), encoding="utf-8")
        return path
    return make


def sixteen_unwired(folder: Path) -> Path:
    return write_rig(folder, {f"c{i}": (i, "C-863", SPIN.format(tps=_tps(i)))
                              for i in range(16)}, [])


def sixteen_in_pairs(folder: Path) -> Path:
    programs, wires = {}, []
    for pair in range(8):
        lead, follow = f"a{pair}", f"b{pair}"
        programs[lead] = (2 * pair, "C-863", LEADER.format(tps=_tps(2 * pair)))
        programs[follow] = (2 * pair + 1, "C-863", FOLLOWER)
        wires += [f"{lead}.out1 -> {follow}.in1", f"{follow}.out2 -> {lead}.in2"]
    return write_rig(folder, programs, wires)


def raster_and_busy(folder: Path) -> Path:
    for name in ("x.mcm", "y.mcm"):
        shutil.copyfile(RASTER / name, folder / name)
    raster = (RASTER / "raster.rig.toml").read_text(encoding="utf-8")
    busy = "".join(f"\n[controllers.c{i}]\naddress = {i}\nmodel = \"C-863\"\n"
                   f"program = \"c{i}.mcm\"\n" for i in range(2, 16))
    for i in range(2, 16):
        (folder / f"c{i}.mcm").write_text(SPIN.format(tps=_tps(i)), encoding="utf-8")
    path = folder / "r.rig.toml"
    path.write_text(raster + busy, encoding="utf-8")
    return path


CASES = [  # (name, rig maker, --until, --buttons)
    ("(a) 16 unwired, 1 h", sixteen_unwired, "1h", ""),
    ("(a) 16 unwired, 1500 d", sixteen_unwired, "1500d", ""),
    ("(b) 16 in 8 handshake pairs, 1 h", sixteen_in_pairs, "1h", ""),
    ("(c) raster + 14 unwired busy, 1 h", raster_and_busy, "1h", "x:1@0-100ms"),
    ("(d) w3 token ring, 3600 s", lambda f: write_rig(f, W3, W3_WIRES), "3600s", ""),
    ("(e) slow pair, 3600 s", lambda f: write_rig(f, SLOW, SLOW_WIRES), "3600s", ""),
    ("(f) chase, C-863, 1 h", chase("C-863"), "1h", ""),
    ("(f) chase, C-863, 1500 d", chase("C-863"), "1500d", ""),
    ("(f) chase, C-663, 1 h", chase("C-663"), "1h", ""),
    ("(f) chase, C-663, 1500 d", chase("C-663"), "1500d", ""),
]


def measure(rig: Path, until: str, buttons: str, give_up: float) -> tuple[float | None, float]:
    """Wall seconds (None: over give_up) and peak memory (MB) of one run."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    args = [sys.executable, "-m", "mercmac", "sim", str(rig), "--until", until,
            "--format", "json"] + (["--buttons", buttons] if buttons else [])
    start = time.perf_counter()
    child = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env,
                             cwd=tempfile.gettempdir())
    while True:
        pid, status, usage = os.wait4(child.pid, os.WNOHANG)
        if pid:
            break
        if time.perf_counter() - start > give_up:
            child.kill()
            _, status, usage = os.wait4(child.pid, 0)
            return None, usage.ru_maxrss / 1024
        time.sleep(0.01)
    wall = time.perf_counter() - start
    code = os.waitstatus_to_exitcode(status)
    if code != 0:  # a rig `check` refuses runs nothing: no figure
        raise SystemExit(f"{rig}: exit {code}: {child.stderr.read().decode()}")
    return wall, usage.ru_maxrss / 1024  # KB on Linux


def main() -> None:
    give_up = float(sys.argv[sys.argv.index("--give-up") + 1]) if "--give-up" in sys.argv \
        else GIVE_UP
    for name, make, until, buttons in CASES:
        with tempfile.TemporaryDirectory() as folder:
            wall, peak = measure(make(Path(folder)), until, buttons, give_up)
        shown = f"over {give_up:g} s" if wall is None else f"{wall:.2f} s"
        print(f"{name}: {shown} wall, peak {peak:.0f} MB")


if __name__ == "__main__":
    main()
