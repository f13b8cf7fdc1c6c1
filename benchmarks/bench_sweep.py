"""Benchmark of sweeps (not a test): parallel efficiency, Dask against the local pool, runs per second
per core, the share of a run spent outside the integrator calls, warm-started optimize maps.

    PYTHONPATH=. python benchmarks/bench_sweep.py --out out/bench_sweep          # several minutes (three optimize maps)
    PYTHONPATH=. python benchmarks/bench_sweep.py --points 40 --map 3            # a quick look
    PYTHONPATH=. python benchmarks/bench_sweep.py --skip share,optimize --model-per-point  # heavier points

Numbers (written to ``bench_sweep.json`` and printed):

* ``parallel_efficiency``: a zhang2021 simulate sweep (``--points``, default 200, default options:
  one model per worker, compiled C from the disk cache, which a 4-point sweep fills first) on the
  local pool with 1 worker and with 2 workers, both timed end to end (pool start, model build and
  figures included; the models and scenes this process holds from earlier sweeps are dropped
  before each timed sweep): ``T1 / (2 T2)``; target >= 0.85. ``parallel_efficiency_sweep_only``:
  the same from the sweeps' own ``wall_time_s`` (without the figures drawn at the end).
  ``efficiency_bound_from_cpu``: what the measured CPU seconds of the 2-worker sweep allow
  (:func:`efficiency_bound`: the sweep process's own CPU is serial, its workers' parallel).
  ``two_at_once``: the share of two cores' throughput two forked processes get on this machine
  (the same points alone and two at once, :func:`two_at_once`); ``efficiency_expected``: the two
  together, what the sweep can reach here.
* ``dask_over_local``: the same sweep on a Dask LocalCluster (2 worker processes, 1 thread each,
  started inside the timing) over the 2-worker local pool; target <= 1.2. The three sweeps run
  ``--rounds`` times (default 3), alternating, and the medians are compared (``runs_s``: each run).
  ``cpu_sweep_process_s``, ``cpu_workers_s``: median CPU seconds of the sweep's own process (first
  point, Dask scheduler, writing, figures) and of its worker processes (with the Dask nannies and
  the process drawing half of the figures); they move much less with the load than wall times.
* ``command_line``: the same three sweeps as whole commands, as a user runs them
  (``python -m clutchocp.cli sweep zhang2021 --grid ... --workers N``: interpreter start, imports,
  the sweep, figures and summary), alternating, medians: ``parallel_efficiency`` and
  ``dask_over_local`` of the wall times.
* ``runs_per_second_per_core``: points per second per worker of the 2-worker local sweep.
* ``reused_model_share_vm``, ``reused_model_share_native``: per engagement scene, the share of a
  point's time spent outside the IDAS calls in a sweep that reuses one model per worker (the
  default), on CasADi's virtual machine and as compiled C; target <= 0.15.
* ``outside_integrator_share``: the same for a new model per point (``--model-per-point``), and for
  a re-run of a built model with the scene's own values;
  again with 200 output times per run instead of the scene's (``..._200_output_points``);
  ``new_point_breakdown``: where a new point's time goes (profiled: model assembly, mode
  compilation, integrator construction, integrator calls, outputs and event checks, summary).
* ``optimize_map``: a default_driveline optimize map (``--map`` x ``--map`` points, load torque x
  oil viscosity) as a sweep does it by default (one collocation problem reused for every point,
  warm starts along the grid) against the same points solved cold, each on its own problem (25
  ordinary optimisations), on one process each; ``warm_over_cold`` of the wall time and of the
  IPOPT time; target <= 0.40. ``cold_reused_s``: the reused problem without warm starts (what
  reuse alone saves); ``max_objective_rel_diff``: the map's objectives against the cold ones.
The load of the machine (``os.getloadavg``) is recorded before and after each part.
"""

import argparse
import csv
import json
import os
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

from clutchocp.engagement.model import EngagementModel
from clutchocp.engagement.run import simulate_engagement
from clutchocp.scene import load_scene
from clutchocp.study import run_sweep
from clutchocp.study.executor import start_method
from clutchocp.study.tasks import clear_caches
from clutchocp.study.folder import RESULTS, TEXT_COLUMNS, parse_cell

TARGETS = {"parallel_efficiency": 0.85, "dask_over_local": 1.2, "outside_integrator_share": 0.15,
           "optimize_warm_over_cold": 0.40}


