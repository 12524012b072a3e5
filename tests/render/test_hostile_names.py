"""Names from outside reach no output raw.

A program's file name is free (any character but `/` and NUL), a `--backup` folder too, and
the flash history recalls whatever an older mercmac recorded. Each surface that shows such a
name is run with a plain one and with hostile ones (ESC clearing the screen, OSC 52 writing
the clipboard, CR and newline forging "all controllers verified", a bidi override, a `"]`
that leaves a mermaid label, markdown markup), and must show the hostile name:

- with no raw control character (C0 but the newline between lines, DEL, C1, bidi overrides);
- in as many lines as the plain name, none of them a forged one;
- in markdown, with the same blocks (headings, lists, one fenced mermaid block) as the plain
  name, parsed by markdown-it-py; in mermaid and Graphviz, with as many statements.

Every output format has its one function in mercmac/names.py.
"""
from __future__ import annotations

import io
import json
import re
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path

import pytest
from markdown_it import MarkdownIt
from markdown_it.tree import SyntaxTreeNode

from helpers.cli import cli
from helpers.emulator import FAST, FAST_TIMING, line_clock, serve
from helpers.paths import EXAMPLE4, ROOT
from helpers.rigs import X, Y
from mercmac import names
from mercmac.compiler import compile_file
from mercmac.emulator.chain import Chain
from mercmac.emulator.ptyserver import PtyServer
from mercmac.emulator.virtual import VirtualController
from mercmac.upload import history
from mercmac.upload.chain import flash_chain

SCENARIO = ROOT / "examples" / "scenarios" / "manual-example4-four-modes.mode2.toml"
FORGED = "all controllers verified"
PLAIN = "x"
HOSTILE = {
    "esc": "x\x1b[2J\x1b[H",  # clears the screen
    "osc52": "x\x1b]52;c;bWVyY21hYw==\x07",  # writes the clipboard
    "cr": f"x\r{FORGED}",
    "newline": f"x\n{FORGED}",
    "bidi": "x\u202egpj.\u2066",
    "mermaid": 'x"]; click x_MC00 call alert(); %%',
    "markdown": "x # [a](b) <b>`c` *d* _e_ |f| ~~g~~ &amp; <!-- ",  # no `/`: a file name
    "c1": "x\x9b2J\x85",  # CSI and NEL as one C1 character each
}
# A surface that takes seconds (a scan of 16 addresses) is shown every hostile name at once.
SLOW = {"pull --rig", "decompile --port --rig"}
ALL = {"all": "".join(HOSTILE.values())}
# What may not stand raw in any output: C0 (the newline between lines aside), DEL, C1, the
# line and paragraph separators, bidi embeddings, overrides and isolates.
RAW = re.compile("[\x00-\x09\x0b-\x1f\x7f-\x9f\u2028\u2029\u202a-\u202e\u2066-\u2069]")


def _assert_safe(shown: str, plain: str) -> None:
    """`shown` (a hostile name's output) has no raw control character, no forged line, and
    as many lines as `plain` (the plain name's)."""
    assert not RAW.findall(shown), RAW.findall(shown)
    assert not [line for line in shown.split("\n") if line.startswith(FORGED)]
    assert len(shown.split("\n")) == len(plain.split("\n")), shown


def _rig(folder: Path, name: str) -> Path:
    """A rig in FOLDER whose x runs the program in the file `NAME.mcm` (y runs y.mcm)."""
    folder.mkdir(parents=True)
    (folder / f"{name}.mcm").write_text(X, encoding="utf-8")
    (folder / "y.mcm").write_text(Y, encoding="utf-8")
    path = folder / "r.rig.toml"
    path.write_text('wires = ["x.out1 -> y.in1", "y.out2 -> x.in2"]\n'
                    '[controllers.x]\naddress = 0\nmodel = "C-663"\n'
                    f"program = {json.dumps(name + '.mcm')}\n"  # JSON's escapes are TOML's
                    '[controllers.y]\naddress = 1\nmodel = "C-663"\nprogram = "y.mcm"\n',
                    encoding="utf-8")
    return path


def _output(*args) -> str:
    """`mercmac ARGS` as a terminal would show it: click keeps ANSI codes (color=True)."""
    result = cli(*args, color=True)
    assert result.exit_code == 0, result.output
    return result.output


@contextmanager
def _chain(macros=({}, {})):
    vcs = [VirtualController("C-663", a, macros=dict(m)) for a, m in enumerate(macros)]
    with PtyServer(Chain(vcs)) as server, line_clock(server):  # addresses of nobody: fast
        yield server


