"""Hostile rig folders for the rig fuzz tests: random keys, types, names, paths
and wires, written as TOML (sometimes broken) beside programs, symlinks and a secret that
lies outside the rig's folder and must never be read, shown or written.

    ROOT/outside/secret.mcm      what no rig may reach (its text holds SECRET)
    ROOT/rig/r.rig.toml          the hostile rig, its programs beside it and below it

One `random.Random` drives each rig, so that Hypothesis (`st.randoms()`) and a plain
seeded loop (the language server's test) draw from the same space.
"""
from __future__ import annotations

import os
import random
from pathlib import Path

from helpers.paths import EXAMPLES
from helpers.rigs import X as GOOD, Y as OTHER  # the two wired controllers, well formed

SECRET = "aws_secret_access_key = SECRET-d41d8cd98f00"
WRONG = "target C-863\nautostart { SC 2, DP 200, WN 3, CN 1 }\n"  # SC in macro 0, model
NAMES = ["x", "y", "z", "left", "b2", "bad name", "../x", "a" * 300, "x\x1b[2J", "é", "1x", ""]
RIG_NAMES = ["raster", "../../x", "/abs/x", "a/b", "x\x1b]52;c;cHduZWQ=\x07", "\u202eevil",
             "n" * 300, "", "ok_name", "a\r\nall controllers verified"]
PROGRAMS = ["x.mcm", "sub/y.mcm", "y.mcm", "../outside/secret.mcm", "{outside}/secret.mcm",
            "x\x00.mcm", "/etc/passwd", "/proc/self/environ", "notes.txt", "r.rig.toml",
            "link.mcm", "sub/../../outside/secret.mcm", "missing.mcm", "dir.mcm",
            "fifo.mcm", "wrong.mcm", "linkdir/secret.mcm", "X.MCM", ""]
ADDRESSES = [0, 1, 2, 15, 16, -1, 99, "0", 1.5, True, 10 ** 30, "9" * 5000, [1]]
MODELS = ["C-863", "C-663", "c-663", "C-999", "", 1, ["C-863"]]
KEYS = ["adress", "programme", "box", "name", "extra"]
ARROWS = ["->", "→", "=>", "-", ""]


def make_rig(rnd: random.Random, root: Path) -> Path:
    """A hostile rig in ROOT/rig (the secret in ROOT/outside); the rig file's path."""
    outside, folder = root / "outside", root / "rig"
    outside.mkdir(parents=True, exist_ok=True)
    (outside / "secret.mcm").write_text(SECRET + "\n", encoding="utf-8")
    folder.mkdir(parents=True, exist_ok=True)
    _programs(folder, outside)
    text = _toml(_table(rnd, outside))
    path = folder / "r.rig.toml"
    path.write_text(_mangled(rnd, text), encoding="utf-8", newline="")
    return path


def tree(root: Path, *, skip: Path | None = None) -> dict[str, bytes | str]:
    """What lies under ROOT (but under `skip`): each file's bytes, a link's target, by path."""
    found: dict[str, bytes | str] = {}
    for folder, dirs, files in os.walk(root):
        if skip is not None and Path(folder).resolve() == skip.resolve():
            dirs[:] = []
            continue
        for name in dirs + files:
            path = Path(folder) / name
            if path.is_symlink():
                found[str(path)] = "-> " + os.readlink(path)
            elif path.is_file():
                found[str(path)] = path.read_bytes()
    return found


def _programs(folder: Path, outside: Path) -> None:
    (folder / "sub").mkdir(exist_ok=True)
    (folder / "dir.mcm").mkdir(exist_ok=True)
    for name, text in (("x.mcm", GOOD), ("y.mcm", OTHER), ("sub/y.mcm", OTHER),
                       ("wrong.mcm", WRONG), ("notes.txt", GOOD),
                       ("four-modes.mcm", (EXAMPLES / "four-modes.mcm").read_text("utf-8"))):
        (folder / name).write_text(text, encoding="utf-8")
    for link, to in (("link.mcm", outside / "secret.mcm"), ("linkdir", outside)):
        if not (folder / link).is_symlink():
            (folder / link).symlink_to(to)
    if not (folder / "fifo.mcm").exists():
        os.mkfifo(folder / "fifo.mcm")


