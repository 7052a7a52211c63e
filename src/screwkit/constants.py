"""Physical constants used across layers (defined once)."""

#: standard acceleration of gravity, m/s² (CGPM 1901; the default ``gravity`` of a spec)
STANDARD_GRAVITY = 9.80665
