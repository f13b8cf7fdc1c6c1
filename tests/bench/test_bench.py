"""Benchmark machinery (clutchocp.bench): matched-error interpolation, growth exponents, error
measures against a confirmed reference, CVODES on the engine, and one small end-to-end run of
run_bench (the full and --quick runs are benchmarks, not tests)."""

import csv
import json
import math

import numpy as np
import pytest

from clutchocp.bench import floor, optimization, scaling
from clutchocp.bench import run as bench_run
from clutchocp.bench import workprecision as wp
from clutchocp.bench.progress import Progress
from clutchocp.engagement.model import EngagementModel
from clutchocp.engagement.run import simulate_engagement
from clutchocp.errors import ClutchocpError, ModelError, SolverError
from clutchocp.scene.loader import load_scene


def test_time_at_error_interpolates_a_power_law_exactly():
    # time = 2 error^-0.25: log-log linear, so interpolation between any two points is exact
    points = [(e, 2 * e**-0.25) for e in (1e-3, 1e-5, 1e-7)]
    assert wp.time_at_error(points, 1e-6) == pytest.approx(2 * 1e-6**-0.25, rel=1e-12)
    assert wp.time_at_error(points, 1e-8) is None and wp.time_at_error(points, 1e-2) is None


def test_time_at_error_uses_the_pareto_front():
    # (1e-4, 5.0) is beaten by (1e-5, 2.0): more accurate and cheaper, so it is not on the front;
    # a run without a finite error is left out
    points = [(1e-3, 1.0), (1e-4, 5.0), (1e-5, 2.0), (math.inf, 0.1)]
    assert wp.pareto_front(points) == [(1e-5, 2.0), (1e-3, 1.0)]
    assert wp.time_at_error(points, 1e-4) == pytest.approx(math.sqrt(2.0), rel=1e-12)   # log-midpoint of 2 and 1


def test_a_loose_run_slower_than_a_tight_one_leaves_the_levels_between_them_reached():
    # a two-tolerance sweep whose loose run was timed slower than its tight one (a busy machine):
    # the tight run is the cheapest at least as accurate at every level up to the loose run's error
    points = [(1e-8, 2.0), (1e-5, 3.0)]
    assert wp.pareto_front(points) == [(1e-8, 2.0)]
    assert wp.time_at_error(points, 1e-6) == 2.0 and wp.time_at_error(points, 1e-5) == 2.0
    assert wp.time_at_error(points, 1e-9) is None and wp.time_at_error(points, 1e-4) is None
    rows = [{"method": m, "status": "ok", "error": e, "wall_time_s": w}
            for m, pts in (("idas", [(1e-8, 1.0), (1e-5, 0.5)]), ("Radau", points)) for e, w in pts]
    ratios = wp.speedups(rows, peers=("Radau",), levels=(1e-6,))["Radau"]
    assert ratios[1e-6] == pytest.approx(2.0 / 0.5 ** (2 / 3))          # idas: 2/3 of the way in log-log


def test_speedups_divide_peer_time_by_idas_time_at_each_level():
    rows = [{"method": m, "status": "ok", "error": e, "wall_time_s": f * e**-0.2}
            for m, f in (("idas", 1.0), ("Radau", 7.0)) for e in (1e-4, 1e-6, 1e-8)]
    ratios = wp.speedups(rows, peers=("Radau",), levels=(1e-5, 1e-7, 1e-9))
    assert ratios["Radau"][1e-5] == pytest.approx(7.0) and ratios["Radau"][1e-7] == pytest.approx(7.0)
    assert ratios["Radau"][1e-9] is None
    assert wp.headline(ratios["Radau"]) == (pytest.approx(7.0), pytest.approx(7.0), 2)


def test_whole_over_floor_divides_the_whole_run_speedup_by_the_floor():
    entry = {"speedup_vs_radau": 3.0, "floor_speedup_vs_radau": 6.0, "speedup_vs_lsoda": 2.0,
             "floor_speedup_vs_lsoda": None}
    assert bench_run.whole_over_floor(entry) == {"whole_over_floor_vs_radau": 0.5, "whole_over_floor_vs_lsoda": None}


