"""The closed forms of the families: the RSRC quartic and its analysis, the planar 4R, the RSSR, the RCCC and the CSSP, and the Motion they build (docs/architecture.md)."""