def _table(rnd: random.Random, outside: Path) -> dict:
    table: dict = {}
    if rnd.random() < 0.5:
        table["name"] = _pick(rnd, RIG_NAMES + [3, ["x"]])
    names = rnd.sample(NAMES[:4], rnd.randint(1, 3)) if rnd.random() < 0.8 else \
        [_pick(rnd, NAMES) for _ in range(rnd.randint(0, 3))]
    table["controllers"] = {n: _controller(rnd, outside) for n in names}
    if rnd.random() < 0.1:
        table["controllers"] = _pick(rnd, ["x", 3, [1]])
    if rnd.random() < 0.5:
        table["box"] = _pick(rnd, names + ["nobody", 1])
    if rnd.random() < 0.3:
        table["box_buttons"] = _pick(rnd, [[1, 2], [1, 1], [0, 5], ["1"], [], 3])
    if rnd.random() < 0.3:
        table["joystick"] = {_pick(rnd, ["X", "Y", "Z", "W"]): _pick(rnd, names + ["q", 2])
                             for _ in range(rnd.randint(1, 3))}
    if rnd.random() < 0.8:
        table["wires"] = [_wire(rnd, names) for _ in range(rnd.randint(0, 5))]
    if rnd.random() < 0.1:
        table[_pick(rnd, KEYS)] = 1
    return table


def _controller(rnd: random.Random, outside: Path) -> dict:
    entry: dict = {}
    if rnd.random() < 0.95:
        entry["address"] = _pick(rnd, ADDRESSES) if rnd.random() < 0.4 else rnd.randint(0, 15)
    if rnd.random() < 0.95:
        entry["model"] = _pick(rnd, MODELS) if rnd.random() < 0.3 else "C-663"
    if rnd.random() < 0.95:
        program = _pick(rnd, PROGRAMS) if rnd.random() < 0.6 else _pick(rnd, ["x.mcm", "y.mcm"])
        entry["program"] = program.replace("{outside}", str(outside)) \
            if isinstance(program, str) else program
    if rnd.random() < 0.05:
        entry[_pick(rnd, KEYS)] = "x"
    return entry


def _wire(rnd: random.Random, names: list[str]) -> object:
    if rnd.random() < 0.1:
        return _pick(rnd, [3, ["x"], "", "x.out1", "garbage"])
    ends = []
    for kind in ("out", "in"):
        name = _pick(rnd, names + ["nobody"]) if names else "x"
        number = _pick(rnd, ["1", "2", "3", "4", "0", "5", "9" * 5000, "\u0661", "²"])
        ends.append(f"{name}.{_pick(rnd, [kind, kind, 'in', 'out'])}{number}")
    return f" {ends[0]} {_pick(rnd, ARROWS)} {ends[1]} "


def _mangled(rnd: random.Random, text: str) -> str:
    """TOML that is sometimes broken: cut, a character spliced in, a BOM, CR line ends."""
    roll = rnd.random()
    at = rnd.randint(0, len(text))
    if roll < 0.05:
        return text[:at]
    if roll < 0.1:
        return text[:at] + _pick(rnd, ["[", "]", '"', "=", "\x00", "\ufeff", "[[", "\x1b"]) \
            + text[at:]
    if roll < 0.15:
        return "\ufeff" + text.replace("\n", "\r\n")
    if roll < 0.18:
        return "a = [" * 2000 + text
    return text


def _pick(rnd: random.Random, choices: list):
    return choices[rnd.randrange(len(choices))]


# -- a small TOML writer (tomllib reads TOML; the standard library writes none) --------

def _toml(table: dict) -> str:
    lines = [f"{_key(k)} = {_value(v)}" for k, v in table.items()
             if not isinstance(v, dict)]
    for key, value in table.items():
        if isinstance(value, dict):
            lines += _tables([key], value)
    return "\n".join(lines) + "\n"


def _tables(path: list[str], table: dict) -> list[str]:
    out = [f"[{'.'.join(_key(p) for p in path)}]"]
    out += [f"{_key(k)} = {_value(v)}" for k, v in table.items() if not isinstance(v, dict)]
    for key, value in table.items():
        if isinstance(value, dict):
            out += _tables(path + [key], value)
    return out


def _key(key: str) -> str:
    bare = key and all(c.isascii() and (c.isalnum() or c in "_-") for c in key)
    return key if bare else _string(key)


def _value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return str(value)
    if isinstance(value, list):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{_key(k)} = {_value(v)}" for k, v in value.items()) + "}"
    if isinstance(value, str) and value.isdigit() and value.isascii() and len(value) > 100:
        return value  # a bare integer too long for int(): tomllib's own ValueError
    return _string(value)


def _string(text: str) -> str:
    out = []
    for c in text:
        if c in '"\\':
            out.append("\\" + c)
        elif ord(c) < 0x20 or ord(c) == 0x7F:
            out.append(f"\\u{ord(c):04x}")
        else:
            out.append(c)
    return '"' + "".join(out) + '"'