def _rows(times):
    """Work-precision rows from ``{method: [(error, wall_time_s, integration_time_s), ...]}``."""
    return [{"method": m, "status": "ok", "error": e, "wall_time_s": w, "integration_time_s": i}
            for m, pts in times.items() for e, w, i in pts]


def test_whole_over_floor_bound_divides_the_peer_time_by_idas_integration_time_then_by_the_floor():
    rows = _rows({"idas": [(1e-4, 2.0, 1.0), (1e-6, 4.0, 2.5), (1e-8, 8.0, 4.0)],
                  "Radau": [(1e-4, 10.0, 9.0), (1e-6, 40.0, 30.0), (1e-8, 160.0, 150.0)]})
    entry = {"floor_speedup_vs_radau": 40.0, "floor_speedup_vs_lsoda": 5.0}
    # by hand, at the log-midpoints 1e-5 and 1e-7: Radau's wall time sqrt(10 * 40) = 20 and
    # sqrt(40 * 160) = 80, IDAS's integration time sqrt(1 * 2.5) and sqrt(2.5 * 4); the geometric
    # mean of the two ratios is sqrt(20 * 80 / sqrt(25)) = sqrt(320); over the floor 40
    bound = bench_run.whole_over_floor_bound(rows, entry, levels=(1e-5, 1e-7))
    assert bound["whole_over_floor_bound_vs_radau"] == pytest.approx(math.sqrt(320.0) / 40.0, rel=1e-12)
    assert bound["whole_over_floor_bound_vs_lsoda"] is None                 # no LSODA rows
    # whole / floor from the wall times: IDAS sqrt(2 * 4) and sqrt(4 * 8), so sqrt(20 * 80 / 16) / 40
    whole = wp.headline(wp.speedups(rows, peers=("Radau",), levels=(1e-5, 1e-7))["Radau"])[0]
    assert whole / 40.0 == pytest.approx(0.25, rel=1e-12)
    assert bound["whole_over_floor_bound_vs_radau"] >= whole / 40.0


def test_whole_over_floor_bound_is_whole_over_floor_over_the_integrator_share_of_the_run():
    # IDAS spends a fixed share of every run inside its integrator calls: the bound is whole / floor
    # over that share, so never below whole / floor
    for share in (1.0, 0.7, 0.25):
        rows = _rows({"idas": [(e, 3.0 * e**-0.2, share * 3.0 * e**-0.2) for e in (1e-4, 1e-6, 1e-8)],
                      "LSODA": [(e, 9.0 * e**-0.3, 1.0) for e in (1e-4, 1e-6, 1e-8)]})
        entry = {"floor_speedup_vs_lsoda": 4.0, "speedup_vs_lsoda": wp.headline(wp.speedups(rows, peers=("LSODA",))["LSODA"])[0]}
        ratio = bench_run.whole_over_floor(entry, peers=("LSODA",))["whole_over_floor_vs_lsoda"]
        bound = bench_run.whole_over_floor_bound(rows, entry, peers=("LSODA",))["whole_over_floor_bound_vs_lsoda"]
        assert bound == pytest.approx(ratio / share, rel=1e-12) and bound >= ratio


def _idas_and_radau_rows(**columns):
    """IDAS and Radau rows at errors 1e-4, 1e-6, 1e-8 (wall times 2, 4, 8 and 10, 40, 160 s; IDAS's
    integration times 1, 2.5, 4 s), with extra ``columns`` (key -> six values, IDAS's rows first)."""
    rows = _rows({"idas": [(1e-4, 2.0, 1.0), (1e-6, 4.0, 2.5), (1e-8, 8.0, 4.0)],
                  "Radau": [(1e-4, 10.0, 9.0), (1e-6, 40.0, 30.0), (1e-8, 160.0, 150.0)]})
    for key, values in columns.items():
        for row, value in zip(rows, values):
            row[key] = value
    return rows