def load():
    return [round(v, 2) for v in os.getloadavg()]


def rows_of(folder):
    with (Path(folder) / RESULTS).open(newline="") as fh:
        return [{k: v if k in TEXT_COLUMNS else parse_cell(v) for k, v in r.items()} for r in csv.DictReader(fh)]


def cpu_s():
    """CPU seconds (user + system) of this process and of its finished child processes."""
    import resource

    return tuple(sum(getattr(resource.getrusage(who), a) for a in ("ru_utime", "ru_stime"))
                 for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN))


CPU = {}        # name of a timed sweep -> (CPU of this process, CPU of its workers) [s]


def timed_sweep(work, name, **kw):
    folder = Path(work) / name
    clear_caches()                       # this process's models from earlier sweeps: built again, timed
    cpu = cpu_s()
    start = time.perf_counter()
    summary = run_sweep(out_dir=folder, progress=False, **kw)
    wall = time.perf_counter() - start
    CPU[name] = tuple(b - a for a, b in zip(cpu, cpu_s()))
    if summary["points_ok"] != summary["points"]:
        raise RuntimeError(f"{name}: {summary['points_failed']} points failed: {summary['failures'][:2]}")
    return wall, summary, rows_of(folder)


def zhang_grid(points):
    n_viscosity = 10 if points >= 20 else 2
    n_pressure = max(1, points // n_viscosity)
    return [f"actuation.pressure=0.3 MPa:0.6 MPa:{n_pressure}", f"oil.viscosity=0.04:0.08:{n_viscosity}"]


def efficiency_bound(serial_s, parallel_s):
    """The parallel efficiency on 2 workers that a sweep process's CPU time ``serial_s`` (first point,
    rows, figures: nothing runs beside it) and its workers' CPU time ``parallel_s`` allow on an
    otherwise idle machine (Amdahl): T1 = S + P, T2 = S + P / 2, T1 / (2 T2)."""
    return (serial_s + parallel_s) / (2 * serial_s + parallel_s)


def _points_per_second(task, points):
    """Points per second of simulating ``points`` in this (forked) process."""
    from clutchocp.study.tasks import simulate_point

    start = time.perf_counter()
    for point in points:
        simulate_point(task, point)
    return len(points) / (time.perf_counter() - start)


def two_at_once(points, rounds=3):
    """How much of two cores' throughput two processes get on this machine: the same zhang2021 points
    (a reused model built here, the processes forked from this one, as a sweep's workers are) run
    alone, one half after the other, and the two halves at once; per round
    ``(rate of the two at once, summed) / (2 x rate alone)``. 1 on two independent cores; below 1
    where the two share what a core needs (caches, memory bandwidth, a host's scheduling)."""
    import multiprocessing

    from clutchocp.study.points import grid_points, parse_grid
    from clutchocp.study.tasks import Task, warm_up

    scene = load_scene("zhang2021")
    grid = grid_points([parse_grid(g, scene) for g in zhang_grid(points)])
    task = Task("zhang2021", "simulate")
    clear_caches()
    warm_up(task, [grid[:1]])
    halves = [(task, grid[1::2]), (task, grid[2::2])]
    context = multiprocessing.get_context("fork")
    out = []
    for _ in range(rounds):
        with context.Pool(1) as pool:
            alone = [pool.apply(_points_per_second, half) for half in halves]
        with context.Pool(2) as pool:
            both = pool.starmap(_points_per_second, halves)
        out.append(sum(both) / sum(alone))
    clear_caches()
    return {"rounds": [round(v, 4) for v in out], "median": statistics.median(out)}


def parallel(work, points, options=None, rounds=3):
    grid = zhang_grid(points)
    out = {"points": None, "rounds": rounds, "load_before": load()}
    # the compiled C of the sweep's model is built once per machine (disk cache): build it before timing
    warm = [f"{g.rsplit(':', 1)[0]}:2" for g in grid]
    out["native_first_build_s"] = timed_sweep(work, "warmup", scene="zhang2021", grid=warm, engine="serial")[0]
    runs = {"local1": dict(engine="local", workers=1), "local2": dict(engine="local", workers=2),
            "dask2": dict(engine="dask", workers=2)}
    wall, inner, cpu = {k: [] for k in runs}, {k: [] for k in runs}, {k: [] for k in runs}
    for r in range(rounds):                 # side by side, alternating: the load changes from minute to minute
        for name, kw in runs.items():
            t, s, _ = timed_sweep(work, f"{name}_{r}", scene="zhang2021", grid=grid, options=options, **kw)
            wall[name].append(t)
            inner[name].append(s["wall_time_s"])
            cpu[name].append(CPU[f"{name}_{r}"])
            out["points"] = s["points"]
    t1, t2, td = (statistics.median(wall[k]) for k in runs)
    s1, s2, sd = (statistics.median(inner[k]) for k in runs)
    out.update(local_1_worker_s=t1, local_2_workers_s=t2, dask_2_workers_s=td,
               runs_s={k: [round(v, 3) for v in wall[k]] for k in runs},
               cpu_sweep_process_s={k: statistics.median(c[0] for c in cpu[k]) for k in runs},
               cpu_workers_s={k: statistics.median(c[1] for c in cpu[k]) for k in runs},
               parallel_efficiency=t1 / (2 * t2), dask_over_local=td / t2,
               efficiency_bound_from_cpu=efficiency_bound(statistics.median(c[0] for c in cpu["local2"]),
                                                          statistics.median(c[1] for c in cpu["local2"])),
               parallel_efficiency_sweep_only=s1 / (2 * s2), dask_over_local_sweep_only=sd / s2,
               runs_per_second_per_core=out["points"] / t2 / 2)
    if start_method() == "fork":
        out["two_at_once"] = two_at_once(points)
        out["efficiency_expected"] = out["efficiency_bound_from_cpu"] * out["two_at_once"]["median"]
    out["load_after"] = load()
    return out


def command_line(work, points, rounds=3):
    """The same sweeps as whole commands (``python -m clutchocp.cli sweep``: interpreter start,
    imports, sweep, figures), alternating; medians."""
    import subprocess

    grid = [a for g in zhang_grid(points) for a in ("--grid", g)]
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[1]))
    runs = {"local1": ["--workers", "1"], "local2": ["--workers", "2"], "dask2": ["--engine", "dask", "--workers", "2"]}
    wall = {k: [] for k in runs}
    out = {"load_before": load()}
    for r in range(rounds):
        for name, extra in runs.items():
            cmd = [sys.executable, "-m", "clutchocp.cli", "sweep", "zhang2021", *grid, *extra, "--out",
                   str(Path(work) / f"cli_{name}_{r}")]
            start = time.perf_counter()
            subprocess.run(cmd, env=env, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            wall[name].append(time.perf_counter() - start)
    t1, t2, td = (statistics.median(wall[k]) for k in runs)
    out.update(local_1_worker_s=t1, local_2_workers_s=t2, dask_2_workers_s=td,
               runs_s={k: [round(v, 3) for v in wall[k]] for k in runs},
               parallel_efficiency=t1 / (2 * t2), dask_over_local=td / t2, load_after=load())
    return out


def reused_share(work, scene_name, native, points=8):
    """Share of a point's time outside the IDAS calls in a sweep that reuses one model (the default):
    a serial sweep of ``points`` viscosities around the scene's, median over all points but the first."""
    nominal = load_scene(scene_name).value("oil.viscosity")
    grid = [f"oil.viscosity={0.95 * nominal}:{1.05 * nominal}:{points}"]
    tag = f"{scene_name}_{'native' if native else 'vm'}"
    wall, summary, rows = timed_sweep(work, tag, scene=scene_name, grid=grid, engine="serial",
                                      options={"native": "auto" if native else False})
    rest = [r for r in rows[1:] if r["model_reused"]]
    run = statistics.median(r["run_time_s"] for r in rest)
    integ = statistics.median(r["integration_time_s"] for r in rest)
    return {"first_point_s": rows[0]["run_time_s"], "point_s": run, "integration_s": integ,
            "share": statistics.median(1 - r["integration_time_s"] / r["run_time_s"] for r in rest),
            "points_model_reused": summary["points_model_reused"], "native_used": summary["native_code"]["used"]}


def outside_share(scene_name, repeats=3, output_points=None):
    """Share of a point's time outside the IDAS calls: new model per point, and a re-run of one model
    (``output_points``: output grid of the runs, default the scene's)."""
    base = load_scene(scene_name)
    fresh, warm = [], []
    for k in range(repeats):
        scene = base.with_overrides({"oil.viscosity": base.value("oil.viscosity") * (1 + 0.01 * (k + 1))})
        start = time.perf_counter()
        model = EngagementModel(scene)
        built = time.perf_counter()
        run = simulate_engagement(scene, model=model, output_points=output_points)
        total = time.perf_counter() - start
        fresh.append((total, built - start, run.result.stats["integration_time_s"]))
        start = time.perf_counter()
        run = simulate_engagement(scene, model=model, output_points=output_points)
        warm.append((time.perf_counter() - start, run.result.stats["integration_time_s"]))
    total, build, integ = (statistics.median(v) for v in zip(*fresh))
    wtotal, winteg = (statistics.median(v) for v in zip(*warm))
    return {"new_point_s": total, "model_build_s": build, "integration_s": integ,
            "new_point_share": 1 - integ / total, "rerun_s": wtotal, "rerun_integration_s": winteg,
            "rerun_share": 1 - winteg / wtotal}


def _parts():
    """Where a new point's time goes: (label, function) of the profiled calls."""
    from clutchocp.engagement.run import summarize
    from clutchocp.simulation.compiled import ColumnFunction, CompiledMode
    from clutchocp.simulation.idas_path import IdasPath

    return (("model assembly", EngagementModel.__init__), ("mode compilation", CompiledMode.__init__),
            ("event-slope functions", CompiledMode.event_slopes), ("integrator construction", IdasPath._integrator),
            ("integrator calls", IdasPath._run), ("outputs and event checks on the grid", ColumnFunction.__call__),
            ("summary", summarize))


def breakdown(scene_name):
    """Seconds of each part of one new point (cProfile, cumulative time of each function; the
    profiler itself slows the run, ``total_s``, by tens of per cent)."""
    import cProfile
    import pstats

    base = load_scene(scene_name)
    simulate_engagement(base)                          # imports and first-use caches outside the profile
    scene = base.with_overrides({"oil.viscosity": base.value("oil.viscosity") * 1.037})
    profile = cProfile.Profile()
    start = time.perf_counter()
    profile.enable()
    simulate_engagement(scene)
    profile.disable()
    total = time.perf_counter() - start
    stats = pstats.Stats(profile).stats
    out = {"total_s": total}
    for label, function in _parts():
        code = function.__code__
        out[label] = sum(v[3] for key, v in stats.items() if key == (code.co_filename, code.co_firstlineno, code.co_name))
    return out


def optimize_map(work, n):
    grid = [f"load.torque=80:120:{n}", f"oil.viscosity=0.05:0.09:{n}"]
    common = dict(scene="default_driveline", task="optimize", grid=grid, engine="serial")
    out = {"points": n * n, "load_before": load()}
    tw, sw, warm = timed_sweep(work, "warm", options={"intervals": 40, "verify": False}, **common)
    tc, sc, cold = timed_sweep(work, "cold", options={"intervals": 40, "verify": False, "warm_start": False,
                                                      "reuse_problem": False}, **common)
    tr, sr, cold_reused = timed_sweep(work, "cold_reused", options={"intervals": 40, "verify": False,
                                                                    "warm_start": False}, **common)
    ipopt_w, ipopt_c = sum(r["solve_time_s"] for r in warm), sum(r["solve_time_s"] for r in cold)
    by_id = {r["point_id"]: r for r in cold}

    def diff(rows):
        return max(abs(r["objective"] - by_id[r["point_id"]]["objective"]) / abs(by_id[r["point_id"]]["objective"])
                   for r in rows)

    out.update(warm_s=tw, cold_s=tc, warm_over_cold=tw / tc, ipopt_warm_s=ipopt_w, ipopt_cold_s=ipopt_c,
               ipopt_warm_over_cold=ipopt_w / ipopt_c, cold_reused_s=tr, cold_reused_over_cold=tr / tc,
               iterations_warm=sum(r["ipopt_iterations"] for r in warm),
               iterations_cold=sum(r["ipopt_iterations"] for r in cold),
               build_warm_s=sum(r["build_time_s"] for r in warm), build_cold_s=sum(r["build_time_s"] for r in cold),
               points_problem_reused=sum(r["problem_reused"] is True for r in warm),
               max_objective_rel_diff=diff(warm), max_objective_rel_diff_cold_reused=diff(cold_reused),
               load_after=load())
    return out


def target_lines(result):
    """One line per target: the figure measured, the target, met or not."""
    lines = []
    checks = (("parallel", "parallel_efficiency", ">=", TARGETS["parallel_efficiency"],
               "parallel efficiency, 2 local workers"),
              ("parallel", "dask_over_local", "<=", TARGETS["dask_over_local"], "Dask LocalCluster / local pool"),
              ("command_line", "parallel_efficiency", ">=", TARGETS["parallel_efficiency"],
               "whole command: parallel efficiency, 2 local workers"),
              ("command_line", "dask_over_local", "<=", TARGETS["dask_over_local"],
               "whole command: Dask LocalCluster / local pool"),
              ("optimize_map", "warm_over_cold", "<=", TARGETS["optimize_warm_over_cold"],
               "optimize map, warm / cold"))
    for part, key, sense, target, label in checks:
        if part in result:
            value = result[part][key]
            met = value >= target if sense == ">=" else value <= target
            lines.append(f"{label}: {value:.3f} (target {sense} {target}; {'met' if met else 'NOT met'}; "
                         f"load {result[part]['load_before']} -> {result[part]['load_after']})")
    if "parallel" in result:
        lines.append(f"parallel efficiency the serial CPU allows (Amdahl): "
                     f"{result['parallel']['efficiency_bound_from_cpu']:.3f}")
        if "two_at_once" in result["parallel"]:
            lines.append(f"two processes at once get {result['parallel']['two_at_once']['median']:.3f} of two cores' "
                         f"throughput on this machine; with the Amdahl bound: "
                         f"{result['parallel']['efficiency_expected']:.3f}")
        lines.append(f"runs per second per core: {result['parallel']['runs_per_second_per_core']:.1f}")
    for scene, share in result.get("reused_model_share_native", {}).items():
        lines.append(f"share outside the integrator, {scene}, reused model, native: {share['share']:.2f} "
                     f"(target <= {TARGETS['outside_integrator_share']})")
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", default="out/bench_sweep")
    parser.add_argument("--points", type=int, default=200, help="zhang2021 sweep points (default 200)")
    parser.add_argument("--map", type=int, default=5, help="optimize map size n (n x n points, default 5)")
    parser.add_argument("--model-per-point", action="store_true",
                        help="parallel part: a new model at every point (heavier points) instead of the default")
    parser.add_argument("--skip", default="", help="comma-separated parts to skip: parallel, cli, share, optimize")
    parser.add_argument("--rounds", type=int, default=3,
                        help="alternating rounds of the timed 200-point sweeps (medians; default 3)")
    args = parser.parse_args(argv)
    skip = set(filter(None, args.skip.split(",")))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    work = Path(tempfile.mkdtemp(prefix="bench_sweep_"))
    result = {"cores": os.cpu_count(), "targets": TARGETS}
    try:
        if "parallel" not in skip:
            result["parallel"] = parallel(work, args.points, {"reuse_model": False} if args.model_per_point else None,
                                          rounds=args.rounds)
            print(json.dumps(result["parallel"], indent=1), file=sys.stderr)
        if "cli" not in skip:
            result["command_line"] = command_line(work, args.points, rounds=args.rounds)
            print(json.dumps(result["command_line"], indent=1), file=sys.stderr)
        if "share" not in skip:
            scenes = ("zhang2021", "bao2020", "default_driveline")
            result["outside_integrator_share"] = {s: outside_share(s) for s in scenes}
            result["outside_integrator_share_200_output_points"] = {s: outside_share(s, output_points=200)
                                                                   for s in scenes}
            result["reused_model_share_vm"] = {s: reused_share(work, s, native=False) for s in scenes}
            result["reused_model_share_native"] = {s: reused_share(work, s, native=True) for s in scenes}
            print(json.dumps({k: result[k] for k in ("reused_model_share_vm", "reused_model_share_native")},
                             indent=1), file=sys.stderr)
            result["new_point_breakdown"] = {s: breakdown(s) for s in scenes}
            print(json.dumps(result["new_point_breakdown"], indent=1), file=sys.stderr)
        if "optimize" not in skip:
            result["optimize_map"] = optimize_map(work, args.map)
            print(json.dumps(result["optimize_map"], indent=1), file=sys.stderr)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    (out / "bench_sweep.json").write_text(json.dumps(result, indent=2) + "\n")
    print(json.dumps(result, indent=2))
    print("\n".join(target_lines(result)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
