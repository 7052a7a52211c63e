"""The report viewer inline in Jupyter: an ``<iframe srcdoc>`` holding the same self-contained
page as ``screwkit report`` (:func:`screwkit.report.viewer.render_report_html`).

>>> from screwkit.report.notebook import view
>>> view(m)                              # a Motion: shows the animated 3-D view and plots
>>> view(m, spec, dynamics=dyn, dynamics_mode=0, balance=bal)
>>> view(solve_mechanism(mech, inputs))  # any mechanism, a graph (kinematics only)

or once per session :func:`enable_notebook_display`, after which every ``Motion`` shown as the
last value of a cell draws itself. A result class can also offer ``_repr_html_`` by returning
:func:`motion_html` of itself (the result layers cannot import the report layer; the
registration here does it from above)."""

from __future__ import annotations

import html
from typing import Any

from screwkit.errors import InputError
from screwkit.report.scene import scene_from_motion
from screwkit.report.viewer import render_report_html

DEFAULT_HEIGHT = 640


def report_iframe(scene: dict[str, Any], height: int = DEFAULT_HEIGHT) -> str:
    """An iframe whose ``srcdoc`` is the whole report page (scripts allowed, nothing else:
    the page needs no network, no storage and no access to the notebook)."""
    doc = html.escape(render_report_html(scene), quote=True)
    return (f"<iframe srcdoc=\"{doc}\" sandbox=\"allow-scripts\" "
            f"style=\"width:100%;height:{int(height)}px;border:1px solid #ddd\" "
            f"title=\"{html.escape(str(scene['name']), quote=True)} — screwkit report\"></iframe>")


def _doc(x: Any) -> dict[str, Any] | None:
    if x is None or isinstance(x, dict):
        return x
    return dict(x.as_dict())


def _scene(motion: Any, owner: Any, dynamics: Any, dynamics_mode: int | None, balance: Any,
           synthesis: Any, options: dict[str, Any]) -> dict[str, Any]:
    """The scene of a loop's ``Motion``, or of a mechanism's ``MechanismMotion`` (kinematics
    only: :func:`screwkit.report.graph_scene.scene_from_mechanism`)."""
    if hasattr(motion, "mechanism"):
        from screwkit.report.graph_scene import scene_from_mechanism

        if dynamics is not None or balance is not None or synthesis is not None:
            raise InputError("the report of a mechanism (a graph) shows its kinematics only; "
                             "leave out dynamics, balance and synthesis")
        return scene_from_mechanism(owner if owner is not None else motion.mechanism, motion,
                                    **options)
    return scene_from_motion(owner if owner is not None else motion.linkage, motion,
                             dynamics_doc=_doc(dynamics), dynamics_mode=dynamics_mode,
                             balance_doc=_doc(balance), synthesis_doc=synthesis, **options)


def motion_html(motion: Any, spec_or_linkage: Any = None, *, dynamics: Any = None,
                dynamics_mode: int | None = None, balance: Any = None, synthesis: Any = None,
                height: int = DEFAULT_HEIGHT, **scene_options: Any) -> str:
    """The inline report (HTML) of a motion. ``spec_or_linkage`` defaults to
    ``motion.linkage``; ``dynamics`` (a ``Dynamics`` or its ``as_dict()``) of mode
    ``dynamics_mode``; ``balance`` a ``BalanceResult`` or its document; ``synthesis`` the
    synthesis document. Other keywords go to :func:`scene_from_motion`."""
    scene = _scene(motion, spec_or_linkage, dynamics, dynamics_mode, balance, synthesis,
                   scene_options)
    return report_iframe(scene, height)


class ReportView:
    """A report that Jupyter displays inline (it has ``_repr_html_``)."""

    def __init__(self, scene: dict[str, Any], height: int = DEFAULT_HEIGHT) -> None:
        self.scene = scene
        self.height = height

    def _repr_html_(self) -> str:
        return report_iframe(self.scene, self.height)

    def save(self, path: str) -> None:
        """Write the report as a standalone HTML file."""
        from screwkit.io.results import write_atomic

        write_atomic(path, render_report_html(self.scene))


def view(motion: Any, spec_or_linkage: Any = None, *, dynamics: Any = None,
         dynamics_mode: int | None = None, balance: Any = None, synthesis: Any = None,
         height: int = DEFAULT_HEIGHT, **scene_options: Any) -> ReportView:
    """A :class:`ReportView` of a motion (same arguments as :func:`motion_html`)."""
    scene = _scene(motion, spec_or_linkage, dynamics, dynamics_mode, balance, synthesis,
                   scene_options)
    return ReportView(scene, height)


def enable_notebook_display(shell: Any = None) -> None:
    """Make IPython show every ``screwkit.kinematics.motion.Motion`` as its inline report."""
    from screwkit.kinematics.motion import Motion

    if shell is None:
        from IPython import get_ipython  # type: ignore[attr-defined]

        shell = get_ipython()
        if shell is None:
            raise InputError("enable_notebook_display() works inside IPython or Jupyter only")
    shell.display_formatter.formatters["text/html"].for_type(Motion, lambda m: motion_html(m))