def _radau_bound(rows, bound):
    """The bound against Radau at the log-midpoints 1e-5 and 1e-7, floor speed-up 40."""
    entry = {"floor_speedup_vs_radau": 40.0}
    return bench_run.whole_over_floor_bound(rows, entry, peers=("Radau",), levels=(1e-5, 1e-7),
                                            bound=bound)[f"{bound}_vs_radau"]


def test_summary_bound_adds_idas_summary_work_to_its_integrator_calls():
    # the peer's summary work is not read
    rows = _idas_and_radau_rows(summary_work_s=(1.5, 1.5, 2.0, 9.0, 9.0, 9.0))
    # by hand, at the log-midpoints 1e-5 and 1e-7: IDAS's calls plus summary work sqrt(2.5 * 4) and
    # sqrt(4 * 6), Radau's wall time 20 and 80: sqrt(20 * 80 / sqrt(10 * 24)) / 40
    bound = _radau_bound(rows, "whole_over_floor_summary_bound")
    assert bound == pytest.approx(math.sqrt(20.0 * 80.0 / math.sqrt(240.0)) / 40.0, rel=1e-12)
    assert bound < _radau_bound(rows, "whole_over_floor_bound")
    assert "calls_and_work_s" not in rows[0]                        # the rows are left as they were


def test_events_bound_adds_idas_event_work_to_its_calls_and_summary_work():
    rows = _idas_and_radau_rows(summary_work_s=(1.5, 1.5, 2.0, 9.0, 9.0, 9.0),
                                event_work_s=(0.5, 0.5, 1.0, 9.0, 9.0, 9.0))
    # by hand, at the log-midpoints 1e-5 and 1e-7: IDAS's calls, summary and event work sqrt(3 * 4.5)
    # and sqrt(4.5 * 7), Radau's wall time 20 and 80: sqrt(20 * 80 / sqrt(13.5 * 31.5)) / 40
    bound = _radau_bound(rows, "whole_over_floor_events_bound")
    assert bound == pytest.approx(math.sqrt(20.0 * 80.0 / math.sqrt(13.5 * 31.5)) / 40.0, rel=1e-12)
    assert bound < _radau_bound(rows, "whole_over_floor_summary_bound")
    with pytest.raises(KeyError):                                   # only the bounds the bench reports
        _radau_bound(rows, "whole_over_floor_event_bound")


def test_replay_bound_divides_by_the_replayed_calls_and_the_summary_arithmetic_alone():
    rows = _idas_and_radau_rows(replayed_calls_s=(1.2, 3.0, 5.0, 9.0, 9.0, 9.0),
                                summary_arithmetic_s=(0.3, 0.5, 1.0, 9.0, 9.0, 9.0))
    # by hand, at the log-midpoints 1e-5 and 1e-7: IDAS's replayed calls plus summary arithmetic
    # sqrt(1.5 * 3.5) and sqrt(3.5 * 6) (its integration time is part of the replay, not added),
    # Radau's wall time 20 and 80: sqrt(20 * 80 / sqrt(5.25 * 21)) / 40
    assert _radau_bound(rows, "whole_over_floor_replay_bound") == pytest.approx(
        math.sqrt(20.0 * 80.0 / math.sqrt(5.25 * 21.0)) / 40.0, rel=1e-12)


def test_timed_runs_per_point():
    assert wp.timed_runs("idas", 1) == 3 and wp.timed_runs("Radau", 1) == 1
    least = {"Radau": 3, "LSODA": 3}
    assert wp.timed_runs("Radau", 1, least) == 3 and wp.timed_runs("BDF", 1, least) == 1
    assert wp.timed_runs("idas", 2, least) == 6 and wp.timed_runs("LSODA", 5, least) == 5


def test_growth_exponent_of_a_power_law():
    n = np.array([1, 2, 4, 8, 16])
    assert scaling.growth_exponent(n, 3e-3 * n**1.25) == pytest.approx(1.25, rel=1e-12)