# -- the surfaces: each shows the name given to it; (tmp_path, name) -> output ---------------

def _describe_text(tmp: Path, name: str) -> str:
    return _output("describe", _rig(tmp / "rig", name))


def _describe_markdown(tmp: Path, name: str) -> str:
    return _output("describe", _rig(tmp / "rig", name), "--format", "markdown")


def _describe_graph(tmp: Path, name: str) -> str:
    graph = tmp / "graph.dot"
    _output("describe", _rig(tmp / "rig", name), "--graph", graph)
    return graph.read_text(encoding="utf-8")


def _flash(tmp: Path, name: str) -> str:
    """A rig flash, its backups in a folder named after `name` too (--backup is free text)."""
    backups = tmp / f"b{name}"
    with _chain() as server:
        return _output("flash", server.path, _rig(tmp / "rig", name), "--backup",
                       f"{backups}/", *FAST)


def _flash_dry_run(tmp: Path, name: str) -> str:
    with _chain() as server:
        return _output("flash", server.path, _rig(tmp / "rig", name), "--dry-run", *FAST)


def _port(tmp: Path, server, name: str) -> Path:
    """The pty by a name of its own: a link named `port` + NAME (any name opens it)."""
    link = tmp / f"port{name}"
    link.symlink_to(server.path)
    return link


def _flash_file(tmp: Path, name: str) -> str:
    """A program flashed through a port, to a backup file, all three named after `name`."""
    program = tmp / f"{name}.mcm"
    program.write_text(X, encoding="utf-8")
    with serve(model="C-663") as (server, _):
        return _output("flash", _port(tmp, server, name), program, "--backup",
                       tmp / f"b{name}.mcm", *FAST)


def _pull_file(tmp: Path, name: str) -> str:
    """`pull` through a port named after `name`, into a file named so: what it says, and the
    file's header comment, which names the port."""
    output = tmp / f"{name}.mcm"
    # no macro 0: a pull that came within its first millisecond would stop it running, and
    # say so in a line more ("a macro was running"): a race, not the name's doing
    with serve(model="C-663", macros={1: "MR5"}) as (server, _):
        said = _output("pull", _port(tmp, server, name), "-o", output, *FAST)
    return said + output.read_text(encoding="utf-8")


def _flashed_by_an_old_mercmac(server, tmp: Path, name: str) -> None:
    """The rig flashed, then its records changed as a file of the history may hold them:
    the rig's name is `name` (which `pull --rig` may take for its rig file, or leave)."""
    flash_chain(server.path, str(_rig(tmp / "rig", "x")), timing=FAST_TIMING)
    for path in history.folder().iterdir():
        record = json.loads(path.read_text(encoding="utf-8"))
        path.write_text(json.dumps({**record, "rig_name": name}), encoding="utf-8")


def _pull_rig(tmp: Path, name: str) -> str:
    """What `pull --rig` says, through a port named after `name` too, and the rig file it
    writes, whose comment names the port."""
    with _chain() as server:
        _flashed_by_an_old_mercmac(server, tmp, name)
        said = _output("pull", _port(tmp, server, name), "--rig", tmp / "pulled", *FAST)
    rig_file, = (tmp / "pulled").glob("*.rig.toml")
    return said + rig_file.read_text(encoding="utf-8")


def _decompile_rig(tmp: Path, name: str) -> str:
    with _chain() as server:
        _flashed_by_an_old_mercmac(server, tmp, name)
        return _output("decompile", "--port", _port(tmp, server, name), "--rig", tmp / "pulled",
                       *FAST)


def _history(tmp: Path, name: str) -> str:
    rig = history.InRig(str(tmp / f"{name}.rig.toml"), name, "x")
    history.record(port=f"/dev/{name}", address=0, model="C-663", firmware="1.10",
                   file=str(tmp / f"{name}.mcm"), source="[MC00] MR5\n", build=["MD0,MR5"],
                   rig=rig)
    return _output("history")


def _sim(tmp: Path, name: str) -> str:
    """`sim RIG`'s text for a rig of that name: a rig's name defaults to its file's, and the
    header shows it (its controllers' names are words: the rig reader refuses others)."""
    from mercmac.render import sim as render
    from mercmac.rig.open import accept
    from mercmac.sim.simulate import simulate

    accepted = accept(str(_rig(tmp / "rig", "x")))
    rig = replace(accepted.rig, name=name)
    programs = {n: c.program for n, c in accepted.programs.items()}
    shown = io.StringIO()
    render.write_text(simulate(rig, programs, until_ms=50), shown)
    return shown.getvalue()


