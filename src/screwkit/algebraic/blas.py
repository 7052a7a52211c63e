"""BLAS's own threads held at one while a batch runs in threads of its own (threadpoolctl).

A limit is process-wide: threadpoolctl sets the library's thread count on entry and restores
the count it found on exit. Threads that enter and leave limits of their own at overlapping
times can therefore restore a count that another thread still relies on, so a batch split
over threads holds the limit once around all of them (:func:`one_blas_thread`); limits
entered inside it then find and restore one.
"""

from __future__ import annotations

from functools import lru_cache
from typing import Any


@lru_cache(maxsize=1)
def blas_controller() -> Any:
    """threadpoolctl's view of the BLAS libraries loaded (found once: ~3 ms; a limit then
    costs ~20 µs), for holding BLAS's threads at one while a batch runs in threads."""
    # scipy's LAPACK may be a BLAS library of its own (scipy's wheels bundle their OpenBLAS),
    # loaded only with scipy.linalg: loaded first, so that the controller, made once, holds it
    import scipy.linalg  # noqa: F401
    from threadpoolctl import ThreadpoolController

    return ThreadpoolController()


def one_blas_thread() -> Any:
    """A context that holds BLAS at one thread (module docstring)."""
    return blas_controller().limit(limits=1, user_api="blas")
