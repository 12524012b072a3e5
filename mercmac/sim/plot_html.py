"""The `--plot FILE.html` page: the plot's SVG with wheel zoom and drag pan, self-contained.

No network: the picture, the lanes' data (a JSON block for programs) and the
few lines of script are all inline.
"""
from __future__ import annotations

import html
import json
import re

# Wheel: zoom about the pointer. Drag: pan. Double-click or the 0 key: back to the whole run.
_SCRIPT = """
(function () {
  const svg = document.querySelector("#plot svg");
  svg.removeAttribute("width"); svg.removeAttribute("height");
  const box = svg.viewBox.baseVal, home = [box.x, box.y, box.width, box.height];
  const set = (x, y, w, h) => { box.x = x; box.y = y; box.width = w; box.height = h; };
  const at = (e) => { const r = svg.getBoundingClientRect();
    return [box.x + (e.clientX - r.left) / r.width * box.width,
            box.y + (e.clientY - r.top) / r.height * box.height]; };
  svg.addEventListener("wheel", (e) => {
    e.preventDefault();
    const [px, py] = at(e), k = Math.exp(e.deltaY * 0.0015);
    const w = Math.min(home[2], box.width * k), h = Math.min(home[3], box.height * k);
    set(px - (px - box.x) * w / box.width, py - (py - box.y) * h / box.height, w, h);
  }, {passive: false});
  let drag = null;
  svg.addEventListener("pointerdown", (e) => { drag = at(e); svg.setPointerCapture(e.pointerId); });
  svg.addEventListener("pointermove", (e) => { if (!drag) return;
    const [px, py] = at(e); set(box.x + drag[0] - px, box.y + drag[1] - py, box.width, box.height); });
  svg.addEventListener("pointerup", () => { drag = null; });
  const reset = () => set(...home);
  svg.addEventListener("dblclick", reset);
  document.addEventListener("keydown", (e) => { if (e.key === "0") reset(); });
})();
"""

_PAGE = """<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>{title}</title>
<style>
body {{ font-family: sans-serif; margin: 1em; }}
#plot {{ border: 1px solid #ccc; overflow: hidden; }}
#plot svg {{ width: 100%; height: auto; cursor: grab; display: block; }}
p.help {{ color: #555; font-size: 90%; }}
</style>
</head>
<body>
<h1 style="font-size: 120%">{title}</h1>
<p class="help">Lanes: {lanes}. Hatched: time drawn compressed
(fast-forwarded, or idle after the program ended); a red arrow on an edge: a target beyond
the position axis. Wheel: zoom; drag: pan; double-click or 0: the whole run.</p>
<div id="plot">
{svg}
</div>
<script type="application/json" id="mercmac-plot-data">{data}</script>
<script>{script}</script>
</body>
</html>
"""


LANES = "position, buttons, LEDs, macro"  # a single controller's plot (plot.py)


def page(svg: str, data: dict, title: str = "", lanes: str = "") -> str:
    """The HTML page around an SVG plot (matplotlib's), with its data as JSON; `lanes`
    says what the picture shows (a rig's differs)."""
    body = re.sub(r"^<\?xml[^>]*\?>\s*(<!DOCTYPE[^>]*>\s*)?", "", svg)
    # `</` cannot end the JSON block early: `<\\/` is the same JSON string
    text = json.dumps(data, separators=(",", ":")).replace("</", "<\\/")
    return _PAGE.format(title=html.escape(title or "mercmac sim"), svg=body, data=text,
                        script=_SCRIPT, lanes=html.escape(lanes or LANES))
