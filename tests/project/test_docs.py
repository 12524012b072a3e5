"""The docs/ pages explain the repository without the texts outside it: each page has its
fixed headings (code comments cite them by name), every relative link and anchor resolves,
every page renders as CommonMark without stray backticks, and the README links them all."""
from __future__ import annotations

import re
from pathlib import Path

import pytest
from markdown_it import MarkdownIt

from helpers.docs import HEADINGS
from helpers.paths import ROOT

DOCS = ROOT / "docs"
README = ROOT / "README.md"

PAGES = sorted(DOCS.glob("*.md"))
DOCUMENTS = [README, *PAGES]
_MD = MarkdownIt("commonmark")


def _name(path: Path) -> str:
    return str(path.relative_to(ROOT))


def _tokens(path: Path):
    return _MD.parse(path.read_text(encoding="utf-8"))


def _headings(path: Path) -> list[tuple[int, str]]:
    """(level, text as rendered) of every heading: code spans count by their content."""
    tokens = _tokens(path)
    return [(int(t.tag[1]), "".join(c.content for c in tokens[i + 1].children or ()
                                    if c.type in ("text", "code_inline")))
            for i, t in enumerate(tokens) if t.type == "heading_open"]


def slug(text: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation but '-' and '_' dropped,
    each space a '-'."""
    return re.sub(r"[^\w\- ]", "", text.lower()).replace(" ", "-")


def _anchors(path: Path) -> set[str]:
    """Every heading's anchor; a repeated one gets -1, -2, ... as GitHub numbers them."""
    seen: dict[str, int] = {}
    out = set()
    for _, text in _headings(path):
        base = slug(text)
        n = seen.get(base, 0)
        seen[base] = n + 1
        out.add(base if n == 0 else f"{base}-{n}")
    return out


def _links(path: Path) -> list[str]:
    """Every link target and image source of the page."""
    found = []

    def walk(tokens):
        for t in tokens:
            if t.type == "link_open":
                found.append(t.attrs["href"])
            elif t.type == "image":
                found.append(t.attrs["src"])
            walk(t.children or ())

    walk(_tokens(path))
    return found


def _relative(href: str) -> bool:
    return not re.match(r"^[a-zA-Z][a-zA-Z0-9+.-]*:", href) and not href.startswith("//")


def test_the_pages_are_those_listed():
    assert sorted(p.name for p in PAGES) == sorted(HEADINGS)


@pytest.mark.parametrize("page", sorted(HEADINGS))
def test_each_page_has_its_headings(page):
    path = DOCS / page
    assert path.is_file(), f"docs/{page} is missing"
    second = [text for level, text in _headings(path) if level == 2]
    assert second == HEADINGS[page]


def test_the_slug_follows_github():
    assert slug("One table, one model, one renderer") == "one-table-one-model-one-renderer"
    assert slug("Rig rules (MR)") == "rig-rules-mr"
    assert slug("The `.mcm` language") == "the-mcm-language"
    assert slug("Power-on") == "power-on"


@pytest.mark.parametrize("path", DOCUMENTS, ids=_name)
def test_relative_links_resolve(path):
    for href in filter(_relative, _links(path)):
        target, _, anchor = href.partition("#")
        file = (path.parent / target).resolve() if target else path
        assert file.is_file(), f"{_name(path)}: {href}: no such file"
        if anchor and file.suffix == ".md":
            assert anchor in _anchors(file), f"{_name(path)}: {href}: no such heading"


def _outside_code(html: str) -> str:
    """The rendering without the contents of code spans and code blocks."""
    return re.sub(r"<pre>.*?</pre>|<code>.*?</code>", "", html, flags=re.S)


@pytest.mark.parametrize("path", DOCUMENTS, ids=_name)
def test_renders_without_stray_backticks(path):
    text = path.read_text(encoding="utf-8")
    html = _MD.render(text)
    assert html.count("<code") == html.count("</code>")
    assert "`" not in _outside_code(html), f"{_name(path)}: a backtick outside code"

    def texts(tokens):
        for t in tokens:
            if t.type == "text":
                yield t.content
            yield from texts(t.children or ())

    stray = [t for t in texts(_MD.parse(text)) if "`" in t]
    assert stray == [], f"{_name(path)}: unbalanced backticks in {stray[:3]}"
    lines = text.splitlines()
    for fence in (t for t in _MD.parse(text) if t.type == "fence"):
        last = lines[fence.map[1] - 1].strip()  # an unclosed fence runs to the end of the file
        assert last.startswith(fence.markup), f"{_name(path)}:{fence.map[0] + 1}: fence not closed"


def test_readme_links_every_page():
    linked = {(README.parent / href.partition("#")[0]).resolve()
              for href in filter(_relative, _links(README))}
    assert [_name(p) for p in PAGES if p.resolve() not in linked] == []


def test_the_rules_page_is_what_explain_says():
    from mercmac.render.rules_page import markdown

    assert (DOCS / "rules.md").read_text(encoding="utf-8") == markdown(), \
        "regenerate it: python -m mercmac.render.rules_page > docs/rules.md"


def test_each_rule_link_names_a_heading_of_the_page():
    """An editor's diagnostic code and SARIF's helpUri link to the rule's heading."""
    from mercmac.render.explain import ALL
    from mercmac.render.rules_page import PAGE, url

    anchors = _anchors(DOCS / "rules.md")
    for rule in ALL:
        page, _, anchor = url(rule).partition("#")
        assert page == PAGE and anchor in anchors, rule.code
