"""benchmarks/bench_whole_run_budget.py: its ratio is the bench's whole / floor, its budget the run time
at which that ratio meets the target, and its timers split a run without counting anything twice."""

import pytest

from clutchocp.simulation.compiled import ColumnFunction
from clutchocp.simulation.driver import _Run
from clutchocp.simulation.idas_path import IdasPath
from repo_scripts import load_script


def _bench():
    return load_script("benchmarks/bench_whole_run_budget.py")


def test_budget_is_the_run_time_at_which_the_bench_ratio_meets_the_target():
    bench = _bench()
    t_whole, t_floor, r_whole, r_floor = 4.1e-3, 1.05e-3, 85.5e-3, 72.5e-3
    # (t_floor / t_whole) x (r_whole / r_floor), by hand
    assert bench.whole_over_floor(t_whole, t_floor, r_whole, r_floor) == pytest.approx(
        (1.05 / 4.1) * (85.5 / 72.5), rel=1e-14)
    allowed = bench.budget(t_floor, r_whole, r_floor)
    assert bench.whole_over_floor(allowed, t_floor, r_whole, r_floor) == pytest.approx(bench.TARGET, rel=1e-14)
    assert bench.whole_over_floor(1.01 * allowed, t_floor, r_whole, r_floor) < bench.TARGET


def test_parts_of_a_run_add_up_and_the_timers_are_removed():
    inner = (ColumnFunction.__call__, ColumnFunction.on_numpy, IdasPath._run, _Run.loop)
    rows = _bench().measure("zhang2021", [1e-5], repeats=1, engines=["vm"])
    assert (ColumnFunction.__call__, ColumnFunction.on_numpy, IdasPath._run, _Run.loop) == inner
    (row,) = rows
    parts = row["parts_ms"]
    assert set(parts) == {"integrator_calls", "grid_evaluations", "summary", "hybrid_loop", "setup_and_assembly"}
    # a part counted twice drives the hybrid loop or the setup and assembly below 0
    assert all(value > 0 for value in parts.values()), parts
    assert sum(parts.values()) == pytest.approx(row["timed_whole_ms"], rel=1e-12)
    assert row["whole_over_floor"] < row["whole_over_floor_without_loop"]
    assert row["budget_ms"] > row["idas_floor_ms"] > 0


def test_hybrid_loop_is_the_loop_without_the_calls_and_evaluations_made_inside_it():
    import clutchocp.simulation.driver as driver
    from clutchocp.bench.workprecision import run_method
    from clutchocp.engagement.model import EngagementModel
    from clutchocp.scene import load_scene

    scene = load_scene("zhang2021")
    model = EngagementModel(scene)
    run_method(scene, model, "idas", 1e-5)                       # builds and caches the integrators
    timers = _bench().PartTimers()
    try:
        run_method(scene, model, "idas", 1e-5)
        parts = dict(timers.parts)
    finally:
        timers.remove()
    assert driver._Run.loop is _Run.loop
    # every integrator call is made inside the loop; of the grid evaluations, those of the summary are not
    assert parts["loop_integrator_calls"] == parts["integrator_calls"]
    assert parts["loop_grid_evaluations"] == pytest.approx(
        parts["grid_evaluations"] - parts.get("summary_evaluations", 0.0), rel=1e-12)
    assert parts["loop_total"] > parts["loop_integrator_calls"] + parts["loop_grid_evaluations"]
    (row,) = _bench().measure("zhang2021", [1e-5], repeats=1, engines=["vm"])
    hybrid = row["parts_ms"]["hybrid_loop"]
    assert row["whole_over_floor_without_hybrid_loop"] == pytest.approx(
        (row["idas_floor_ms"] / (row["timed_whole_ms"] - hybrid)) * (row["radau_whole_ms"] / row["radau_floor_ms"]),
        rel=1e-12)
    assert row["whole_over_floor"] < row["whole_over_floor_without_hybrid_loop"] < row["whole_over_floor_without_loop"]


def test_ideal_ratio_is_that_of_a_run_costing_its_floor_plus_the_summary_work():
    (row,) = _bench().measure("zhang2021", [1e-5], repeats=1, engines=["vm"])
    floor, work, whole = row["idas_floor_ms"], row["summary_work_ms"], row["idas_whole_ms"]
    by_hand = (floor / (floor + work)) * (row["radau_whole_ms"] / row["radau_floor_ms"])
    assert row["whole_over_floor_ideal"] == pytest.approx(by_hand, rel=1e-12)
    assert row["path_overhead_ms"] == pytest.approx(whole - floor - work, rel=1e-12)
    assert row["path_allowance_ms"] == pytest.approx(row["budget_ms"] - floor - work, rel=1e-12)
    calls = row["parts_ms"]["integrator_calls"]
    assert row["whole_over_floor_calls_and_summary"] == pytest.approx(
        (floor / (calls + work)) * (row["radau_whole_ms"] / row["radau_floor_ms"]), rel=1e-12)
    assert row["whole_over_floor"] < row["whole_over_floor_ideal"]


def test_summary_and_event_work_are_timed_on_one_run_and_the_spy_is_removed():
    import clutchocp.engagement.run as run_module
    from clutchocp.bench.workprecision import run_method
    from clutchocp.engagement.model import EngagementModel
    from clutchocp.scene import load_scene

    scene = load_scene("zhang2021")
    model = EngagementModel(scene)
    inner = run_module.summarize
    work, events = _bench().summary_and_event_work(scene, model, "idas", 1e-5, repeats=2)
    assert run_module.summarize is inner
    assert 0 < events < work < run_method(scene, model, "idas", 1e-5).result.stats["wall_time_s"]
    (row,) = _bench().measure("zhang2021", [1e-5], repeats=1, engines=["vm"])
    calls, work, events = row["parts_ms"]["integrator_calls"], row["summary_work_ms"], row["event_work_ms"]
    assert row["whole_over_floor_calls_summary_events"] == pytest.approx(
        (row["idas_floor_ms"] / (calls + work + events)) * (row["radau_whole_ms"] / row["radau_floor_ms"]), rel=1e-12)
    assert row["whole_over_floor_calls_summary_events"] < row["whole_over_floor_calls_and_summary"]


def test_replay_ratio_is_that_of_the_runs_own_calls_and_the_summary_arithmetic():
    (row,) = _bench().measure("zhang2021", [1e-5], repeats=3, engines=["vm"])
    assert row["replayed_calls"]["integrator"] == row["replayed_calls"]["integrator_stats"] > 0
    assert row["whole_over_floor_calls_replayed"] == pytest.approx(
        (row["idas_floor_ms"] / (row["replayed_calls_ms"] + row["parts_ms"]["summary"]))
        * (row["radau_whole_ms"] / row["radau_floor_ms"]), rel=1e-12)
    assert row["replayed_calls_ms"] > 0
