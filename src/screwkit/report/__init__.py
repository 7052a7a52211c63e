"""Pictures and reports of results (matplotlib, imported lazily: ``pip install screwkit[plot]``)."""
