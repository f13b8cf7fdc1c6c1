"""The engines of a sweep: batches of points, forked local workers and a LocalCluster started by the sweep."""

import csv

import pytest

from clutchocp.study import run_sweep
from clutchocp.study.executor import batches, start_method
from clutchocp.study.folder import RESULTS

GRID = ["actuation.pressure=0.3 MPa:0.6 MPa:2", "oil.viscosity=0.04:0.06:3"]
TIMING = ("build_time_s", "integration_time_s", "run_time_s")               # wall-clock, not results


def _rows(folder):
    with (folder / RESULTS).open(newline="") as fh:
        return {r["point_id"]: {k: v for k, v in r.items() if k not in TIMING} for r in csv.DictReader(fh)}


@pytest.fixture(scope="module")
def serial_rows(tmp_path_factory):
    out = tmp_path_factory.mktemp("serial") / "s"
    run_sweep("zhang2021", out, grid=GRID, engine="serial", progress=False, options={"native": False})
    return _rows(out)


@pytest.mark.parametrize("n_units, workers", [(200, 2), (19, 2), (7, 4), (1, 8), (0, 2)])
def test_batches_keep_every_unit_once_in_order_and_shrink_to_single_units(n_units, workers):
    units = [[{"k": float(i)}] for i in range(n_units)]
    parts = batches(units, workers)
    assert [u for part in parts for u in part] == units
    sizes = [len(p) for p in parts]
    assert all(sizes) and sizes == sorted(sizes, reverse=True)
    if n_units:
        assert sizes[0] == -(-n_units // (4 * workers)) and sizes[-1] == 1
    if n_units == 200:                    # 25, 22, 20, 17 ... 1: 29 messages instead of 200
        assert sizes[:4] == [25, 22, 20, 17] and len(parts) < 50


def test_local_workers_give_the_rows_of_a_serial_sweep(tmp_path, serial_rows):
    summary = run_sweep("zhang2021", tmp_path / "s", grid=GRID, engine="local", workers=2, progress=False,
                        options={"native": False})
    assert summary["engine"]["start_method"] == start_method()
    rows = _rows(tmp_path / "s")
    assert rows == serial_rows                                       # the same text, to the last digit
    assert all(r["model_reused"] == "true" for r in rows.values())


def test_a_dask_local_cluster_started_by_the_sweep_gives_the_rows_of_a_serial_sweep(tmp_path, serial_rows):
    pytest.importorskip("distributed")
    summary = run_sweep("zhang2021", tmp_path / "s", grid=GRID, engine="dask", workers=2, progress=False,
                        options={"native": False})
    assert summary["engine"]["engine"] == "dask" and summary["engine"]["workers"] == 2
    assert _rows(tmp_path / "s") == serial_rows


def test_spawned_workers_where_fork_is_not_used_give_the_same_rows(tmp_path, serial_rows, monkeypatch):
    from clutchocp.study import executor

    monkeypatch.setattr(executor, "start_method", lambda: "spawn")       # as on macOS and Windows
    summary = run_sweep("zhang2021", tmp_path / "s", grid=GRID, engine="local", workers=2, progress=False,
                        options={"native": False})
    assert summary["engine"]["start_method"] == "spawn" and summary["engine"]["workers"] == 2
    assert _rows(tmp_path / "s") == serial_rows


_FREEZE_RECORD = {}           # where the forked workers write their frozen-object counts (set by the test)


def _run_unit_recording_the_frozen_heap(task, points):
    """The worker's run_unit, first writing how many objects this worker process holds frozen."""
    import gc
    import os
    from pathlib import Path

    from clutchocp.study.tasks import run_unit

    (Path(_FREEZE_RECORD["dir"]) / f"{os.getpid()}.txt").write_text(str(gc.get_freeze_count()))
    return run_unit(task, points)


def test_the_heap_is_frozen_for_the_workers_and_the_figures_and_handed_back_after(tmp_path, monkeypatch):
    """A full garbage collection rescans every object a sweep's process holds (0.1-0.15 s with a
    model built): the sweep freezes them, the forked workers inherit them frozen, the figures are
    drawn frozen, and at the end the heap is the collector's again."""
    import gc

    from clutchocp.study import executor, run

    if start_method() != "fork":
        pytest.skip("workers inherit the frozen heap only when they are forked")
    assert gc.get_freeze_count() == 0
    _FREEZE_RECORD["dir"] = tmp_path
    monkeypatch.setattr(executor, "run_unit", _run_unit_recording_the_frozen_heap)
    at_drawing = []
    draw = run.draw_study
    monkeypatch.setattr(run, "draw_study", lambda *a: at_drawing.append(gc.get_freeze_count()) or draw(*a))
    before_fork = []
    warm_up = executor.warm_up
    monkeypatch.setattr(executor, "warm_up", lambda *a: (before_fork.append(gc.get_freeze_count()), warm_up(*a))[1])
    run_sweep("zhang2021", tmp_path / "s", grid=GRID, engine="local", workers=2, progress=False,
              options={"native": False})
    counts = [int(p.read_text()) for p in tmp_path.glob("*.txt")]
    assert counts and before_fork[0] > 0
    assert all(c > before_fork[0] for c in counts)          # the warm-up's model frozen too, before the fork
    assert at_drawing[0] > 0
    assert gc.get_freeze_count() == 0                       # handed back


def test_a_heap_frozen_before_the_sweep_stays_frozen():
    import gc

    from clutchocp.study.executor import frozen_heap

    gc.freeze()
    try:
        frozen = gc.get_freeze_count()
        with frozen_heap():
            with frozen_heap():
                pass
            assert gc.get_freeze_count() >= frozen
        assert gc.get_freeze_count() >= frozen > 0
    finally:
        gc.unfreeze()
    with frozen_heap():
        assert gc.get_freeze_count() > 0
        with frozen_heap():
            pass
        assert gc.get_freeze_count() > 0                    # the inner block does not unfreeze the outer's
    assert gc.get_freeze_count() == 0


_REFERENCE_CALLS = {}         # pid -> what the patched usual run did (the child's is copied back by a file)


def _reference_off_by_one_per_cent(task, point, settings):
    """A usual run that disagrees with the parametric one (1 % on the peak torque)."""
    import os
    from pathlib import Path

    numbers = _REAL_REFERENCE[0](task, point, settings)
    (Path(_REFERENCE_CALLS["dir"]) / f"ref_{os.getpid()}.txt").write_text("called")
    return dict(numbers, peak_torque_Nm=numbers["peak_torque_Nm"] * 1.01)


def _reference_failing_in_the_child(task, point, settings):
    import os

    if os.getpid() != _REFERENCE_CALLS["parent"]:
        raise RuntimeError("the child's usual run failed")
    return _REAL_REFERENCE[0](task, point, settings)


_REAL_REFERENCE = []


@pytest.fixture
def warm_task(tmp_path, monkeypatch):
    import os

    from clutchocp.study import tasks

    if start_method() != "fork":
        pytest.skip("the usual run is made beside the warm-up only where processes are forked")
    tasks.clear_caches()
    _REAL_REFERENCE[:] = [tasks._reference_numbers]
    _REFERENCE_CALLS.update(dir=tmp_path, parent=os.getpid())
    yield tasks, tasks.Task("zhang2021", "simulate", options={"native": False})
    tasks.clear_caches()


POINTS = [{"actuation.pressure": 4e5, "oil.viscosity": v} for v in (0.07, 0.08)]


def test_the_warm_up_checks_its_model_against_a_usual_run_made_in_a_second_process(warm_task, tmp_path,
                                                                                   monkeypatch):
    import os

    tasks, task = warm_task
    monkeypatch.setattr(tasks, "_reference_numbers", _reference_off_by_one_per_cent)
    done, rest = tasks.warm_up(task, [[p] for p in POINTS])
    callers = [p.name for p in tmp_path.glob("ref_*.txt")]
    assert callers and f"ref_{os.getpid()}.txt" not in callers            # made by the forked process
    assert done[0][0]["status"] == "ok" and done[0][0]["model_reused"] is False   # the disagreement counted
    assert rest == [[POINTS[1]]] and not tasks._REFERENCES
    assert tasks.simulate_point(task, POINTS[1])[0]["model_reused"] is False      # one model per point from now


def test_a_usual_run_that_fails_beside_the_warm_up_is_made_again_in_the_sweep_process(warm_task, monkeypatch):
    tasks, task = warm_task
    monkeypatch.setattr(tasks, "_reference_numbers", _reference_failing_in_the_child)
    done, _ = tasks.warm_up(task, [[p] for p in POINTS])
    assert done[0][0]["status"] == "ok" and done[0][0]["model_reused"] is True


def test_a_usual_run_not_needed_by_the_warm_up_is_stopped(warm_task, monkeypatch):
    from clutchocp.study import parametric

    tasks, task = warm_task
    started = []

    class Recording(dict):
        def __setitem__(self, key, value):
            started.append(value[0])
            super().__setitem__(key, value)

    monkeypatch.setattr(tasks, "_REFERENCES", Recording())
    monkeypatch.setattr(parametric, "build", lambda scene, names: None)     # no reused model: nothing to check
    done, _ = tasks.warm_up(task, [[p] for p in POINTS])
    assert done[0][0]["status"] == "ok" and done[0][0]["model_reused"] is False
    assert len(started) == 1 and not started[0].is_alive() and started[0].exitcode is not None
    assert not tasks._REFERENCES


def test_the_local_cluster_starts_with_quick_nanny_polling_and_hands_the_setting_back(tmp_path, monkeypatch):
    distributed = pytest.importorskip("distributed")
    from distributed.nanny import WorkerProcess

    from clutchocp.study.executor import NANNY_START_POLL_S

    before = WorkerProcess._init_msg_interval
    seen = []
    cluster = distributed.LocalCluster

    def recording(*args, **kwargs):
        seen.append(WorkerProcess._init_msg_interval)
        return cluster(*args, **kwargs)

    monkeypatch.setattr(distributed, "LocalCluster", recording)
    summary = run_sweep("zhang2021", tmp_path / "s", grid=GRID[:1], engine="dask", workers=2, progress=False,
                        options={"native": False})
    assert summary["points_ok"] == 2 and seen == [NANNY_START_POLL_S] != [before]
    assert WorkerProcess._init_msg_interval == before
