"""Pictures and reports of results: the self-contained HTML report with its animated 3-D view
(:mod:`~screwkit.report.scene`, :mod:`~screwkit.report.viewer`, docs/report.md), matplotlib
plots and animations (imported lazily: ``pip install screwkit[plot]``), the demo index and the
Jupyter view (:mod:`~screwkit.report.notebook`)."""
