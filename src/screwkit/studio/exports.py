"""The studio's exports of the current design: the HTML report ``screwkit report`` writes and
the CSV ``screwkit analyze --csv`` writes, both of the spec with the page's values (the same
functions, so the files are the ones the CLI makes from a saved spec)."""

from __future__ import annotations

from screwkit.io.spec import Spec
from screwkit.pipeline import Pipeline


def export_csv(spec: Spec) -> str:
    """The per-sample CSV of ``screwkit analyze --csv`` (every mode, the spec's units)."""
    return Pipeline(spec).analysis_table().csv_text(spec.display_units())


def export_report(spec: Spec, spec_text: str) -> str:
    """The self-contained HTML report of ``screwkit report``, showing ``spec_text`` (the
    design's spec file) as its spec."""
    from screwkit.report.spec_report import spec_scene
    from screwkit.report.viewer import render_report_html

    scene = spec_scene(Pipeline(spec))
    scene["text"]["spec"] = spec_text
    return render_report_html(scene)