def test_with_pairs_repeats_the_plate_mass():
    scene = scaling.with_pairs(load_scene("bao2020"), 4)
    assert scene.value("plates.n_interfaces") == 4
    assert list(scene.value("pack.plate_masses")) == [pytest.approx(0.367)] * 4
    assert scaling.with_pairs(load_scene("zhang2021"), 3).value("plates.n_interfaces") == 3


def test_with_pairs_keeps_the_heat_capacity_of_each_interface():
    scene = load_scene("default_driveline")                          # [thermal], 4 interfaces
    for n in (1, 16):                                                # 16: more than the linings of 4 pairs hold
        variant = scaling.with_pairs(scene, n)
        for key in scaling.THERMAL_TOTALS:
            per_interface = scene.value(key) / scene.value("plates.n_interfaces")
            assert variant.value(key) / variant.value("plates.n_interfaces") == pytest.approx(per_interface, rel=1e-15)


@pytest.fixture(scope="module")
def zhang():
    scene = load_scene("zhang2021")
    model = EngagementModel(scene)
    reference, confirmation = wp.reference_runs(scene, model)
    return scene, model, reference, confirmation


def test_reference_is_confirmed_by_a_second_method(zhang):
    """IDAS at rtol 1e-12 against scipy Radau at 1e-10 on the same equations: measured 3e-11."""
    _, _, _, confirmation = zhang
    assert confirmation["method"] == "Radau"
    assert confirmation["errors"]["max"] <= 1e-9


def test_error_measures_vanish_on_the_reference_and_shrink_with_the_tolerance(zhang):
    scene, model, reference, _ = zhang
    assert wp.trajectory_errors(reference, reference)["max"] == 0.0
    loose = wp.trajectory_errors(wp.run_method(scene, model, "idas", 1e-5), reference)
    tight = wp.trajectory_errors(wp.run_method(scene, model, "idas", 1e-8), reference)
    assert set(loose) == {"speeds", "gaps", "lock_time", "torque_jump", "max"}
    assert loose["max"] == max(loose[k] for k in wp.ERROR_PARTS)
    assert 0 < tight["max"] < loose["max"] / 30        # three decades of tolerance, > 1.5 decades of error


def test_a_run_that_never_locks_has_infinite_lock_time_error(zhang):
    scene, model, reference, _ = zhang
    short = simulate_engagement(scene, model=model, rtol=1e-8, atol=1e-10)
    short.summary = dict(short.summary, engagement_time_s=None, lockup_torque_jump_Nm=None)
    errors = wp.trajectory_errors(short, reference)
    assert errors["lock_time"] == math.inf and errors["max"] == math.inf


def test_engine_event_tolerances_follow_the_integration_tolerance():
    assert wp.event_options(1e-4) == {"event_value_tol": 1e-6, "event_time_tol": 1e-9}
    assert wp.event_options(1e-10) == {"event_value_tol": 1e-10, "event_time_tol": pytest.approx(1e-13)}


def test_cvodes_integrates_the_same_equations_as_idas(zhang):
    """CVODES (BDF, ODE) through the same hybrid engine: lock time within 1e-7 of the reference
    at rtol 1e-9 (measured 6e-10), with its step counts reported."""
    scene, model, reference, _ = zhang
    run = wp.run_method(scene, model, "cvodes", 1e-9)
    assert run.summary["solver"]["method"] == "cvodes"
    assert run.summary["solver"]["statistics"]["n_steps"] > 0
    assert wp.trajectory_errors(run, reference)["lock_time"] <= 1e-7


def test_cvodes_refuses_a_mode_with_algebraic_variables():
    """A compliant output shaft makes the clutch hub speed an algebraic variable: CVODES cannot
    integrate that DAE, and says so."""
    scene = load_scene("default_driveline").with_overrides({"driveline.shaft_stiffness": "5e3 N m",
                                                           "driveline.shaft_damping": "5 N m s"})
    with pytest.raises(ModelError, match="cvodes.*algebraic"):
        simulate_engagement(scene, method="cvodes")


