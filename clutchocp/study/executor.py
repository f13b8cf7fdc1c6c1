"""Running the units of a study: in this process, on local worker processes, or on Dask.

Engines
-------
``"serial"``  every unit in this process (debugging, one worker).
``"local"``   a pool of local worker processes (``multiprocessing``; default: one per core). On Linux
              the workers are forked from this process after it has run the first point of a
              simulate sweep: they start with the modules imported and the reused model, its
              compiled code and integrators already built (:func:`clutchocp.study.tasks.warm_up`;
              the workers of an optimize sweep build their own problem, each on its own path).
              Elsewhere they are spawned and build their own.
``"dask"``    a Dask distributed cluster: the scheduler at ``scheduler`` (``tcp://host:8786``) or,
              without one, a ``LocalCluster`` of worker processes (one thread each) started here;
              on Linux those are forked after the warm-up, as for ``"local"``. The points go to
              the workers in batches (:func:`batches`), each batch one Dask task.

The units are sent as plain data (:mod:`clutchocp.study.tasks`); the results come back to this
process as they finish and are handed to ``on_result`` one point at a time (so they are written as
they arrive). Ctrl-C cancels what has not started, stops the workers and raises
:class:`StudyInterrupted`; the points already handed over stay written.
"""

import contextlib
import gc
import multiprocessing
import os
import sys

from tqdm import tqdm

from ..errors import ClutchocpError, ModelError
from ..interrupt import ignore_sigint, sigint_held
from .tasks import run_unit, warm_up

ENGINES = ("local", "dask", "serial")


# Dask settings of the LocalCluster a sweep starts: its periodic housekeeping off or rare. Each
# periodic callback wakes a worker's event loop, which then waits for the GIL that the thread
# running CasADi holds; and the scheduler runs in this process beside the workers.
LOCAL_CLUSTER_CONFIG = {
    # no statistical profiler (it samples each worker's stack every 10 ms for a dashboard this
    # cluster does not have; measured: 200-point zhang2021 sweep 8.3 s without it against 9.5 s
    # with it, load 7.5)
    "distributed.worker.profile.enabled": False,
    "distributed.admin.tick.interval": "1s",                 # event-loop health check (default 20 ms)
    "distributed.admin.system-monitor.interval": "10s",      # CPU/memory/network sampling (500 ms)
    "distributed.worker.memory.monitor-interval": "10s",     # worker memory checks (100 ms)
}


# How often the LocalCluster's nannies (in this process) look whether the worker process they
# started has connected: distributed polls every 50 ms, so a worker ready after ~35 ms is seen only
# at 50. Measured alone (2 forked workers): the cluster starts in 0.057-0.066 s at 2 ms against
# 0.085-0.096 s at 50 ms.
NANNY_START_POLL_S = 0.002


@contextlib.contextmanager
def _nanny_polling(interval):
    """Set the nannies' start-up polling interval for the block (``WorkerProcess._init_msg_interval``
    of distributed, where that version has it; otherwise nothing changes)."""
    from distributed.nanny import WorkerProcess

    before = getattr(WorkerProcess, "_init_msg_interval", None)
    if before is not None:
        WorkerProcess._init_msg_interval = interval
    try:
        yield
    finally:
        if before is not None:
            WorkerProcess._init_msg_interval = before


class StudyInterrupted(KeyboardInterrupt):
    """The study was stopped by Ctrl-C after ``done`` points (all of them written)."""

    keeps_results = True      # the command line says so instead of "no results written"

    def __init__(self, done, total):
        super().__init__(f"interrupted after {done} of {total} points; the finished points are kept "
                         "(run the same command again to resume)")
        self.done, self.total = done, total


class _Bar(tqdm):
    """tqdm without its monitor thread: the workers are forked from this process, and a fork
    copies only the forking thread (a lock another thread holds stays held in the child)."""

    monitor_interval = 0


class EngineError(ClutchocpError, RuntimeError):
    """The execution engine could not be started or reached (e.g. no scheduler at the address)."""


_FROZEN = {"depth": 0}      # frozen_heap blocks open in this process


