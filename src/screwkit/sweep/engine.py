"""The engine that runs batches of work (sweep designs, Monte Carlo samples, synthesis starts)
on Dask (docs/sweeps.md, "Engine").

By default an embedded ``LocalCluster`` of worker *processes*, one per core, is started for the
command and stopped after it, so nothing has to be set up. ``scheduler`` (``--scheduler
tcp://HOST:PORT``, or the environment variable ``SCREWKIT_SCHEDULER``) runs the same work on an
existing ``dask scheduler`` and its workers, which must have screwkit installed. ``workers=0``
runs everything in this process without Dask (the same results; for debugging).

Results come back as each task finishes, in any order; callers place them by their index, so
the result never depends on the number of workers or on which finished first.

Faults (docs/sweeps.md, "Faults"): a worker process that dies while the embedded cluster starts
(killed, out of memory) fails Dask's whole start, so the start is tried again, at most
:data:`START_ATTEMPTS` times, then refused with one sentence. A worker lost while the work runs
is replaced by its nanny and its tasks are run again elsewhere (Dask does this); the engine
counts such losses by listing the workers after every result and says so in one line
(:meth:`Engine.notes`). A task whose workers keep dying under it, or a scheduler that goes
away, stops the run with one sentence (:class:`EngineError`). Dask's logs that only narrate
these faults are filtered out, in this process and in every worker process
(:class:`screwkit.sweep.worker_setup.ExpectedFaults`).
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

from screwkit.errors import InputError
from screwkit.sweep.worker_setup import CANCELLED, PRELOAD, filter_dask_logs

#: environment variable naming an existing scheduler
SCHEDULER_ENV = "SCREWKIT_SCHEDULER"
#: tries to start the embedded cluster before giving up (bounded: a machine that cannot start a
#: worker process three times in a row will not on the fourth)
START_ATTEMPTS = 3


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


def _dask_config(key: str) -> list[str]:
    """A list-valued Dask setting (a single string is a list of one, as Dask reads it)."""
    import dask

    value = dask.config.get(key, default=None) or []
    return [value] if isinstance(value, str) else list(value)


def _dask() -> Any:
    try:
        import distributed
    except ImportError:
        raise DaskMissingError("this command runs on Dask, an optional extra: install it with "
                          "pip install 'screwkit[sweep]' (or run it in this process with "
                          "--workers 0)") from None
    return distributed


def _shared_value(value: Any) -> Any:
    return value


def _ordinal(n: int) -> str:
    return {1: "first", 2: "second", 3: "third"}.get(n, f"{n}th")


def _root_cause(exc: BaseException) -> str:
    """The innermost message of an exception chain ("Nanny failed to start worker process"),
    which says more than the outer "Cluster failed to start" wrappers."""
    while exc.__cause__ is not None:
        exc = exc.__cause__
    return str(exc) or type(exc).__name__


class Engine:
    """A running engine: :meth:`map` runs a function over payloads. Use :func:`start_engine`.

    ``start_attempts`` and ``start_failure`` say how many tries the embedded cluster needed and
    why an earlier one failed; ``lost_workers`` and ``added_workers`` count the worker processes
    the scheduler lost unexpectedly and gained while :meth:`map` ran."""

    def __init__(self, client: Any, description: str, start_attempts: int = 1,
                 start_failure: str = "") -> None:
        self.client = client
        self.description = description
        self.start_attempts = start_attempts
        self.start_failure = start_failure
        self.lost_workers = 0
        self.added_workers = 0

    @property
    def workers(self) -> int:
        """Worker processes (threads on them count once each); 1 in-process."""
        if self.client is None:
            return 1
        return max(1, sum(self.client.nthreads().values()))

    def _ask(self, call: Callable[[], Any], task: str = "") -> Any:
        """``call()``, a request to Dask, with its faults as one sentence each: a task whose
        workers all died under it (``task`` names it), a scheduler that went away."""
        distributed = _dask()
        try:
            return call()
        except distributed.KilledWorker:
            raise EngineError(
                f"{task} stopped every worker process that ran it (each died while running it: "
                "out of memory, or killed), so the run stops; run again with fewer --workers or "
                "a smaller --batch-size") from None
        except (OSError, *CANCELLED) as exc:  # CommClosedError is an OSError
            reason = getattr(exc, "reason", None) or _root_cause(exc).splitlines()[0]
            if reason == "scheduler-connection-lost":
                reason = "it stopped answering"
            if isinstance(exc, OSError) or reason == "it stopped answering":
                raise EngineError(
                    f"the run lost its connection to the {self.description} ({reason}); check "
                    "that the scheduler is running and run again") from None
            raise EngineError(f"the {self.description} cancelled the work ({reason}); check "
                              "the scheduler and its workers and run again") from None

    def map(self, function: Callable[..., Any], shared: Any, payloads: Sequence[tuple[Any, ...]],
            on_result: Callable[[int, Any], None]) -> None:
        """Run ``function(shared, *payloads[i])`` for every ``i`` and call
        ``on_result(i, result)`` as each finishes (in completion order). ``shared`` goes to each
        worker once (as the result of a task, fetched by each worker that needs it). An
        exception in ``function`` is raised here; Dask's own faults as an
        :class:`EngineError` with one sentence (:meth:`_ask`).

        The workers are listed at the start and after every result: one that has gone is
        counted lost, one that has come counted added (a worker lost and replaced between two
        results shows as both, since its replacement has a new address)."""
        if self.client is None:
            for i, payload in enumerate(payloads):
                on_result(i, function(shared, *payload))
            return
        distributed = _dask()
        client = self.client
        start = set(self._ask(client.nthreads))
        seen = set(start)
        # a task, not scattered data: a task's result lost with its worker is computed again,
        # scattered data is gone (every task would then be cancelled)
        shared_future = client.submit(_shared_value, shared, pure=False)
        futures = [client.submit(function, shared_future, *payload, pure=False)
                   for payload in payloads]
        index = {f.key: i for i, f in enumerate(futures)}
        try:
            for future in distributed.as_completed(futures, loop=client.loop):
                i = index[future.key]
                result = self._ask(future.result, f"task {i + 1} of {len(futures)}")
                on_result(i, result)
                future.release()
                seen |= set(self._ask(client.nthreads))
        finally:
            for f in futures:
                f.cancel()
        now = set(self._ask(client.nthreads))
        self.lost_workers += len(seen - now)
        self.added_workers += len((seen | now) - start)

    def notes(self, what: str = "task") -> list[str]:
        """One sentence per fault the engine recovered from (none: an empty list): a start that
        needed more than one attempt, worker processes lost while the work ran. ``what`` names
        the unit of work ("design", "Monte Carlo sample" …)."""
        out = []
        if self.start_attempts > 1:
            out.append(f"the embedded Dask cluster started at the {_ordinal(self.start_attempts)} "
                       f"attempt ({self.start_failure})")
        if self.lost_workers:
            k = self.lost_workers
            workers = "1 worker process was" if k == 1 else f"{k} worker processes were"
            how = ("lost and replaced" if self.added_workers >= k
                   else "lost (its work was run again on the others)" if k == 1
                   else "lost (their work was run again on the others)")
            out.append(f"{workers} {how} during the run; every {what} was evaluated")
        return out


@contextmanager
def start_engine(config: EngineConfig) -> Iterator[Engine]:
    """Start the engine of ``config`` (module docstring) and stop what it started on exit,
    also on an error or Ctrl-C."""
    if config.workers == 0 and config.address() is None:
        yield Engine(None, "in this process (no Dask)")
        return
    distributed = _dask()
    filter_dask_logs()
    yield from _dask_engine(distributed, config)


def _dask_engine(distributed: Any, config: EngineConfig) -> Iterator[Engine]:
    """:func:`start_engine`'s Dask engines: on a scheduler, or an embedded cluster."""
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
            with _quiet_shutdown():
                client.close()
        return
    n = config.workers if config.workers is not None else machine_cores()
    if n < 0:
        raise EngineError(f"--workers must be 0 (in this process) or more; got {n}")
    cluster, attempts, failure = _local_cluster(distributed, n)
    try:
        client = distributed.Client(cluster, set_as_default=False)
        try:
            yield Engine(client, f"embedded Dask cluster of {n} worker process(es)", attempts,
                         failure)
        finally:
            with _quiet_shutdown():
                client.close()
    finally:
        with _quiet_shutdown():
            cluster.close()


