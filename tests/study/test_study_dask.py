"""A sweep through a real Dask distributed scheduler with worker processes, started by the test."""

import csv

import pytest

distributed = pytest.importorskip("distributed")

from clutchocp.study import run_sweep  # noqa: E402
from clutchocp.study.folder import RESULTS  # noqa: E402

GRID = ["actuation.pressure=0.3 MPa:0.6 MPa:2", "oil.viscosity=0.04:0.06:2"]


def _rows(folder):
    with (folder / RESULTS).open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    timing = ("build_time_s", "integration_time_s", "run_time_s")                 # wall-clock, not results
    return {r["point_id"]: {k: v for k, v in r.items() if k not in timing} for r in rows}


def test_a_sweep_on_a_dask_local_cluster_gives_the_rows_of_a_serial_sweep(tmp_path):
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        summary = run_sweep("zhang2021", tmp_path / "dask", grid=GRID, engine="dask",
                            scheduler=cluster.scheduler_address, progress=False, options={"native": False})
        assert summary["engine"] == {"engine": "dask", "workers": 2, "address": cluster.scheduler_address}
        assert len(cluster.workers) == 2 and all(w.process is not None for w in cluster.workers.values())
    run_sweep("zhang2021", tmp_path / "serial", grid=GRID, engine="serial", progress=False, options={"native": False})
    dask_rows, serial_rows = _rows(tmp_path / "dask"), _rows(tmp_path / "serial")
    assert len(dask_rows) == 4 and dask_rows == serial_rows           # the same text, to the last digit
    assert all(r["status"] == "ok" for r in dask_rows.values())


def test_a_worker_with_several_threads_gives_the_rows_of_a_serial_sweep(tmp_path):
    """A worker's reused model is called through buffers bound once: its threads take the units in
    turn (without that, 15 of these 36 rows differed from the serial sweep's, one locking where
    it slips)."""
    grid = ["actuation.pressure=0.3 MPa:0.6 MPa:6", "oil.viscosity=0.06:0.08:6"]
    with distributed.LocalCluster(n_workers=1, threads_per_worker=4, processes=True, dashboard_address=None) as cluster:
        run_sweep("zhang2021", tmp_path / "dask", grid=grid, engine="dask", scheduler=cluster.scheduler_address,
                  progress=False)
    run_sweep("zhang2021", tmp_path / "serial", grid=grid, engine="serial", progress=False)
    dask_rows, serial_rows = _rows(tmp_path / "dask"), _rows(tmp_path / "serial")
    assert len(dask_rows) == 36 and dask_rows == serial_rows


@pytest.mark.slow
def test_an_unreachable_scheduler_is_one_clear_error(tmp_path):
    from clutchocp.study.executor import EngineError

    with pytest.raises(EngineError, match="no Dask scheduler reachable"):
        run_sweep("zhang2021", tmp_path / "s", grid=GRID[:1], engine="dask", scheduler="tcp://127.0.0.1:9",
                  progress=False)
