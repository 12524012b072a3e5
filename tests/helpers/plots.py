"""Reading back what `sim --plot` wrote: the texts of an SVG, and the HTML page's inline
SVG and the lanes' data it carries (docs/simulator.md, "What sim writes")."""
from __future__ import annotations

import json
import re
import xml.etree.ElementTree as ET

SVG = "{http://www.w3.org/2000/svg}"


def svg_texts(svg: str) -> list[str]:
    """Every <text> of an SVG document, stripped, in document order."""
    root = ET.fromstring(svg)
    return ["".join(t.itertext()).strip() for t in root.iter(f"{SVG}text")]


def page_data(page: str) -> dict:
    """The lanes' data the HTML page carries for its zoom and pan script."""
    block = re.search(r'<script type="application/json" id="mercmac-plot-data">(.*?)</script>',
                      page, re.S)
    return json.loads(block.group(1))


def inline_svg(page: str) -> str:
    """The SVG drawing inside the HTML page."""
    return page[page.index("<svg"):page.index("</svg>") + len("</svg>")]