def test_wall_time_cap_stops_every_method_with_a_clear_message():
    scene = load_scene("bao2020")
    model = EngagementModel(scene)
    for method in ("idas", "cvodes", "Radau"):
        with pytest.raises(SolverError, match="wall-time limit") as info:
            simulate_engagement(scene, model=model, method=method, solver_options={"max_wall_time": 1e-4})
        assert "Try:" in str(info.value)


def test_progress_goes_to_the_given_stream(capsys):
    import io

    stream = io.StringIO()
    bar = Progress(4, stream=stream)
    bar.step("first")
    bar.note("aside")
    bar.close()
    text = stream.getvalue()
    lines = text.replace("\r", "\n").splitlines()
    assert "1/4" in text                                                   # the count of steps done
    assert [line.split()[-1] for line in lines if "first" in line or "aside" in line] == ["first", "aside"]
    assert all(line.split()[0].count(":") == 1 for line in lines if "first" in line)      # elapsed mm:ss
    assert capsys.readouterr().err == ""                                   # nothing beside the stream
    Progress(2, enabled=False).step("silent")
    assert capsys.readouterr().err == ""


def test_floor_pieces_run_from_switch_to_switch(zhang):
    """zhang2021 slips, then locks: two pieces, the first from t = 0 to the lock-up event, the
    second from the state after the lock-up (locked mode) to the end."""
    scene, model, reference, _ = zhang
    parts = floor.pieces(reference)
    lock = reference.result.events[-1]
    assert [p[0].name for p in parts] == [lock.source, lock.target]
    assert parts[0][1] == 0.0 and parts[0][4] == pytest.approx(lock.t, abs=0)
    assert parts[1][1] == lock.t and parts[1][4] == scene.value("simulation.t_end")
    cm = parts[1][0]
    after = np.array([lock.x_after[n] for n in cm.x_names]) / cm.x_nominal
    assert np.array_equal(parts[1][2], after)


def test_floor_pieces_reproduce_the_reference_with_both_integrators(zhang):
    """Each piece integrated alone from the reference state at its start, by IDAS and by scipy
    Radau (independent integrators), ends on the reference state; the error shrinks with rtol."""
    _, model, reference, _ = zhang
    parts = floor.pieces(reference)
    errors = {}
    for method in ("idas", "Radau"):
        for rtol in (1e-5, 1e-9):
            time_s, errors[method, rtol] = floor.floor_run(model, parts, method, rtol, repeats=1)
            assert time_s > 0
        assert errors[method, 1e-9] < errors[method, 1e-5]
        assert errors[method, 1e-9] <= 1e-7


