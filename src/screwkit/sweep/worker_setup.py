"""Set-up of every worker process of the embedded cluster, run by Dask as a worker preload
(``dask_setup``; docs/sweeps.md, "Faults"), and the filter of Dask's fault logs that the engine
installs in its own process and the preload in each worker process.

Ctrl-C in a terminal sends SIGINT to the whole process group: to the command and to each worker
process. The command stops the cluster in order (and keeps the checkpoint); a worker that also
acts on it dies with a KeyboardInterrupt traceback first, one per worker, and its lost data is
logged as an error. So the workers ignore SIGINT and are stopped by the command, as they are
at the end of every run.

A worker process that outlives a lost peer or a closing scheduler by a heartbeat logs that it
cannot reach the scheduler, with a traceback, on the command's stderr. The engine reports such
faults itself in one sentence, so the workers drop these logs as the command does
(:class:`ExpectedFaults`).

This module imports nothing of screwkit's or Dask's at import time: Dask imports it in every
worker process.
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import logging
import signal
import threading
from typing import Any

#: the preload's name, as Dask imports it in each worker process
PRELOAD = __name__

#: Dask's cancellations: a request cut short as a connection ends (asyncio's), a future given up
#: by the scheduler (distributed.FutureCancelledError derives from concurrent.futures')
CANCELLED = (asyncio.CancelledError, concurrent.futures.CancelledError)


class ExpectedFaults(logging.Filter):
    """Drops Dask's logs of faults the engine recovers from or reports itself in one sentence:
    a result fetched from a worker that has just died (it is fetched again from where it is
    computed anew), a client giving up on a scheduler that went away, a worker that cannot
    reach a scheduler that is closing, and connections that close or requests cancelled as a
    client, a cluster or a lost scheduler's connection ends (``CommClosedError``,
    ``CancelledError``; logged with a traceback, sometimes after the client has closed)."""

    messages = ("Couldn't gather keys", "Batched Comm Closed", "Failed to reconnect to scheduler",
                "Failed to communicate with scheduler during heartbeat")

    def filter(self, record: logging.LogRecord) -> bool:
        from distributed.comm.core import CommClosedError

        exc = record.exc_info[1] if record.exc_info else None
        seen: set[int] = set()
        while exc is not None and id(exc) not in seen:  # a chain, possibly with a cycle
            if isinstance(exc, (CommClosedError, *CANCELLED)):
                return False
            seen.add(id(exc))
            exc = exc.__cause__ or exc.__context__
        text = record.getMessage()
        return not any(m in text for m in self.messages)


class CancelBeforeStart(logging.Filter):
    """Drops tornado's log of one fault inside Dask, not ours: Ctrl-C or SIGTERM arriving while
    ``distributed.utils.sync`` has scheduled a call but not yet started it makes its ``cancel``
    callback read the call's future before it is assigned. Tornado then logs "Exception in
    callback ... sync.<locals>.cancel" with a ``NameError`` traceback next to the command's
    one-line message (distributed 2026.8; the call is not started, so nothing is lost)."""

    def filter(self, record: logging.LogRecord) -> bool:
        exc = record.exc_info[1] if record.exc_info else None
        return not (isinstance(exc, NameError) and "sync.<locals>.cancel" in record.getMessage())


def filter_dask_logs() -> None:
    """:class:`ExpectedFaults` on Dask's log handlers, and :class:`CancelBeforeStart` on
    tornado's callback log, once; they stay, since Dask logs some of this noise after the
    engine has stopped."""
    for handler in logging.getLogger("distributed").handlers:
        if not any(isinstance(f, ExpectedFaults) for f in handler.filters):
            handler.addFilter(ExpectedFaults())
    tornado = logging.getLogger("tornado.application")
    if not any(isinstance(f, CancelBeforeStart) for f in tornado.filters):
        tornado.addFilter(CancelBeforeStart())


def dask_setup(worker: Any) -> None:
    """Called by Dask in the worker process as it starts (a worker preload)."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    filter_dask_logs()
