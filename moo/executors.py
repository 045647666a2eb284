"""Where an experiment grid runs: this process, a local process pool, or a Dask cluster.

:func:`open_executor` checks its arguments when called and returns a context
manager that yields a :class:`concurrent.futures.Executor` (or ``None`` for
"in this process") and releases it on exit::

    with open_executor("dask", scheduler="tcp://10.0.0.5:8786") as ex:
        run_experiment(..., executor=ex)

``"process"``
    ``workers`` spawned processes (a :class:`~concurrent.futures.ProcessPoolExecutor`);
    ``workers=1`` (the default) runs in this process. A pool process killed
    mid-grid breaks the pool (``BrokenProcessPool``: every run in flight or
    queued is lost); the experiment driver then starts a fresh pool and
    resubmits the lost runs, at most :data:`POOL_RESTARTS` times per grid (a
    run that kills its process every time would otherwise loop forever), with
    a message on stderr. After that the grid stops; the records written stay
    and a rerun resumes. The pool processes exit with the driver: each one
    watches its parent (a thread polling ``os.getppid()`` every
    :data:`PARENT_POLL` seconds), so a driver killed by SIGTERM or SIGKILL
    leaves no pool process behind.
``"dask"``
    With ``scheduler``: the workers of an existing ``dask.distributed``
    scheduler (started with ``dask scheduler`` / ``dask worker``, or by
    dask-jobqueue on a batch system). Without: a
    :class:`~distributed.LocalCluster` of ``workers`` worker processes, one
    thread each. The scheduler recomputes the runs of a lost worker on the
    others (up to ``distributed.scheduler.allowed-failures`` times per run).
    The workers need ``moo`` installed (the same version), not the results
    directory, and any user module named by an import path (``--problem
    package.module:factory``). A scheduler lost mid-grid raises
    :class:`SchedulerLostError` (a ``ConnectionError``): the records written
    stay and the same command, rerun, resumes.

On leaving the block because of an error (a failed run, Ctrl-C), queued runs
are cancelled; a local pool or cluster is shut down without waiting for the
runs in flight.
"""

from __future__ import annotations

import os
import re
import threading
import time
from collections.abc import Callable, Iterator
from concurrent.futures import Executor, Future, ProcessPoolExecutor
from contextlib import AbstractContextManager, contextmanager
from multiprocessing import get_context
from typing import Any

from moo.store import DISK_ERRORS
from moo.validation import check_choice, check_int

__all__ = ["EXECUTORS", "POOL_RESTARTS", "PARENT_POLL", "SchedulerLostError", "open_executor"]

#: Seconds between two checks of a pool process that its driver is still alive.
PARENT_POLL = 0.5

_SCHEDULER = re.compile(r"^(tcp|tls|inproc|ucx|ws|wss)://[^\s/:]+(:\d{1,5})?/?$|^[^\s/:]+:\d{1,5}$")


class SchedulerLostError(ConnectionError):
    """The Dask scheduler went away mid-grid (the records written stay; rerun to resume)."""


def _exit_with_parent(parent: int) -> None:
    """Pool-process initializer: exit as soon as the driver ``parent`` is gone.

    A daemon thread polls ``os.getppid()``: an orphan is re-parented, so the
    value changes when the driver dies, however it dies. (Linux's
    ``PR_SET_PDEATHSIG`` is not used: it fires when the *thread* that started
    the process ends, which is not the driver's death.)
    """
    if os.getppid() != parent:                                 # died before we got here
        os._exit(1)

    def watch() -> None:
        while True:
            time.sleep(PARENT_POLL)
            if os.getppid() != parent:
                os._exit(1)

    threading.Thread(target=watch, name="moo-parent-watch", daemon=True).start()

#: Executor kinds of :func:`open_executor` (and ``python -m moo experiment --executor``).
EXECUTORS: tuple[str, ...] = ("process", "dask")

#: How often the ``"process"`` pool is replaced after a pool process died, per grid (as Dask's
#: ``distributed.scheduler.allowed-failures``, 3 by default, bounds the recomputations of a run).
POOL_RESTARTS = 3