def test_run_bench_end_to_end_writes_its_files(tmp_path, monkeypatch):
    """A reduced run (one scene, two tolerances, two methods, two pack sizes, no optimisation)
    through the real run_bench: every file and the summary keys the lead's CLI reports."""
    monkeypatch.setitem(bench_run.QUICK, "tolerances", (1e-5, 1e-8))
    monkeypatch.setitem(bench_run.QUICK, "methods", ("idas", "cvodes", "Radau", "BDF", "LSODA"))
    monkeypatch.setattr(scaling, "PAIRS", (1, 2))
    monkeypatch.setattr(optimization, "plan", lambda quick: None)
    summary = bench_run.run_bench(tmp_path, quick=True, progress=False, scenes=[load_scene("zhang2021")])
    names = {p.name for p in tmp_path.iterdir()}
    assert {"summary.json", "engagement_work_precision.csv", "engagement_work_precision.png",
            "engagement_speedup.csv", "engagement_integrator_floor.csv", "scaling.csv", "scaling.png", "stiffness_zhang2021.png",
            "stiffness_zhang2021.csv"} <= names
    written = json.loads((tmp_path / "summary.json").read_text())
    entry = written["scenes"]["zhang2021"]
    for key in ("speedup_vs_radau", "speedup_vs_bdf", "speedup_vs_lsoda", "speedup_vs_cvodes",
                "scaling_exponent_pairs", "stiffness"):
        assert key in entry
    assert entry["scaling"]["pairs"] == [1, 2]
    assert written["optimization"]["available"] is False
    assert "targets" not in summary and "engagement_targets" not in summary     # no fixed targets
    assert all(s["time_ratio"] < 1.0 and s["scene"] == "zhang2021" for s in written["idas_slower"])
    for key in ("speedup_vs_radau_integration", "speedup_vs_lsoda_integration"):
        assert entry[key] is not None and entry[key] > 0
    rows = [r for r in csv.DictReader(open(tmp_path / "engagement_work_precision.csv")) if r["status"] == "ok"]
    for row in rows:     # the integrator calls are part of the run, so they take less time than it
        assert 0 < float(row["integration_time_s"]) < float(row["wall_time_s"])
    whole = {(r["method"], r["rtol"]): r for r in rows}
    low = [r for r in csv.DictReader(open(tmp_path / "engagement_integrator_floor.csv")) if r["status"] == "ok"]
    assert {r["method"] for r in low} == {"idas", "Radau", "LSODA"}
    for row in low:      # a floor point keeps the error of the whole run at its tolerance
        assert float(row["time_s"]) > 0
        assert row["error"] == whole[row["method"], row["rtol"]]["error"]
    for method in ("idas", "Radau", "LSODA"):       # and its pieces end nearer the reference at 1e-8
        end = {float(r["rtol"]): float(r["piece_end_error"]) for r in low if r["method"] == method}
        assert end[1e-8] < end[1e-5], method
    for key in ("floor_speedup_vs_radau", "floor_speedup_vs_lsoda"):
        assert entry[key] is not None and entry[key] > 0
    assert written["scenes"]["zhang2021"].keys() >= {"whole_over_floor_vs_radau", "whole_over_floor_vs_lsoda"}
    assert entry["whole_over_floor_vs_radau"] == bench_run.whole_over_floor(entry)["whole_over_floor_vs_radau"]
    for row in rows:     # IDAS's summary and event work are part of its run; the other methods' are not timed
        if row["method"] == "idas":
            outside = float(row["wall_time_s"]) - float(row["integration_time_s"])
            assert 0 < float(row["event_work_s"]) < float(row["summary_work_s"]) < outside
            assert float(row["replayed_calls_s"]) > 0 and float(row["summary_arithmetic_s"]) > 0
        else:
            assert all(row[k] == "" for k in ("summary_work_s", "event_work_s", "summary_arithmetic_s",
                                              "replayed_calls_s"))
    rows_written = [{**r, "error": float(r["error"]), "wall_time_s": float(r["wall_time_s"]),
                     "integration_time_s": float(r["integration_time_s"]),
                     "summary_work_s": float(r["summary_work_s"] or "nan"),
                     "event_work_s": float(r["event_work_s"] or "nan"),
                     "summary_arithmetic_s": float(r["summary_arithmetic_s"] or "nan"),
                     "replayed_calls_s": float(r["replayed_calls_s"] or "nan")} for r in rows]
    for peer in ("radau", "lsoda"):       # the bound, recomputed from the written rows, is above whole / floor
        bound = bench_run.whole_over_floor_bound(rows_written, entry)[f"whole_over_floor_bound_vs_{peer}"]
        assert entry[f"whole_over_floor_bound_vs_{peer}"] == pytest.approx(bound, rel=1e-9)
        assert bound > entry[f"whole_over_floor_vs_{peer}"]      # integrator calls are part of the run
        with_summary = bench_run.whole_over_floor_bound(rows_written, entry, bound="whole_over_floor_summary_bound")
        key = f"whole_over_floor_summary_bound_vs_{peer}"
        assert entry[key] == pytest.approx(with_summary[key], rel=1e-9)
        assert entry[f"whole_over_floor_vs_{peer}"] < entry[key] < bound  # so is the summary work
        with_events = bench_run.whole_over_floor_bound(rows_written, entry, bound="whole_over_floor_events_bound")
        events_key = f"whole_over_floor_events_bound_vs_{peer}"
        assert entry[events_key] == pytest.approx(with_events[events_key], rel=1e-9)
        assert entry[f"whole_over_floor_vs_{peer}"] < entry[events_key] < entry[key]  # and the event checks
        replay = bench_run.whole_over_floor_bound(rows_written, entry, bound="whole_over_floor_replay_bound")
        replay_key = f"whole_over_floor_replay_bound_vs_{peer}"
        assert entry[replay_key] == pytest.approx(replay[replay_key], rel=1e-9)
        assert entry[f"whole_over_floor_vs_{peer}"] < entry[replay_key]   # the Python around the calls is not replayed
    assert written["single_run_s"] == {}          # bao2020 not among the scenes: not timed
    text = bench_run.format_summary(summary)
    assert "issue" not in text and "target" not in text and "integrator floor" in text
    assert "no time outside the integrator calls" in text


