"""Plot axes a person can read (issue 30): round limits, ticks written to the precision of their
step (no "0.209739" at an axis end, no "90.000003"), large values with a power of ten (no
"2000000"), in the HTML report's plots and in the matplotlib pictures; the report's dynamics in
the spec's units."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import screwkit as sk
from screwkit.report.plots import pyplot, tidy_axes
from screwkit.report.spec_report import spec_scene
from screwkit.report.viewer import render_report_html

EXAMPLES = Path(__file__).parents[2] / "examples"
LBF = 0.45359237 * 9.80665  # N (avoirdupois pound times standard gravity)
INCH = 0.0254

#: (x data, y data) whose plain extents were the bad labels of the issue
AWKWARD = {
    "small": ([0.0, 0.1, 0.209739], [1.0, 2.0, 3.0]),
    "ninety": ([0.0, 45.0, 90.000003], [0.0, 1.0, 90.000003]),
    "large": ([0.0, 1.0, 2.0], [0.0, 1.3e6, 2.0e6]),
}


def _number(label: str) -> float:
    """A tick label's value: "1.5", "−2", "2×10⁶"."""
    sup = str.maketrans("⁻⁰¹²³⁴⁵⁶⁷⁸⁹", "-0123456789")
    text = label.replace("−", "-")
    if "×10" in text:
        m, e = text.split("×10")
        return float(m) * 10.0 ** int(e.translate(sup))
    return float(text)


def _check_axis(lo: float, hi: float, labels: list[str], data: list[float]) -> None:
    assert all(len(t) <= 7 for t in labels), labels
    assert not any(re.search(r"\d\.\d*0000\d|209739|2000000|90\.0000", t) for t in labels), labels
    values = [_number(t) for t in labels]
    step = values[1] - values[0]
    assert np.allclose(np.diff(values), step)
    # the limits are ticks, and the data lie inside them
    assert np.isclose(lo, values[0]) and np.isclose(hi, values[-1])
    assert lo <= min(data) + 1e-12 and hi >= max(data) - 1e-12
    assert hi - lo <= 2.0 * (max(data) - min(data))


@pytest.mark.parametrize("case", list(AWKWARD))
def test_matplotlib_axes_have_round_limits_and_short_labels(case: str) -> None:
    plt = pyplot()
    x, y = AWKWARD[case]
    fig, ax = plt.subplots()
    ax.plot(x, y)
    tidy_axes(fig)
    fig.canvas.draw()
    for axis, lim, data in ((ax.xaxis, ax.get_xlim(), x), (ax.yaxis, ax.get_ylim(), y)):
        ticks = [t for t in axis.get_major_ticks() if lim[0] - 1e-9 <= t.get_loc() <= lim[1] + 1e-9]
        labels = [re.sub(r"^\$\\mathdefault\{(.*)\}\$$", r"\1", t.label1.get_text())
                  for t in ticks]
        offset = axis.get_offset_text().get_text()
        scale = 10.0 ** int(re.search(r"10\^\{(-?\d+)\}", offset).group(1)) if offset else 1.0
        _check_axis(lim[0] / scale, lim[1] / scale, labels, [d / scale for d in data])
    if case == "large":
        assert "10^{6}" in ax.yaxis.get_offset_text().get_text()
    plt.close(fig)


def test_report_axes_are_round_in_the_browser(tmp_path: Path, open_report: Any) -> None:
    scene = spec_scene(sk.load_spec(EXAMPLES / "bagci_fig7_rsrc.toml"))
    for name, (x, y) in AWKWARD.items():
        scene["plots"].append({"id": f"awkward-{name}", "group": "kinematics", "title": name,
                               "kind": "line", "x_label": "x", "y_label": "y", "x_scale": 1.0,
                               "y_scale": 1.0, "linked": False,
                               "series": [{"name": name, "mode": None, "style": "line",
                                           "x": x, "y": y}]})
    path = tmp_path / "axes.html"
    path.write_text(render_report_html(scene), encoding="utf-8")
    page = open_report(path)
    axes = page.evaluate("screwkitViewer.plotAxes()")
    assert not page.errors
    for name, (x, y) in AWKWARD.items():
        for key, data in (("x", x), ("y", y)):
            a = axes[f"awkward-{name}"][key]
            _check_axis(a["min"], a["max"], a["labels"], data)
    assert re.fullmatch(r"2(\.0+)?×10⁶", axes["awkward-large"]["y"]["labels"][-1])
    # every plot of the report: no label longer than a readable number
    for pid, a in axes.items():
        for key in ("x", "y"):
            assert all(len(t) <= 8 for t in a[key]["labels"]), (pid, key, a[key]["labels"])


def test_report_dynamics_are_in_the_spec_units(tmp_path: Path) -> None:
    text = (EXAMPLES / "rsrc_fig7_dynamics.toml").read_text(encoding="utf-8")
    spec_file = tmp_path / "fig7_lbf.toml"
    spec_file.write_text(text.replace('angle = "deg"', 'angle = "deg"\nforce = "lbf"', 1),
                         encoding="utf-8")
    scene = spec_scene(sk.load_spec(spec_file))
    plots = {p["id"]: p for p in scene["plots"]}
    assert plots["dyn-sf"]["y_label"] == "force (lbf)"
    assert np.isclose(plots["dyn-sf"]["y_scale"], 1 / LBF, rtol=1e-12)
    assert plots["dyn-sm"]["y_label"] == "moment (lbf·in)"
    assert np.isclose(plots["dyn-sm"]["y_scale"], 1 / (LBF * INCH), rtol=1e-12)
    assert np.isclose(plots["dyn-sf-xy"]["x_scale"], 1 / LBF, rtol=1e-12)
    torque = next(p for k, p in plots.items() if k.startswith("dyn-effort-"))
    assert torque["y_label"] == "effort (lbf·in)"
    assert scene["display_units"]["force"] == "lbf"  # the arrows' legend
    assert np.isclose(scene["display_units"]["force_factor"], 1 / LBF, rtol=1e-12)
    note = next(g["note"] for g in scene["plot_groups"] if g["id"] == "dynamics")
    assert "forces in lbf, moments in lbf·in" in note
