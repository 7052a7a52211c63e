"""The report's page in a notebook output, updated in place: the studio's notebook controls
(:mod:`screwkit.studio.notebook`) show the report page of the first design in an ``<iframe
srcdoc>`` (:func:`~screwkit.report.viewer.render_report_html`, sandboxed: scripts only) and
hand each later design of the same mechanism to the viewer already shown, as the web page
does (``screwkitViewer.update(scene)``, docs/report.md): the camera stays where it was turned,
the frames, plots and text are replaced, and no new page is built.

The kernel reaches the page through the notebook's own output machinery (ipywidgets has no
channel into an iframe): a hidden ``Output`` widget is given one ``application/javascript``
output per design, which JupyterLab runs (an output made by the running kernel is trusted).
That script posts the packed scene to the iframe (``postMessage``: the sandboxed page has an
origin of its own), whose listener — added to the report page here — checks the view's id
and hands the scene to the viewer, replaces the text sections, and counts the updates in
``document.body.dataset.updates``. A scene the viewer cannot take in place (another
mechanism: other joints, links or samples, :func:`shape_of`) builds the page anew.
"""

from __future__ import annotations

import html
import json
import secrets
from typing import Any

from screwkit.report.viewer import pack_scene, render_report_html, script_json, text_section

#: the report page's listener for the scenes the kernel posts (``%ID%``: the view's id)
LISTENER = """<script>(function () {
  const id = '%ID%';
  window.addEventListener('message', (event) => {
    const d = event.data;
    if (!d || d.screwkitStudio !== id || !window.screwkitViewer) return;
    if (!window.screwkitViewer.update(d.scene)) return;
    const text = document.getElementById('sk-text');
    if (text && d.text !== undefined) text.outerHTML = d.text;
    const about = document.querySelector('header .muted');
    if (about && d.description !== undefined) about.textContent = d.description;
    document.body.dataset.updates = String((+document.body.dataset.updates || 0) + 1);
    document.body.dataset.seq = String(d.seq);
  });
}());</script>"""


def shape_of(scene: dict[str, Any]) -> tuple[Any, ...]:
    """What the viewer's ``update`` needs unchanged to take a scene in place (its
    ``sameShape``): the joints' kinds and inputs, the number of links and of samples, and the
    number of points of each link's polyline."""
    joints = tuple((j["kind"], bool(j.get("input"))) for j in scene["joints"])
    widths = tuple(sorted({len(m["link_points"][0][0]) if m["link_points"] else 0
                           for m in scene["modes"]}))
    return joints, len(scene["links"]), len(scene["input"]["values"]), widths


class InPlaceView:
    """The iframe of the report page and the hidden output that updates it (module
    docstring). ``frame`` and ``push`` are the two ipywidgets to show."""

    def __init__(self, widgets: Any, height: int) -> None:
        self.id = secrets.token_hex(8)
        self.height = height
        self.frame = widgets.HTML()
        self.push = widgets.Output(layout=widgets.Layout(display="none"))
        self.shape: tuple[Any, ...] | None = None
        self.updates = 0  # scenes handed to the shown page

    def show(self, scene: dict[str, Any]) -> None:
        """Show ``scene`` (an unpacked report scene): in the shown page when it draws the same
        mechanism, else in a new page."""
        shape = shape_of(scene) if scene["modes"] else None
        if shape is None or shape != self.shape:
            self.frame.value = self._iframe(scene)
            self.push.outputs = ()
            self.shape = shape
            return
        self.updates += 1
        message = {"screwkitStudio": self.id, "seq": self.updates, "scene": pack_scene(scene),
                   "text": text_section(scene["text"]),
                   "description": str(scene.get("description") or "")}
        script = ("(function () { const f = document.querySelector("
                  f"'iframe[data-screwkit-view=\"{self.id}\"]'); "
                  f"if (f && f.contentWindow) f.contentWindow.postMessage({script_json(message)}, '*'); "
                  "}());")
        self.push.outputs = ({"output_type": "display_data", "metadata": {},
                              "data": {"application/javascript": script,
                                       "text/plain": f"scene {self.updates} of the view"}},)

    def _iframe(self, scene: dict[str, Any]) -> str:
        head, tail = render_report_html(scene).rsplit("</body>", 1)
        page = head + LISTENER.replace("%ID%", self.id) + "</body>" + tail
        return (f"<iframe srcdoc=\"{html.escape(page, quote=True)}\" sandbox=\"allow-scripts\" "
                f"data-screwkit-view=\"{self.id}\" "
                f"style=\"width:100%;height:{int(self.height)}px;border:1px solid #ddd\" "
                f"title=\"{html.escape(str(scene['name']), quote=True)} — screwkit report\">"
                "</iframe>")


def posted_scene(script: str) -> dict[str, Any]:
    """The message a push script posts (for tests: the scene it hands the viewer)."""
    start = script.index("postMessage(") + len("postMessage(")
    end = script.rindex(", '*')")
    return dict(json.loads(script[start:end]))