def open_executor(kind: str = "process", *, workers: int | None = None,
                  scheduler: str | None = None) -> AbstractContextManager[Executor | None]:
    """A context manager yielding the executor of ``kind`` (see the module docstring).

    Parameters
    ----------
    kind : {"process", "dask"}
        A local process pool, or Dask.
    workers : int, optional
        Processes of the pool or of the local Dask cluster (default 1). Not
        with ``scheduler``: a running cluster has its own workers.
    scheduler : str, optional
        Address of a running Dask scheduler, e.g. ``"tcp://10.0.0.5:8786"``
        (``kind="dask"`` only).

    Raises
    ------
    ValueError, TypeError
        At the call, for bad arguments. ``ConnectionError`` on entering the
        block when the scheduler cannot be reached.
    """
    kind = check_choice(kind, "executor", EXECUTORS)
    if workers is not None:
        workers = check_int(workers, "workers", 1)
    if scheduler is not None:
        if not isinstance(scheduler, str) or not _SCHEDULER.match(scheduler.strip()):
            raise ValueError(f"scheduler must be an address such as 'tcp://HOST:8786', got {scheduler!r}")
        scheduler = scheduler.strip()
        if kind != "dask":
            raise ValueError("scheduler needs the 'dask' executor")
        if workers is not None:
            raise ValueError("workers sizes a local cluster; the cluster at scheduler has its own workers")
    if kind == "process":
        return _process_pool(workers or 1)
    return _dask(scheduler, workers or 1)


class RestartingPool(Executor):
    """A pool of ``workers`` spawned processes that :meth:`restart` replaces once it is broken."""

    def __init__(self, workers: int, restarts: int = POOL_RESTARTS):
        self.workers, self.restarts_left = workers, restarts
        self._pool = self._new()

    def _new(self) -> ProcessPoolExecutor:
        return ProcessPoolExecutor(max_workers=self.workers, mp_context=get_context("spawn"),
                                   initializer=_exit_with_parent, initargs=(os.getpid(),))

    def submit(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> Future:
        return self._pool.submit(fn, *args, **kwargs)

    def shutdown(self, wait: bool = True, *, cancel_futures: bool = False) -> None:
        self._pool.shutdown(wait=wait, cancel_futures=cancel_futures)

    def restart(self) -> bool:
        """Replace the (broken) pool by a fresh one; False once :data:`POOL_RESTARTS` are used up."""
        if self.restarts_left == 0:
            return False
        self.restarts_left -= 1
        self._pool.shutdown(wait=True)      # a broken pool has already terminated its processes
        self._pool = self._new()
        return True


@contextmanager
def _process_pool(workers: int) -> Iterator[Executor | None]:
    if workers == 1:
        yield None
        return
    pool = RestartingPool(workers)
    try:
        yield pool
    except BaseException:
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown()


@contextmanager
def _dask(scheduler: str | None, workers: int) -> Iterator[Executor]:
    from distributed import Client, LocalCluster

    cluster = None
    if scheduler is None:
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0")
        client = Client(cluster)
    else:
        try:
            client = Client(scheduler)
        except (OSError, ValueError, TypeError) as exc:
            raise ConnectionError(f"cannot reach the Dask scheduler at {scheduler}: "
                                  f"{str(exc).splitlines()[0]}") from None
    where = "the local Dask cluster" if scheduler is None else f"the Dask scheduler at {scheduler}"
    try:
        yield client.get_executor()
    except (KeyboardInterrupt, SchedulerLostError):
        raise
    except BaseException as exc:
        if _scheduler_lost(client, exc):
            raise SchedulerLostError(f"lost {where}; the records written are kept: "
                                     "restart the scheduler and rerun the same command to resume") from None
        raise
    finally:
        _close_quietly(client)
        if cluster is not None:
            _close_quietly(cluster)


def _scheduler_lost(client: Any, exc: BaseException) -> bool:
    """True if ``exc`` comes from losing the scheduler (a cancelled future or a comm error, client cut off)."""
    from asyncio import CancelledError as AsyncCancelled
    from concurrent.futures import CancelledError

    from distributed.comm.core import CommClosedError

    if isinstance(exc, OSError) and exc.errno in DISK_ERRORS:
        return False                       # the driver's own write failed (a full disk), not the scheduler
    if isinstance(exc, (CancelledError, AsyncCancelled, CommClosedError, OSError, TimeoutError)):
        return True
    return getattr(client, "status", "running") not in ("running", "connecting")


def _close_quietly(obj: Any) -> None:
    """Close a Dask client or cluster without the tracebacks of a scheduler that is gone."""
    import logging

    loggers = [logging.getLogger(n) for n in ("distributed", "distributed.client", "distributed.comm",
                                               "distributed.batched", "tornado", "asyncio")]
    levels = [lg.level for lg in loggers]
    for lg in loggers:
        lg.setLevel(logging.CRITICAL)
    try:
        obj.close(timeout=5)
    except BaseException:  # noqa: BLE001 - closing a client whose scheduler is gone: nothing left to save
        pass
    finally:
        for lg, level in zip(loggers, levels, strict=True):
            lg.setLevel(level)