@contextlib.contextmanager
def frozen_heap():
    """Keep the objects this process holds out of the garbage collector's full collections while
    the block runs (``gc.freeze``); they are handed back when the outermost such block ends (not
    at all if the heap was frozen before it).

    A full collection scans every object the process holds: with the modules, scenes and CasADi
    models of a sweep that is 0.10-0.15 s, taken at moments of the collector's choosing (in a
    200-point zhang2021 sweep of ~1 s on 2 workers, about one sweep in four, often while the
    figures are drawn). Frozen, a full collection scans only what was made since. The engines
    freeze again right before they fork workers (after the warm-up), as the ``gc`` documentation
    advises for fork: the workers then neither rescan the pages they inherit nor copy them by
    writing the collector's marks into them.
    """
    outermost = _FROZEN["depth"] == 0
    # counted only at the outermost block: gc.get_freeze_count walks the frozen objects (7 ms)
    hand_back = outermost and gc.get_freeze_count() == 0
    _FROZEN["depth"] += 1
    gc.freeze()
    try:
        yield
    finally:
        _FROZEN["depth"] -= 1
        if hand_back:
            gc.unfreeze()


def _run_units(task, units):
    """Several units in one call (a batch sent to a worker at once): their results, in order."""
    return [result for unit in units for result in run_unit(task, unit)]


def _run_units_args(args):
    return _run_units(*args)


def start_method():
    """``"fork"`` on Linux (the workers inherit what this process has built), else ``"spawn"``."""
    return "fork" if sys.platform.startswith("linux") and "fork" in multiprocessing.get_all_start_methods() \
        else "spawn"


def batches(units, workers, share=4):
    """``units`` cut into batches of consecutive units, each ``1 / (share * workers)`` of the units
    left (rounded up): large batches first (few messages), down to single units at the end, so
    that the workers finish together."""
    out, start = [], 0
    while start < len(units):
        size = -(-(len(units) - start) // (share * workers))
        out.append(units[start:start + size])
        start += size
    return out


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
    bar = _Bar(total=total, unit="point", file=sys.stderr, disable=not progress, dynamic_ncols=True,
               desc=f"{task.kind} {task.scene}")
    counter = {"done": 0}

    def deliver(results):
        for row, curve in results:
            on_result(row, curve)
            counter["done"] += 1
            bar.update(1)

    try:
        with frozen_heap():
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
    """A process pool; results in completion order (each batch's as it finishes)."""
    method = start_method()
    if method == "fork":                      # build once here; the forked workers inherit it
        done, units = warm_up(task, units)
        deliver(done)
        gc.freeze()                           # what the warm-up built too (see frozen_heap)
    n = max(1, min(workers, len(units)))
    if not units:
        return {"engine": "local", "workers": n, "start_method": method}
    with sigint_held():
        pool = multiprocessing.get_context(method).Pool(n, initializer=ignore_sigint)
    try:
        for results in pool.imap_unordered(_run_units_args, [(task, b) for b in batches(units, n)], chunksize=1):
            deliver(results)
        pool.close()
    except BaseException:
        _stop_pool(pool)              # Ctrl-C or an error in this process: stop the workers now
        raise
    finally:
        pool.join()
    return {"engine": "local", "workers": n, "start_method": method}


def _stop_pool(pool):
    """Stop a pool's workers now. ``Pool.terminate`` first takes the task queue's read lock, which an
    idle worker holds while it waits for a task (seen: a Ctrl-C near the end of a sweep hung there);
    one stop sentinel per worker (``None``, what ``Pool.close`` sends) lets such a worker exit."""
    for _ in range(len(pool._pool)):
        pool._inqueue.put(None)
    pool.terminate()


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
            import dask

            method = start_method()
            if method == "fork":            # the forked workers inherit what the warm-up built
                done, units = warm_up(task, units)
                deliver(done)
                gc.freeze()                 # what the warm-up built too (see frozen_heap)
            with dask.config.set({"distributed.worker.multiprocessing-method": method, **LOCAL_CLUSTER_CONFIG}), \
                    _nanny_polling(NANNY_START_POLL_S):
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
        parts = batches(units, max(n_workers, 1))
        futures = client.map(_run_units, [task] * len(parts), parts, pure=False)
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
