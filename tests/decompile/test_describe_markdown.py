"""`describe --format markdown` reads as meant in a CommonMark renderer.

The markdown is parsed with markdown-it-py (CommonMark) and its token tree compared with
the text format: the same headings, the same items nested the same way (a loop's buttons
inside the loop's item), each item's text coming back as plain text (no code block, no
emphasis, link or HTML made of a name or a raw line), and the call graph as one fenced
block with the info string `mermaid`.
"""
from __future__ import annotations

import os

import pytest
from markdown_it import MarkdownIt
from markdown_it.tree import SyntaxTreeNode

from helpers.cli import cli
from helpers.emulator import FAST
from helpers.paths import EXAMPLE4, EXAMPLE_FILES, FOUR_MODES
from mercmac.decompile import describe, read_macros


def _tree(markdown: str) -> SyntaxTreeNode:
    return SyntaxTreeNode(MarkdownIt("commonmark").parse(markdown))


def _plain(inline: SyntaxTreeNode) -> str:
    """The text of an inline node, which must be text only: no markup was meant."""
    kinds = {child.type for child in inline.children}
    assert kinds <= {"text"}, f"markup in {inline.content!r}: {kinds}"
    return "".join(child.content for child in inline.children)


def _expected(text: str) -> tuple[str, list]:
    """The text format as (title, [(heading, [(item, [nested items])])])."""
    lines = text.rstrip("\n").split("\n")
    sections: list = []
    for line in lines[1:]:
        if not line:
            continue
        if not line.startswith(" "):
            sections.append((line.removesuffix(":"), []))
        elif line.startswith("      "):
            sections[-1][1][-1][1].append(line.strip())
        else:
            sections[-1][1].append((line.strip(), []))
    return lines[0], sections


def _items(bullets: SyntaxTreeNode) -> list:
    out = []
    for item in bullets.children:
        assert item.type == "list_item"
        paragraph, *rest = item.children
        assert paragraph.type == "paragraph"
        nested = []
        for child in rest:
            assert child.type == "bullet_list", child.type
            nested += [text for text, deeper in _items(child) if not deeper]
        out.append((_plain(paragraph.children[0]), nested))
    return out


def _found(markdown: str) -> tuple[str, list, SyntaxTreeNode]:
    """(title, sections, the one fence) as a CommonMark reader sees them."""
    tree = _tree(markdown)
    nodes = tree.children
    assert not any(n.type in ("code_block", "html_block") for n in tree.walk())
    fences = [n for n in tree.walk() if n.type == "fence"]
    assert len(fences) == 1, [f.info for f in fences]
    assert nodes[0].type == "heading" and nodes[0].tag == "h1"
    title, sections, i = _plain(nodes[0].children[0]), [], 1
    while i < len(nodes):
        head = nodes[i]
        assert head.type == "heading" and head.tag == "h2", head.type
        if _plain(head.children[0]) == "Call graph":
            assert len(nodes) == i + 2 and nodes[i + 1] is fences[0]
            break
        assert nodes[i + 1].type == "bullet_list"
        sections.append((_plain(head.children[0]), _items(nodes[i + 1])))
        i += 2
    return title, sections, fences[0]


def _same_reading(text: str, markdown: str) -> None:
    title, sections, fence = _found(markdown)
    assert (title, sections) == _expected(text)
    assert fence.info == "mermaid" and fence.content.startswith("graph TD\n")


@pytest.mark.parametrize("path", EXAMPLE_FILES, ids=lambda p: p.name)
def test_every_example_reads_as_its_text(path):
    text = cli("describe", path)
    markdown = cli("describe", path, "--format", "markdown")
    if "// expect: " in path.read_text() and text.exit_code == 1:  # errors on purpose:
        macros = read_macros(path.read_text())  # what a controller would hold of it
        text, markdown = (describe(macros, fmt=f) for f in ("text", "markdown"))
    else:
        assert text.exit_code == 0 and markdown.exit_code == 0, markdown.output
        text, markdown = text.stdout, markdown.stdout
    _same_reading(text, markdown)


def test_a_loops_buttons_are_a_list_inside_its_item():
    markdown = cli("describe", EXAMPLE4,
                   "--format", "markdown").stdout
    _, sections, _ = _found(markdown)
    loops = dict(sections)["Polling loops and the buttons they answer"]
    assert [len(nested) for _, nested in loops] == [4, 5, 4]
    assert loops[0][1][0].startswith("while button 1 is held, MC16 (mode_1_button_1): move")


def test_names_and_raw_lines_that_look_like_markup_stay_text():
    """A raw line that does not read as commands is quoted as it is, and names may hold `_`."""
    macros = {0: "EM1,EM2", 1: "MR5*<b>`x`&amp;[a](b)_y_ **z**", 2: "XN1,MR5"}
    names = {2: "_edge_", 0: "autostart"}
    text = describe(macros, names=names)
    markdown = describe(macros, names=names, fmt="markdown")
    assert "MR5*<B>`X`&AMP;[A](B)_Y_**Z**" in text
    _same_reading(text, markdown)


@pytest.mark.skipif(not hasattr(os, "openpty"), reason="needs pseudo-terminals")
def test_port_output_reads_as_its_text(tmp_path, monkeypatch):
    from helpers.emulator import serve

    monkeypatch.setenv("MERCMAC_DATA_DIR", str(tmp_path / "data"))
    with serve() as (server, vc):
        program = FOUR_MODES
        assert cli("flash", server.path, program, "--backup", tmp_path / "b.mcm",
                   *FAST).exit_code == 0
        text = cli("describe", "--port", server.path, *FAST)
        markdown = cli("describe", "--port", server.path, "--format", "markdown", *FAST)
    assert text.exit_code == 0 and markdown.exit_code == 0, markdown.output
    assert "jog (MC02): every 20 ms" in markdown.stdout
    _same_reading(text.stdout, markdown.stdout)