@contextmanager
def _quiet_shutdown() -> Iterator[None]:
    """Dask's loggers silenced while the command closes its client and stops its own cluster:
    connections closing (``CommClosedError``) and workers stopped with results on them (after
    Ctrl-C) are logged as errors, but they are the expected end of the run, not faults."""
    logger = logging.getLogger("distributed")
    level = logger.level
    logger.setLevel(logging.CRITICAL + 1)
    try:
        yield
    finally:
        logger.setLevel(level)


def _local_cluster(distributed: Any, n: int) -> tuple[Any, int, str]:
    """An embedded cluster of ``n`` worker processes, the attempts it took and why the last
    failed one failed; tried :data:`START_ATTEMPTS` times (module docstring)."""
    failure = ""
    for attempt in range(1, START_ATTEMPTS + 1):
        try:
            # on this machine only; the scheduler's HTTP server on a free port (8787 may be
            # taken)
            cluster = distributed.LocalCluster(
                n_workers=n, threads_per_worker=1, processes=True, host="127.0.0.1",
                dashboard_address="127.0.0.1:0", silence_logs=logging.ERROR,
                preload=[*_dask_config("distributed.worker.preload"), PRELOAD])
        except (RuntimeError, OSError, TimeoutError) as exc:
            failure = _root_cause(exc)  # Dask closed what it had started
            if "Nanny failed to start" in failure:
                failure = f"a worker process stopped while starting: {failure}"
            continue
        return cluster, attempt, failure
    raise EngineError(
        f"the embedded Dask cluster of {n} worker process(es) did not start in "
        f"{START_ATTEMPTS} attempts ({failure}); "
        "check the machine's free memory and run again, with fewer --workers, or with "
        "--workers 0 to run in this process")


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