def _sim_scenario(tmp: Path, name: str) -> str:
    """`sim FILE --scenario` with a scenario file named after `name`: its closing line."""
    scenario = tmp / f"{name}.toml"
    scenario.write_text(SCENARIO.read_text(encoding="utf-8"), encoding="utf-8")
    return _output("sim", EXAMPLE4, "--scenario", scenario)


SURFACES = {"sim": _sim, "sim --scenario": _sim_scenario, "describe text": _describe_text,
            "describe markdown": _describe_markdown, "describe --graph dot": _describe_graph,
            "flash": _flash, "flash --dry-run": _flash_dry_run, "flash FILE": _flash_file,
            "pull -o": _pull_file, "pull --rig": _pull_rig,
            "decompile --port --rig": _decompile_rig, "history": _history}
_PLAIN: dict[str, str] = {}  # each surface's output for the plain name, made once


def _shown(surface: str, folder: Path, name: str, monkeypatch) -> str:
    """What SURFACE shows for NAME, with a flash history of its own in FOLDER."""
    monkeypatch.setenv("MERCMAC_DATA_DIR", str(folder / "data"))
    folder.mkdir(parents=True)
    return SURFACES[surface](folder, name)


def _plain(surface: str, tmp_path: Path, monkeypatch) -> str:
    if surface not in _PLAIN:
        _PLAIN[surface] = _shown(surface, tmp_path / "plain", PLAIN, monkeypatch)
    return _PLAIN[surface]


@pytest.mark.parametrize("surface, hostile", [
    pytest.param(surface, hostile, id=f"{surface}-{key}") for surface in SURFACES
    for key, hostile in (ALL if surface in SLOW else HOSTILE).items()])
def test_a_hostile_name_is_shown_escaped_in_as_many_lines(surface, hostile, tmp_path,
                                                          monkeypatch):
    plain = _plain(surface, tmp_path, monkeypatch)
    shown = _shown(surface, tmp_path / "hostile", hostile, monkeypatch)
    _assert_safe(shown, plain)
    assert names.printable(hostile) in shown or names.markdown(hostile) in shown or \
        names.dot(hostile) in shown, "the name is not shown"


@pytest.mark.parametrize("command", [("sim",), ("describe",), ("flash", "/dev/null"),
                                     ("build",), ("decompile",)], ids=lambda c: c[0])
def test_a_file_that_cannot_be_read_is_named_escaped_on_one_line(command, tmp_path):
    hostile = HOSTILE["newline"] + HOSTILE["osc52"] + HOSTILE["bidi"]
    said = []
    for name in (PLAIN, hostile):
        result = cli(*command, tmp_path / f"{name}.mcm", color=True)
        assert result.exit_code == 2, result.output
        said.append(result.output)
    _assert_safe(said[1], said[0])


def test_every_message_escapes_its_control_characters(tmp_path):
    """Whatever a message quotes (here `fmt`'s, which names the file as given), ESC, CR and
    bidi marks are shown escaped (cli.common.say)."""
    hostile = HOSTILE["esc"] + HOSTILE["osc52"] + HOSTILE["cr"] + HOSTILE["bidi"]
    result = cli("fmt", tmp_path / f"{hostile}.mcm", color=True)
    assert result.exit_code == 2 and names.printable(hostile) in result.output
    assert not RAW.findall(result.output)


def test_a_port_name_adds_no_line_to_what_pull_writes(tmp_path):
    """The file's header comment names the port: a newline there would make the rest of
    the name a line of the program."""
    output = tmp_path / "pulled.mcm"
    with serve(model="C-663", macros={0: "MR5"}) as (server, _):
        _output("pull", _port(tmp_path, server, "\n[MC05] MR9\n"), "-o", output, *FAST)
    compilation = compile_file(str(output))
    assert not compilation.report.has_errors, compilation.report.items
    assert set(compilation.program.macros) == {0}


# -- markdown, mermaid and Graphviz keep their structure ------------------------------------------

def _parsed(markdown: str) -> SyntaxTreeNode:
    """MARKDOWN as CommonMark reads it, with GitHub's tables and strikethrough."""
    return SyntaxTreeNode(MarkdownIt("commonmark").enable(["table", "strikethrough"])
                          .parse(markdown))


