"""The filter of one Dask fault in tornado's callback log (sweep/worker_setup.py,
``CancelBeforeStart``): Ctrl-C or SIGTERM arriving before ``distributed.utils.sync`` has started its
call makes its ``cancel`` callback raise a ``NameError``, which tornado logs with a traceback next
to the sweep's one-line message (seen in tests/sweep/test_sweep_faults.py about 1 run in 4 under
load). The callback here fails the same way, through tornado's own IOLoop and logger."""

from __future__ import annotations

import logging
import threading

from tornado.ioloop import IOLoop

from screwkit.sweep.worker_setup import CancelBeforeStart, filter_dask_logs


def sync():  # the names tornado's message quotes: "sync.<locals>.cancel"
    future: object

    def cancel() -> None:
        if future is not None:  # noqa: F821 - read before assignment, as in distributed 2026.8
            pass

    return cancel


def _run(callback, caplog) -> list[logging.LogRecord]:
    """``callback`` run by a fresh tornado IOLoop in its own thread (as Dask runs its loop; the
    test's thread may hold another running event loop), tornado's error records returned."""

    def loop_thread() -> None:
        loop = IOLoop(make_current=False)
        try:
            loop.add_callback(callback)
            loop.add_callback(loop.stop)
            loop.start()
        finally:
            loop.close()

    caplog.clear()
    with caplog.at_level(logging.ERROR, logger="tornado.application"):
        thread = threading.Thread(target=loop_thread)
        thread.start()
        thread.join(30)
    assert not thread.is_alive()
    return [r for r in caplog.records if r.name == "tornado.application"]


def test_the_cancel_before_start_fault_is_not_logged_and_other_callback_errors_are(caplog):
    tornado = logging.getLogger("tornado.application")
    for f in [f for f in tornado.filters if isinstance(f, CancelBeforeStart)]:
        tornado.removeFilter(f)  # an earlier sweep in this process may have installed it
    assert len(_run(sync(), caplog)) == 1  # without the filter tornado logs it
    filter_dask_logs()
    filter_dask_logs()  # once only
    assert sum(isinstance(f, CancelBeforeStart) for f in tornado.filters) == 1
    assert _run(sync(), caplog) == []

    def broken() -> None:
        raise ValueError("a real fault")

    records = _run(broken, caplog)
    assert len(records) == 1 and "a real fault" in str(records[0].exc_info[1])
