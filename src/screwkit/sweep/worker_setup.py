"""Set-up of every worker process of the embedded cluster, run by Dask as a worker preload
(``dask_setup``; docs/sweeps.md, "Faults").

Ctrl-C in a terminal sends SIGINT to the whole process group: to the command and to each worker
process. The command stops the cluster in order (and keeps the checkpoint); a worker that also
acts on it dies with a KeyboardInterrupt traceback first, one per worker, and its lost data is
logged as an error. So the workers ignore SIGINT and are stopped by the command, as they are
at the end of every run.
"""

from __future__ import annotations

import signal
import threading
from typing import Any

#: the preload's name, as Dask imports it in each worker process
PRELOAD = __name__


def dask_setup(worker: Any) -> None:
    """Called by Dask in the worker process as it starts (a worker preload)."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