def test_sweep_methods_take_turns_at_each_tolerance(monkeypatch):
    # the timed runs are recorded in the order they are made: at each tolerance one run of each
    # method per round, until each has had its count (the engine's idas three times the peers'); a
    # method whose warm-up says it does not apply gets its rows without being timed; the best run
    # counts, each row keeps the run of its best wall time
    timed = []

    class Run:
        def __init__(self, wall):
            self.summary = {"solver": {"statistics": {"integration_time_s": wall / 2, "n_steps": 10}},
                            "engagement_time_s": 0.1, "lockup_torque_jump_Nm": -1.0, "wall_time_s": wall}

    def warm_up(scene, model, method, rtol, **options):
        if method == "cvodes":
            raise ModelError("mode 'x' has algebraic variables")

    def timed_run(scene, model, method, rtol, repeats=1, **options):
        timed.append((method, rtol))
        wall = 1e-3 * (5 - sum(1 for m, r in timed if (m, r) == (method, rtol)))   # faster each time
        return wall, 2 * wall, Run(wall)

    monkeypatch.setattr(wp, "reference_runs", lambda scene, model: (Run(1.0), {}))
    monkeypatch.setattr(wp, "run_method", warm_up)
    monkeypatch.setattr(wp, "timed_run", timed_run)
    monkeypatch.setattr(wp, "summary_time", lambda run, count: (1e-4, None))
    monkeypatch.setattr(wp, "event_work_time", lambda run, count: 1e-5)
    monkeypatch.setattr(wp, "summary_arithmetic_time", lambda run, count: 3e-5)
    monkeypatch.setattr(wp, "run_replay_time", lambda scene, model, method, rtol, count: 1.5e-3)
    monkeypatch.setattr(wp, "trajectory_errors", lambda run, reference: dict.fromkeys(("max", *wp.ERROR_PARTS), 1e-6))
    scene = load_scene("zhang2021")
    methods, tolerances = ("idas", "cvodes", "Radau", "LSODA"), (1e-4, 1e-6, 1e-8)
    res = wp.sweep(scene, methods=methods, tolerances=tolerances, model=object(), repeats=1)
    assert timed == [(m, r) for r in tolerances for m in ("idas", "Radau", "LSODA", "idas", "idas")]
    assert [(row["method"], row["rtol"]) for row in res["rows"]] == [(m, r) for m in methods for r in tolerances]
    assert all(row["status"].startswith("n/a") for row in res["rows"] if row["method"] == "cvodes")
    for row in res["rows"]:
        if row["method"] == "idas":        # three runs: 4, 3, 2 ms; the best, with its own run's statistics
            assert (row["wall_time_s"], row["cpu_time_s"], row["integration_time_s"]) == (2e-3, 4e-3, 1e-3)
            assert (row["event_work_s"], row["summary_arithmetic_s"], row["replayed_calls_s"]) == (1e-5, 3e-5, 1.5e-3)
        elif row["method"] != "cvodes":    # one run
            assert row["wall_time_s"] == 4e-3


