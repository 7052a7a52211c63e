"""The engine that runs batches of work (sweep designs, Monte Carlo samples, synthesis starts)
on Dask (docs/sweeps.md, "Engine").

By default an embedded ``LocalCluster`` of worker *processes*, one per core, is started for the
command and stopped after it, so nothing has to be set up. ``scheduler`` (``--scheduler
tcp://HOST:PORT``, or the environment variable ``SCREWKIT_SCHEDULER``) runs the same work on an
existing ``dask scheduler`` and its workers, which must have screwkit installed. ``workers=0``
runs everything in this process without Dask (the same results; for debugging).

Results come back as each task finishes, in any order; callers place them by their index, so
the result never depends on the number of workers or on which finished first.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

from screwkit.errors import InputError

#: environment variable naming an existing scheduler
SCHEDULER_ENV = "SCREWKIT_SCHEDULER"


class EngineError(InputError):
    """The engine cannot start (Dask missing, a scheduler that does not answer …)."""


class DaskMissingError(EngineError):
    """Dask (the optional extra ``screwkit[sweep]``) is not installed."""


@dataclass(frozen=True)
class EngineConfig:
    """Where work runs: ``scheduler`` address (``None``: ``SCREWKIT_SCHEDULER`` or an embedded
    cluster), ``workers`` of the embedded cluster (``None``: one per core; 0: in this process,
    no Dask)."""

    scheduler: str | None = None
    workers: int | None = None
    connect_timeout: float = 10.0  # seconds to reach an existing scheduler

    def address(self) -> str | None:
        return self.scheduler or os.environ.get(SCHEDULER_ENV) or None


def machine_cores() -> int:
    """Cores this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


def _dask() -> Any:
    try:
        import distributed
    except ImportError:
        raise DaskMissingError("this command runs on Dask, an optional extra: install it with "
                          "pip install 'screwkit[sweep]' (or run it in this process with "
                          "--workers 0)") from None
    return distributed


class Engine:
    """A running engine: :meth:`map` runs a function over payloads. Use :func:`start_engine`."""

    def __init__(self, client: Any, description: str) -> None:
        self.client = client
        self.description = description

    @property
    def workers(self) -> int:
        """Worker processes (threads on them count once each); 1 in-process."""
        if self.client is None:
            return 1
        info = self.client.scheduler_info()
        return max(1, sum(w.get("nthreads", 1) for w in info["workers"].values()))

    def map(self, function: Callable[..., Any], shared: Any, payloads: Sequence[tuple[Any, ...]],
            on_result: Callable[[int, Any], None]) -> None:
        """Run ``function(shared, *payloads[i])`` for every ``i`` and call
        ``on_result(i, result)`` as each finishes (in completion order). ``shared`` goes to each
        worker once. An exception in ``function`` is raised here."""
        if self.client is None:
            for i, payload in enumerate(payloads):
                on_result(i, function(shared, *payload))
            return
        distributed = _dask()
        shared_future = self.client.scatter(shared, broadcast=True, hash=False)
        futures = [self.client.submit(function, shared_future, *payload, pure=False)
                   for payload in payloads]
        index = {f.key: i for i, f in enumerate(futures)}
        try:
            for future in distributed.as_completed(futures, loop=self.client.loop):
                on_result(index[future.key], future.result())
                future.release()
        finally:
            for f in futures:
                f.cancel()


@contextmanager
def start_engine(config: EngineConfig) -> Iterator[Engine]:
    """Start the engine of ``config`` (module docstring) and stop what it started on exit,
    also on an error or Ctrl-C."""
    if config.workers == 0 and config.address() is None:
        yield Engine(None, "in this process (no Dask)")
        return
    distributed = _dask()
    address = config.address()
    if address is not None:
        try:
            client = distributed.Client(address, timeout=f"{config.connect_timeout}s",
                                        set_as_default=False)
        except (OSError, TimeoutError) as exc:
            raise EngineError(f"cannot reach the Dask scheduler at {address} ({exc}); start "
                              "one with 'dask scheduler' and workers with 'dask worker "
                              f"{address}' (docs/sweeps.md)") from None
        try:
            yield Engine(client, f"Dask scheduler {address}")
        finally:
            client.close()
        return
    n = config.workers if config.workers is not None else machine_cores()
    if n < 0:
        raise EngineError(f"--workers must be 0 (in this process) or more; got {n}")
    # on this machine only; the scheduler's HTTP server on a free port (8787 may be taken)
    cluster = distributed.LocalCluster(
        n_workers=n, threads_per_worker=1, processes=True, host="127.0.0.1",
        dashboard_address="127.0.0.1:0", silence_logs=logging.ERROR)
    try:
        client = distributed.Client(cluster, set_as_default=False)
        try:
            yield Engine(client, f"embedded Dask cluster of {n} worker process(es)")
        finally:
            client.close()
    finally:
        cluster.close()


def batches(indices: Sequence[int], size: int) -> list[list[int]]:
    """``indices`` cut into consecutive batches of at most ``size``."""
    return [list(indices[k:k + size]) for k in range(0, len(indices), size)]


def batch_size(count: int, workers: int, requested: int | None = None, largest: int = 64) -> int:
    """Designs per task: ``requested``, or enough for about four tasks per worker (so a slow
    batch does not leave the other workers idle at the end), at most ``largest``."""
    if requested is not None:
        if requested < 1:
            raise EngineError(f"--batch-size must be at least 1; got {requested}")
        return requested
    return max(1, min(largest, -(-count // (4 * max(1, workers)))))
