"""benchmarks/bench_whole_run_budget.py: its ratio is the bench's whole / floor, its budget the run time
at which that ratio meets the target, and its timers split a run without counting anything twice."""

import importlib.util
from pathlib import Path

import pytest

from clutchocp.bench.run import whole_over_floor as bench_whole_over_floor
from clutchocp.simulation.compiled import ColumnFunction
from clutchocp.simulation.idas_path import IdasPath

ROOT = Path(__file__).resolve().parents[2]


def _bench():
    spec = importlib.util.spec_from_file_location("bench_whole_run_budget",
                                                  ROOT / "benchmarks" / "bench_whole_run_budget.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_ratio_is_the_bench_ratio_and_the_budget_meets_the_target():
    bench = _bench()
    t_whole, t_floor, r_whole, r_floor = 4.1e-3, 1.05e-3, 85.5e-3, 72.5e-3
    entry = {"speedup_vs_radau": r_whole / t_whole, "floor_speedup_vs_radau": r_floor / t_floor,
             "speedup_vs_lsoda": None, "floor_speedup_vs_lsoda": None}
    assert bench.whole_over_floor(t_whole, t_floor, r_whole, r_floor) == pytest.approx(
        bench_whole_over_floor(entry)["whole_over_floor_vs_radau"], rel=1e-14)
    allowed = bench.budget(t_floor, r_whole, r_floor)
    assert bench.whole_over_floor(allowed, t_floor, r_whole, r_floor) == pytest.approx(bench.TARGET, rel=1e-14)
    assert bench.whole_over_floor(1.01 * allowed, t_floor, r_whole, r_floor) < bench.TARGET


def test_parts_of_a_run_add_up_and_the_timers_are_removed():
    inner = (ColumnFunction.__call__, ColumnFunction.on_numpy, IdasPath._run)
    rows = _bench().measure("zhang2021", [1e-5], repeats=1, engines=["vm"])
    assert (ColumnFunction.__call__, ColumnFunction.on_numpy, IdasPath._run) == inner
    (row,) = rows
    parts = row["parts_ms"]
    assert set(parts) == {"integrator_calls", "grid_evaluations", "summary", "loop"}
    assert all(value > 0 for value in parts.values()), parts          # a part counted twice drives the loop below 0
    assert sum(parts.values()) == pytest.approx(row["timed_whole_ms"], rel=1e-12)
    assert row["whole_over_floor"] < row["whole_over_floor_without_loop"]
    assert row["budget_ms"] > row["idas_floor_ms"] > 0
