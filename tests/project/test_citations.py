"""The repository explains itself: a comment cites a page of docs/ (or the controller's
manual, MS176E §x.y), never a document a clone does not hold, such as the product contract,
the house style or the tracker's issues. Every docs page cited is one of the fixed pages, and
a heading cited with it is one of that page's headings, so a reader always finds the place."""
from __future__ import annotations

import re
import shutil
import subprocess

import pytest

from helpers.docs import HEADINGS
from helpers.paths import ROOT

# The pages of docs/ and their headings, by page name
PAGES = {page.removesuffix(".md"): tuple(headings) for page, headings in HEADINGS.items()}

# What a clone cannot follow: the contract's sections, the style file, the tracker.
UNFOLLOWABLE = re.compile(r"SPEC §|STYLE\.md|\b[Ii]ssues? \d+")
# docs/NAME.md, not a path that merely ends in it (editors/x/docs/y.md is no page of ours)
CITED = re.compile(r"(?<![\w./-])docs/([\w.-]+)\.md\b")
# `(docs/NAME.md, "Heading")`, the heading perhaps on the next line of a comment
HEADED = re.compile(r"(?<![\w./-])docs/([\w-]+)\.md,\s+(?:(?://|#)\s*)?\"([^\"\n]+)\"")

OWNED_ELSEWHERE = ("README.md",)  # the README and docs/ cite the contract's words as pages


def _tracked() -> dict[str, str]:
    if shutil.which("git") is None:
        pytest.skip("needs git to list the tracked files")
    listed = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True,
                            timeout=60)
    if listed.returncode != 0:
        pytest.skip("needs a git checkout to list the tracked files (this is not one)")
    texts = {}
    for name in listed.stdout.decode("utf-8", "surrogateescape").split("\0"):
        path = ROOT / name
        if not name or not path.is_file():  # deleted in the work tree, or a submodule
            continue
        data = path.read_bytes()
        if b"\0" not in data[:8192]:  # text only: an icon cites nothing
            texts[name] = data.decode("utf-8", "replace")
    return texts


@pytest.fixture(scope="module")
def tracked() -> dict[str, str]:
    return _tracked()


def _ours(name: str) -> bool:
    return (not name.startswith("docs/") and name not in OWNED_ELSEWHERE
            and name.rsplit("/", 1)[-1] != "test_citations.py")


def test_no_file_cites_what_a_clone_does_not_hold(tracked):
    found = {}
    for name, text in tracked.items():
        if _ours(name):
            lines = [f"{number}: {line.strip()}" for number, line
                     in enumerate(text.splitlines(), 1) if UNFOLLOWABLE.search(line)]
            if lines:
                found[name] = lines
    assert not found, ("cite a page of docs/ (or MS176E §x.y), or say what happened, "
                       f"instead of: {found}")


def test_every_docs_page_cited_is_one_of_the_pages(tracked):
    wrong = {f"{name}: docs/{page}.md" for name, text in tracked.items()
             if name.rsplit("/", 1)[-1] != "test_citations.py"
             for page in CITED.findall(text) if page not in PAGES}
    assert not wrong, f"no such page (the pages: {', '.join(PAGES)}): {sorted(wrong)}"


def test_every_heading_cited_is_one_of_its_pages_headings(tracked):
    wrong = {f'{name}: docs/{page}.md, "{heading}"' for name, text in tracked.items()
             if name.rsplit("/", 1)[-1] != "test_citations.py"
             for page, heading in HEADED.findall(text)
             if page in PAGES and heading not in PAGES[page]}
    assert not wrong, f"no such heading on that page: {sorted(wrong)}"


@pytest.mark.parametrize("line, cites", [
    ("# as the contract says (SPEC §5)", True),
    ('"""House style: STYLE.md "The floors"."""', True),
    ("# (issue 26: it flashed on and exited 0)", True),
    ("# issues 7 and 20 put hostile programs through them", True),
    ("# Issue 25: names are never paths", True),
    ('# (docs/simulator.md, "Fast-forward"); MS176E §3.8.4', False),
    ("# a tissue 3 mm thick; the issue at hand", False),
])
def test_the_pattern_finds_citations_and_only_them(line, cites):
    assert bool(UNFOLLOWABLE.search(line)) is cites


@pytest.mark.parametrize("text, pages", [
    ('see (docs/rigs.md, "Wires") and docs/cli.md', ["rigs", "cli"]),
    ("editors/vscode/docs/notes.md and ./docs/x.md are not ours; docs/raster.png is no page",
     []),
])
def test_the_page_pattern_reads_citations(text, pages):
    assert CITED.findall(text) == pages


def test_a_heading_on_the_next_comment_line_is_read():
    text = '# the lines end alike (docs/simulator.md,\n# "What sim writes") and so on'
    assert HEADED.findall(text) == [("simulator", "What sim writes")]