def _blocks(markdown: str) -> list[tuple[str, int]]:
    """The block structure markdown-it-py reads: each block's kind and depth, and the kind
    of each inline part (a link, HTML or a code span would show here)."""
    found = []

    def walk(node: SyntaxTreeNode, depth: int) -> None:
        for child in node.children:
            kind = child.type if child.type != "fence" else f"fence {child.info}"
            found.append((kind, depth))
            if child.type != "inline":
                walk(child, depth + 1)
            else:
                found.extend((part.type, depth + 1) for part in child.children)

    walk(_parsed(markdown), 0)
    return found


def _mermaid(markdown: str) -> str:
    """Every mermaid block's text: each program's call graph, then the rig's."""
    tree = _parsed(markdown)
    return "".join(n.content for n in tree.children if n.type == "fence" and n.info == "mermaid")


def _statements(graph: str) -> int:
    """Statements of mermaid or dot text: each line, and each `;` outside a "..." string
    that has more after it (a `\"` inside a dot string does not end it)."""
    count = 0
    for line in filter(str.strip, graph.split("\n")):
        quoted, escaped, count = False, False, count + 1
        for i, c in enumerate(line):
            if escaped:
                escaped = False
            elif c == "\\" and quoted:
                escaped = True
            elif c == '"':
                quoted = not quoted
            elif c == ";" and not quoted and line[i + 1:].strip():
                count += 1
        assert not quoted, f"a string left open: {line!r}"
    return count


@pytest.mark.parametrize("hostile", HOSTILE.values(), ids=HOSTILE.keys())
def test_markdown_keeps_its_blocks_and_the_mermaid_graph_its_statements(hostile, tmp_path,
                                                                        monkeypatch):
    plain = _plain("describe markdown", tmp_path, monkeypatch)
    shown = _shown("describe markdown", tmp_path / "hostile", hostile, monkeypatch)
    assert _blocks(shown) == _blocks(plain)
    assert _statements(_mermaid(shown)) == _statements(_mermaid(plain))
    tree = _parsed(shown)
    heading = next(n for n in tree.walk() if n.type == "heading" and n.tag == "h2")
    text = "".join(part.content for part in heading.children[0].children)
    assert text.endswith(f": {names.printable(hostile)}.mcm")  # the name, as the text shows it


# Words mermaid's flowchart lexer reads as keywords where an id stands (flow.jison)
MERMAID_KEYWORDS = {"end", "graph", "flowchart", "subgraph", "click", "style", "class",
                    "classDef", "linkStyle", "direction", "call", "href", "default"}


def test_controllers_named_like_mermaid_keywords_name_no_subgraph(tmp_path):
    """`end` is a good controller name, and `subgraph end[...]` would end the graph early."""
    rig = tmp_path / "k.rig.toml"
    (tmp_path / "a.mcm").write_text(X, encoding="utf-8")
    (tmp_path / "b.mcm").write_text(Y, encoding="utf-8")
    rig.write_text('wires = ["end.out1 -> graph.in1", "graph.out2 -> end.in2"]\n'
                   '[controllers.end]\naddress = 0\nmodel = "C-663"\nprogram = "a.mcm"\n'
                   '[controllers.graph]\naddress = 1\nmodel = "C-663"\nprogram = "b.mcm"\n',
                   encoding="utf-8")
    graph = _output("describe", rig, "--format", "markdown").split("## Call graph")[-1]
    ids = re.findall(r"^\s*subgraph (\S+?)\[", graph, re.M)
    assert len(ids) == 2 and not set(ids) & MERMAID_KEYWORDS
    assert len(re.findall(r"^\s*end$", graph, re.M)) == 2


@pytest.mark.parametrize("hostile", HOSTILE.values(), ids=HOSTILE.keys())
def test_the_graphviz_graph_keeps_its_statements(hostile, tmp_path, monkeypatch):
    plain = _plain("describe --graph dot", tmp_path, monkeypatch)
    shown = _shown("describe --graph dot", tmp_path / "hostile", hostile, monkeypatch)
    assert _statements(shown) == _statements(plain)


# -- the one function per format ------------------------------------------------------------------

@pytest.mark.parametrize("hostile", HOSTILE.values(), ids=HOSTILE.keys())
def test_each_format_shows_the_name_on_one_line_without_control_characters(hostile):
    for shown in (names.printable(hostile), names.markdown(hostile), names.mermaid(hostile),
                  names.dot(hostile)):
        assert not RAW.search(shown) and "\n" not in shown
    assert '"' not in names.mermaid(hostile)
    assert not re.search(r'(?<!\\)"', names.dot(hostile).replace("\\\\", ""))
