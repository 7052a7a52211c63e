"""The studio page: plain HTML around ``studio.js`` (hand-written, no build step) and the
report's viewer bundle, which draws the 3-D view inside an iframe (docs/studio.md). The page
holds the design's dimensions (name, unit, value, slider range) and its token; every other
datum arrives over the WebSocket."""

from __future__ import annotations

import html

from screwkit import __version__
from screwkit.report.viewer import script_json
from screwkit.studio.design import Design


def render_page(design: Design, token: str) -> str:
    """The HTML of the studio page of ``design`` (the token is in its script URLs)."""
    e = html.escape
    spec = design.spec
    boot = {"token": token, "name": spec.name, "file": design.path.name,
            "dimensions": [d.as_dict() for d in design.dimensions],
            "mode": design.initial_mode}
    q = f"?token={e(token)}"
    return "".join([
        "<!doctype html><html lang='en'><head><meta charset='utf-8'>",
        "<meta name='viewport' content='width=device-width,initial-scale=1'>",
        f"<title>{e(spec.name)} — screwkit studio</title><link rel='icon' href='data:,'>",
        f"<link rel='stylesheet' href='/static/studio.css{q}'></head><body>",
        "<header><h1>", e(spec.name), "</h1><span class='muted'>", e(design.path.name),
        f" · screwkit studio {e(__version__)}</span><nav>",
        "<button id='undo' disabled>undo</button><button id='redo' disabled>redo</button>",
        "<button id='save' title='write the values into ", e(design.path.name),
        " (a .bak keeps the old file)'>save</button>",
        "<button id='export-report'>export report</button>",
        "<button id='export-csv'>export CSV</button>",
        "<button id='export-spec'>export spec</button></nav></header>",
        "<div id='message' role='status'></div>",
        "<main><section id='left'><div id='view-box'></div>",
        "<div class='bar'><button id='play'>play</button>",
        "<input id='frame' type='range' min='0' max='0' value='0' aria-label='input'>",
        "<span id='input-readout' class='mono'></span>",
        "<label>mode <select id='mode' aria-label='assembly mode'></select></label></div>",
        "<div id='assembly'></div><h2>Dimensions</h2><div id='dims'></div></section>",
        "<section id='right'><div id='plots'></div><h2>Numbers</h2>",
        "<table id='numbers'></table><div id='loads-table'></div></section></main>",
        "<script type='application/json' id='studio-boot'>", script_json(boot), "</script>",
        f"<script src='/static/studio.js{q}'></script></body></html>\n",
    ])
