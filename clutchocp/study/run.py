"""A sweep of a scene: points, output folder (lock, resume), execution, summary and figures."""

import time
from pathlib import Path

import numpy as np

from ..errors import ModelError
from ..output import write_summary
from ..scene import load_scene
from ..scene.uncertainty import Uncertainty
from ..simulation.native import native_status
from .executor import StudyInterrupted, check_engine, default_workers, execute, frozen_heap
from .figures import draw_study
from .folder import StudyFolder
from .points import StudySpecError, chains, grid_points, parse_grid, point_id
from .tasks import STATUS_COLUMNS, Task

MAX_LISTED_FAILURES = 20


def study_points(scene, grid=(), samples=None, seed=0, uncertain=()):
    """The points of a study and the fields they set.

    Parameters
    ----------
    scene : clutchocp.scene.Scene
    grid : sequence of str
        ``"part.key=start:stop:count"`` per swept field (several: a full grid).
    samples : int, optional
        Number of samples of the scene's uncertainty (``[uncertainty]`` and ``uncertain``).
    seed : int
        Seed of the samples.
    uncertain : sequence of str
        More uncertain fields, ``"friction.mu=uniform 10 %"``.

    Returns
    -------
    fields : tuple of str
    points : list of dict
    """
    if grid and samples is not None:
        raise StudySpecError("give either --grid (a full grid) or --samples (of the uncertainty), not both")
    if grid:
        axes = [parse_grid(text, scene) for text in grid]
        return tuple(name for name, _ in axes), grid_points(axes)
    if samples is not None:
        if not (isinstance(samples, int) and samples >= 1):
            raise StudySpecError(f"--samples {samples!r}: must be a whole number >= 1")
        u = Uncertainty.from_scene(scene, extra=tuple(uncertain))
        if not u.names:
            raise StudySpecError("--samples: the scene declares no [uncertainty] and no --uncertain was given")
        return tuple(u.names), u.samples(samples, seed=seed)
    raise StudySpecError("give the points: --grid part.key=start:stop:count (repeatable) or --samples N")


def run_sweep(scene, out_dir, *, task="simulate", grid=(), samples=None, seed=0, uncertain=(), overrides=None,
              options=None, engine="local", workers=None, scheduler=None, progress=True):
    """Run a sweep (a grid or Monte Carlo samples) of simulations or optimisations of a scene.

    Parameters
    ----------
    scene : str or pathlib.Path
        Built-in scene name or scene file (workers load it themselves).
    out_dir : str or pathlib.Path
        Output folder: ``results.csv`` (one row per point, written as points finish),
        ``calibration.csv`` (optimize), ``study.json``, ``summary.json`` and figures at the end. A
        folder holding the same sweep is resumed: finished points are not computed again.
    task : {"simulate", "optimize"}
    grid, samples, seed, uncertain
        The points, see :func:`study_points`.
    overrides : dict, optional
        ``{"part.key": value}`` applied to every point (``--set``).
    options : dict, optional
        Task options, see :class:`~clutchocp.study.tasks.Task`.
    engine, workers, scheduler
        Where the points run, see :func:`~clutchocp.study.executor.execute`.
    progress : bool
        Progress bar on stderr.

    Returns
    -------
    dict
        The summary written to ``summary.json`` plus ``files`` (paths written).
    """
    job = Task(str(scene), task, dict(overrides or {}), dict(options or {}))
    check_engine(engine, workers)
    overrides = dict(overrides or {})
    base = load_scene(scene, overrides=overrides or None)
    if base.kind != "engagement":
        raise ModelError(f"scene '{base.name}' is a {base.kind} scene; a sweep runs engagement scenes")
    fields, points = study_points(base, grid, samples, seed, uncertain)
    columns = list(fields) + list(STATUS_COLUMNS) + list(job.columns())
    spec = {"scene": str(scene), "task": task, "fields": list(fields), "grid": list(grid), "samples": samples,
            "seed": seed if samples is not None else None, "uncertain": list(uncertain), "overrides": overrides,
            "options": job.options}
    out = Path(out_dir)
    start = time.perf_counter()
    with StudyFolder(out, spec, columns) as folder, frozen_heap():     # through the figures too
        done = {row["point_id"] for row in folder.finished()}
        todo = [p for p in points if point_id(p) not in done]
        if task == "optimize" and grid:             # one path through the grid per worker: warm starts
            units = chains(todo, 1 if engine == "serial" else workers or default_workers())
        else:
            units = [[p] for p in todo]

        def on_result(row, curve):
            if curve is not None:
                folder.append_curve(row, curve, fields)
            folder.append(row)

        engine_info = execute(job, units, on_result, engine=engine, workers=workers, scheduler=scheduler,
                              progress=progress) if units else {"engine": engine, "workers": 0}
        wall = time.perf_counter() - start
        rows = folder.finished()
        order = {point_id(p): k for k, p in enumerate(points)}
        rows = sorted((r for r in rows if r["point_id"] in order), key=lambda r: order[r["point_id"]])
        try:
            summary = sweep_summary(base, job, fields, rows, resumed=len(done & set(order)), computed=len(todo),
                                    wall=wall, engine_info=engine_info, samples=samples, seed=seed)
            files = draw_study(out, base, job, fields, rows, samples is not None)
            files.append(write_summary(out / "summary.json", summary))
        except KeyboardInterrupt:         # Ctrl-C while drawing: every row is written, say so
            raise StudyInterrupted(len(rows), len(points)) from None
    summary["files"] = [str(f) for f in files]
    return summary


def sweep_summary(scene, task, fields, rows, *, resumed, computed, wall, engine_info, samples, seed):
    """The JSON-ready summary of a finished sweep."""
    ok = [r for r in rows if r["status"] == "ok"]
    failed = [r for r in rows if r["status"] != "ok"]
    results = {}
    for column in task.columns():
        values = np.array([r[column] for r in ok if isinstance(r.get(column), float)], float)
        if values.size:
            results[column] = {"min": float(values.min()), "max": float(values.max()), "mean": float(values.mean()),
                               "n": int(values.size)}
    workers = engine_info.get("workers") or 0
    return {
        "scene": scene.name,
        "task": task.kind,
        "fields": list(fields),
        "samples": samples,
        "seed": seed if samples is not None else None,
        "points": len(rows),
        "points_ok": len(ok),
        "points_failed": len(failed),
        "points_resumed": resumed,
        "points_computed": computed,
        "failures": [{"point_id": r["point_id"], "reason": r["reason"], **{f: r[f] for f in fields}}
                     for r in failed[:MAX_LISTED_FAILURES]],
        "results": results,
        "engine": {k: v for k, v in engine_info.items() if v is not None},
        "wall_time_s": wall,
        "points_per_second": computed / wall if computed and wall > 0 else None,
        "points_per_second_per_worker": computed / wall / workers if computed and wall > 0 and workers else None,
        "native_code": dict(native_status(task.options["native"] is not False), requested=task.options["native"],
                            used=any(r.get("native_code") is True for r in ok)) if task.kind == "simulate" else None,
        "points_model_reused": sum(r.get("model_reused") is True for r in ok) if task.kind == "simulate" else None,
    }
