"""Running the units of a study: in this process, on local worker processes, or on Dask.

Engines
-------
``"serial"``  every unit in this process (debugging, one worker).
``"local"``   a pool of local worker processes (``multiprocessing``, spawned; default: one per core).
``"dask"``    a Dask distributed cluster: the scheduler at ``scheduler`` (``tcp://host:8786``) or,
              without one, a ``LocalCluster`` of worker processes (one thread each) started here.

The units are sent as plain data (:mod:`clutchocp.study.tasks`); the results come back to this
process as they finish and are handed to ``on_result`` one point at a time (so they are written as
they arrive). Ctrl-C cancels what has not started, stops the workers and raises
:class:`StudyInterrupted`; the points already handed over stay written.
"""

import multiprocessing
import os
import signal
import sys

from tqdm import tqdm

from ..errors import ClutchocpError, ModelError
from .tasks import run_unit

ENGINES = ("local", "dask", "serial")


class StudyInterrupted(KeyboardInterrupt):
    """The study was stopped by Ctrl-C after ``done`` points (all of them written)."""

    keeps_results = True      # the command line says so instead of "no results written"

    def __init__(self, done, total):
        super().__init__(f"interrupted after {done} of {total} points; the finished points are kept "
                         "(run the same command again to resume)")
        self.done, self.total = done, total


class EngineError(ClutchocpError, RuntimeError):
    """The execution engine could not be started or reached (e.g. no scheduler at the address)."""


def _ignore_sigint():
    """Worker initialiser: Ctrl-C is handled by the parent, which stops the workers."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _run_unit_args(args):
    return run_unit(*args)


def default_workers():
    """Number of local workers: the cores this process may use."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:          # not on Linux
        return os.cpu_count() or 1


def check_engine(engine, workers):
    """Raise ModelError for an unknown engine or a worker count that is not a whole number >= 1."""
    if engine not in ENGINES:
        raise ModelError(f"--engine {engine!r}: allowed values are {', '.join(ENGINES)}")
    if workers is not None and not (isinstance(workers, int) and not isinstance(workers, bool) and workers >= 1):
        raise ModelError(f"--workers {workers!r}: must be a whole number >= 1")


def execute(task, units, on_result, *, engine="local", workers=None, scheduler=None, progress=True):
    """Run ``units`` (lists of points) of ``task``; call ``on_result(row, curve)`` per finished point.

    Parameters
    ----------
    task : clutchocp.study.tasks.Task
    units : list of list of dict
        The points, grouped into units of work (an optimize chain is one unit).
    on_result : callable
        Called in this process with each point's row and curve (None for simulate) as they arrive.
    engine : {"local", "dask", "serial"}
    workers : int, optional
        Local workers or LocalCluster workers (default: :func:`default_workers`); ignored with a
        ``scheduler`` (the cluster has its own).
    scheduler : str, optional
        Address of a running Dask scheduler (engine ``"dask"``).
    progress : bool
        A progress bar on stderr (tqdm).

    Returns
    -------
    dict
        ``engine``, ``workers`` (number of worker processes that ran units), ``address`` (Dask).

    Raises
    ------
    StudyInterrupted
        On Ctrl-C, after the workers were stopped.
    """
    check_engine(engine, workers)
    total = sum(len(u) for u in units)
    bar = tqdm(total=total, unit="point", file=sys.stderr, disable=not progress, dynamic_ncols=True,
               desc=f"{task.kind} {task.scene}")
    counter = {"done": 0}

    def deliver(results):
        for row, curve in results:
            on_result(row, curve)
            counter["done"] += 1
            bar.update(1)

    try:
        if engine == "serial":
            for unit in units:
                deliver(run_unit(task, unit))
            return {"engine": "serial", "workers": 1}
        if engine == "local":
            return _run_local(task, units, deliver, workers or default_workers())
        return _run_dask(task, units, deliver, workers or default_workers(), scheduler)
    except KeyboardInterrupt:
        raise StudyInterrupted(counter["done"], total) from None
    except ClutchocpError:
        raise
    except Exception as exc:              # infrastructure, not a point (points record their own failures)
        raise EngineError(f"{engine} engine: a worker failed after {counter['done']} of {total} points "
                          f"({type(exc).__name__}: {exc})".replace("\n", " ")) from None
    finally:
        bar.close()


def _run_local(task, units, deliver, workers):
    """A spawned process pool; results in completion order."""
    n = max(1, min(workers, len(units)))
    pool = multiprocessing.get_context("spawn").Pool(n, initializer=_ignore_sigint)
    try:
        for results in pool.imap_unordered(_run_unit_args, [(task, unit) for unit in units], chunksize=1):
            deliver(results)
        pool.close()
    except BaseException:
        pool.terminate()              # Ctrl-C or an error in this process: stop the workers now
        raise
    finally:
        pool.join()
    return {"engine": "local", "workers": n}


def _run_dask(task, units, deliver, workers, scheduler):
    """Dask distributed: the given scheduler, or a LocalCluster of worker processes."""
    try:
        from distributed import Client, LocalCluster, as_completed
    except ImportError:                                   # pragma: no cover - a declared dependency
        raise EngineError("the Dask engine needs the 'distributed' package (pip install 'dask[distributed]')") \
            from None
    cluster = None
    try:
        if scheduler:
            client = Client(scheduler, timeout="5s")
        else:
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                   dashboard_address=None)
            client = Client(cluster)
    except (OSError, TimeoutError) as exc:
        if cluster is not None:
            cluster.close()
        raise EngineError(f"--scheduler {scheduler}: no Dask scheduler reachable ({exc}); start one with "
                          "'dask scheduler' and workers with 'dask worker ADDRESS'") from None
    futures = []
    try:
        n_workers = len(client.scheduler_info()["workers"])
        futures = client.map(run_unit, [task] * len(units), units, pure=False)
        for future in as_completed(futures):
            deliver(future.result())
        return {"engine": "dask", "workers": n_workers, "address": client.scheduler.address}
    except BaseException:
        client.cancel(futures)
        raise
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