def test_floor_methods_take_turns_at_each_tolerance(monkeypatch):
    passes = []

    def floor_pass(model, parts, method, rtol, path):
        passes.append((method, rtol))
        return 1e-3 * (5 - sum(1 for p in passes if p == (method, rtol))), 1e-9

    class Reference:
        model = type("Model", (), {"scene": type("Scene", (), {"name": "s"})()})()

    monkeypatch.setattr(floor, "pieces", lambda reference: [])
    monkeypatch.setattr(floor, "floor_path", lambda model, method, rtol, native=False: None)
    monkeypatch.setattr(floor, "floor_pass", floor_pass)
    sweep_rows = [{"method": m, "rtol": r, "status": "ok", "error": r} for m in ("idas", "BDF", "Radau", "LSODA")
                  for r in (1e-4, 1e-6)]
    low = floor.integrator_floor(Reference(), sweep_rows, repeats=2)
    turn = ["idas", "Radau", "LSODA"]
    assert passes == [(m, r) for r in (1e-4, 1e-6) for m in turn * 3]       # an untimed pass each, then two rounds
    assert [(row["method"], row["rtol"]) for row in low["rows"]] == [(m, r) for m in floor.METHODS for r in (1e-4, 1e-6)]
    assert all(row["time_s"] == 2e-3 for row in low["rows"])               # the best of the timed passes (3, 2 ms)


def test_floor_methods_with_more_repeats_take_the_extra_rounds_after_the_others(monkeypatch):
    """``least_repeats``: IDAS's short floor passes timed more often than its peers', the peers in the
    first rounds."""
    passes = []

    def floor_pass(model, parts, method, rtol, path):
        passes.append(method)
        return 1e-3 * (10 - passes.count(method)), 1e-9

    class Reference:
        model = type("Model", (), {"scene": type("Scene", (), {"name": "s"})()})()

    monkeypatch.setattr(floor, "pieces", lambda reference: [])
    monkeypatch.setattr(floor, "floor_path", lambda model, method, rtol, native=False: None)
    monkeypatch.setattr(floor, "floor_pass", floor_pass)
    sweep_rows = [{"method": m, "rtol": 1e-5, "status": "ok", "error": 1e-5} for m in floor.METHODS]
    low = floor.integrator_floor(Reference(), sweep_rows, repeats=2, least_repeats={"idas": 4})
    turn = ["idas", "Radau", "LSODA"]
    assert passes == turn * 3 + ["idas", "idas"]               # an untimed pass each, two rounds, two more for IDAS
    best = {row["method"]: row["time_s"] for row in low["rows"]}
    assert best == pytest.approx({"idas": 5e-3, "Radau": 7e-3, "LSODA": 7e-3})   # the last (fastest) pass of each


def test_a_method_failing_in_a_round_is_reported_and_not_timed_again(monkeypatch):
    timed = []

    class Run:
        summary = {"solver": {"statistics": {"integration_time_s": 1e-3, "n_steps": 10}}, "engagement_time_s": 0.1}

    def timed_run(scene, model, method, rtol, repeats=1, **options):
        timed.append(method)
        if method == "idas" and timed.count("idas") == 2:
            raise ClutchocpError("IDAS failed at t = 0.1 s")
        return 2e-3, 4e-3, Run()

    monkeypatch.setattr(wp, "timed_run", timed_run)
    monkeypatch.setattr(wp, "trajectory_errors", lambda run, reference: dict.fromkeys(("max", *wp.ERROR_PARTS), 1e-6))
    scene = type("Scene", (), {"name": "s"})()
    rows = wp._points(scene, None, None, ("idas", "Radau"), 1e-6, 1, {"Radau": 3}, None)
    assert timed == ["idas", "Radau", "idas", "Radau", "Radau"]     # no idas run after its failure
    idas, radau = rows
    assert idas["status"].startswith("failed: IDAS failed") and radau["status"] == "ok"
    assert radau["wall_time_s"] == 2e-3 and radau["cpu_time_s"] == 4e-3
