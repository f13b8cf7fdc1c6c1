"""Work-precision benchmark of the engagement simulation: IDAS against scipy Radau, BDF and LSODA.

Every method integrates the same CasADi-generated equations (the scipy methods through
``simulate_engagement(..., method=...)``: the reduced ODE with the exact CasADi Jacobian;
"idas-native" is IDAS with the equations compiled to machine code, ``native=True``). For each
scene a tight IDAS run (rtol 1e-11) is the reference; each method sweeps its tolerance, and its
error is the largest of

* the relative error of the lock-up time, and
* the largest error of the input and output speeds on the output grid, relative to the largest speed.

Each method's (error, wall time) points are interpolated in log-log to common error levels
("matched error"), and the wall-time ratios to IDAS are reported there (with the CPU-time ratios,
which other processes on the machine disturb less). Wall times are the whole
``simulate_engagement`` call (integration, events, outputs, summary) with the model built and
compiled beforehand; each (scene, method) gets one untimed warm-up run, then the best of
``--repeats`` runs counts (IDAS runs are short and noisy: 3x as many). The single-run target
(one bao2020 engagement at the scene's own tolerance) is reported warm and cold (a fresh model:
assembly, compilation and the run).

Usage::

    python benchmarks/bench_engagement.py [--out DIR] [--scenes bao2020 zhang2021] [--repeats 3]

Writes ``engagement_work_precision.csv`` and ``engagement_work_precision.png`` into DIR.
"""

import argparse
import itertools
import math
import sys
import time
from pathlib import Path

import numpy as np

from clutchocp.engagement.model import EngagementModel
from clutchocp.engagement.run import simulate_engagement
from clutchocp.errors import SolverError
from clutchocp.output import new_figure, save_figure, write_csv
from clutchocp.scene.loader import load_scene

METHODS = ("idas", "idas-native", "Radau", "BDF", "LSODA")   # idas-native: SimulationOptions(native=True)
SCIPY = ("Radau", "BDF", "LSODA")
TOLERANCES = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)
REFERENCE_RTOL = 1e-11
ERROR_LEVELS = (1e-5, 1e-6, 1e-7)
TARGETS = {"Radau": 20.0, "LSODA": 5.0}          # issue 3: IDAS >= 20x Radau, >= 5x LSODA
SINGLE_RUN_TARGET_S = 0.020


def grid_values(run, name):
    """Values of ``name`` on the output grid (the samples that repeat a time at an event dropped)."""
    scene = run.model.scene
    grid = np.linspace(0.0, scene.value("simulation.t_end"), scene.value("simulation.output_points"))
    t, values = run.result.t, run.result[name]
    return values[[np.flatnonzero(t == g)[-1] for g in grid]]


def error_against(run, reference):
    """Largest relative error of the lock time and of the speeds on the output grid."""
    t_ref, t_run = reference.summary["engagement_time_s"], run.summary["engagement_time_s"]
    if t_run is None:
        return math.inf
    errors = [abs(t_run - t_ref) / t_ref]
    for speed in ("w_in_rad_s", "w_out_rad_s"):
        ref = grid_values(reference, speed)
        scale = np.max(np.abs(ref))
        if scale > 0:
            errors.append(np.max(np.abs(grid_values(run, speed) - ref)) / scale)
    return float(max(errors))


def timed(scene, model, method, rtol, repeats):
    """Best wall time and best CPU time of ``repeats`` runs [s], and the last run."""
    best_wall, best_cpu, run = math.inf, math.inf, None
    native = method == "idas-native"
    for _ in range(repeats):
        wall, cpu = time.perf_counter(), time.process_time()
        run = simulate_engagement(scene, model=model, method="idas" if native else method, rtol=rtol,
                                  atol=rtol * 1e-2, native=native)
        best_wall = min(best_wall, time.perf_counter() - wall)
        best_cpu = min(best_cpu, time.process_time() - cpu)
    return best_wall, best_cpu, run


def time_at_error(points, level):
    """Wall time at error ``level`` by log-log interpolation of (error, time) points; None outside."""
    pts = sorted((e, w) for e, w in points if math.isfinite(e) and e > 0)
    for (e0, w0), (e1, w1) in itertools.pairwise(pts):
        if e0 <= level <= e1:
            if e1 == e0:
                return min(w0, w1)
            s = (math.log(level) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(w0) + s * (math.log(w1) - math.log(w0)))
    return None


def _ms(seconds):
    return f"{seconds * 1e3:7.2f} ms" if seconds is not None else "      -"


class Progress:
    """One line per run: counter, elapsed time, what ran and what it gave."""

    def __init__(self, total):
        self.total, self.done, self.start = total, 0, time.perf_counter()

    def step(self, text):
        self.done += 1
        elapsed = time.perf_counter() - self.start
        bar = "#" * round(20 * self.done / self.total)
        print(f"[{bar:<20}] {self.done:3d}/{self.total} {elapsed:6.1f} s  {text}", flush=True)


def single_run(method, repeats=20):
    """Warm and cold wall time of one bao2020 engagement at the scene's tolerance [s]."""
    scene = load_scene("bao2020")
    start = time.perf_counter()
    model = EngagementModel(scene)
    run = simulate_engagement(scene, model=model, native=method == "idas-native")
    cold = time.perf_counter() - start
    warm, warm_cpu, _ = timed(scene, model, method, scene.value("simulation.rtol"), repeats)
    return warm, warm_cpu, cold, run.summary["solver"]["statistics"]["n_steps"]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="bench_engagement_out", help="output directory")
    parser.add_argument("--scenes", nargs="+", default=["bao2020", "zhang2021"])
    parser.add_argument("--repeats", type=int, default=3, help="timed runs per point (the best counts)")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    progress = Progress(len(args.scenes) * (1 + len(METHODS) * (1 + len(TOLERANCES))) + 2)
    rows, points, cpu_points = [], {}, {}
    for name in args.scenes:
        scene = load_scene(name)
        model = EngagementModel(scene)
        reference = simulate_engagement(scene, model=model, rtol=REFERENCE_RTOL, atol=REFERENCE_RTOL * 1e-2)
        progress.step(f"{name}: reference IDAS rtol {REFERENCE_RTOL:g}, lock {reference.summary['engagement_time_s']:.9f} s")
        for method in METHODS:
            timed(scene, model, method, TOLERANCES[0], 1)                        # warm-up: builds, caches
            progress.step(f"{name} {method}: warm-up")
            for rtol in TOLERANCES:
                row = {"scene": name, "method": method, "rtol": rtol, "atol": rtol * 1e-2}
                start = time.perf_counter()
                try:
                    repeats = args.repeats * (3 if method.startswith("idas") else 1)
                    wall, cpu, run = timed(scene, model, method, rtol, repeats)
                except SolverError as err:          # e.g. scipy BDF's step size collapsing at the impact
                    row.update(wall_time_s=time.perf_counter() - start, cpu_time_s="failed", error_rel="failed",
                               engagement_time_s="failed",
                               n_rhs_evals=0, n_steps=0)
                    rows.append(row)
                    progress.step(f"{name} {method:5s} rtol {rtol:.0e}: FAILED ({str(err)[:90]}...)")
                    continue
                error = error_against(run, reference)
                stats = run.summary["solver"]["statistics"]
                row.update(wall_time_s=wall, cpu_time_s=cpu, error_rel=error, engagement_time_s=run.summary["engagement_time_s"],
                           n_rhs_evals=stats.get("n_rhs_evals", 0), n_steps=stats.get("n_steps", 0))
                rows.append(row)
                points.setdefault((name, method), []).append((error, wall))
                cpu_points.setdefault((name, method), []).append((error, cpu))
                progress.step(f"{name} {method:5s} rtol {rtol:.0e}: {wall * 1e3:8.1f} ms, error {error:.2e}")

    single = {}
    for method in ("idas", "idas-native"):
        single[method] = single_run(method)
        progress.step(f"single bao2020 run, {method}")

    csv_path = write_csv(out / "engagement_work_precision.csv", {
        "scene": [r["scene"] for r in rows], "method": [r["method"] for r in rows],
        "rtol": [r["rtol"] for r in rows], "atol": [r["atol"] for r in rows],
        "wall_time_s": [r["wall_time_s"] for r in rows], "cpu_time_s": [r["cpu_time_s"] for r in rows],
        "error_rel": [r["error_rel"] for r in rows],
        "engagement_time_s": [r["engagement_time_s"] for r in rows],
        "n_rhs_evals": [r["n_rhs_evals"] for r in rows], "n_steps": [r["n_steps"] for r in rows]})

    fig, axes = new_figure(len(args.scenes), width=5.5, height=4.2)
    for ax, name in zip(axes, args.scenes):
        for method in METHODS:
            e, w = zip(*sorted(points[(name, method)]))
            ax.loglog(e, np.array(w) * 1e3, "o-", label=method)
        for level in ERROR_LEVELS:
            ax.axvline(level, color="0.8", lw=0.8, zorder=0)
        ax.set(xlabel="error (lock time, speeds) [relative]", ylabel="wall time [ms]",
               title=f"{name}: work-precision")
        ax.legend(fontsize=8)
    png_path = save_figure(fig, out / "engagement_work_precision.png")

    print("\nWall time ratio to IDAS at matched error (log-log interpolation of each sweep; '-': level "
          "outside that method's sweep):")
    failed = []
    for name in args.scenes:
        for level in ERROR_LEVELS:
            idas = time_at_error(points[(name, "idas")], level)
            native = time_at_error(points[(name, "idas-native")], level)
            cells = []
            idas_cpu = time_at_error(cpu_points[(name, "idas")], level)
            for method in SCIPY:
                other = time_at_error(points[(name, method)], level)
                other_cpu = time_at_error(cpu_points[(name, method)], level)
                if idas is None or other is None:
                    cells.append(f"{method} -")
                    continue
                ratio = other / idas
                cells.append(f"{method} {ratio:5.1f}x (cpu {other_cpu / idas_cpu:5.1f}x)")
                if method in TARGETS and level == 1e-6 and ratio < TARGETS[method]:
                    failed.append(f"{name} {method} {ratio:.1f}x < {TARGETS[method]:g}x at 1e-6")
            print(f"  {name:10s} error {level:.0e}: IDAS {_ms(idas)} (native {_ms(native)}) | " + " | ".join(cells))
    print()
    for method, (warm, warm_cpu, cold, steps) in single.items():
        print(f"One bao2020 engagement at rtol 1e-8 (scene tolerance), {method}: warm {warm * 1e3:.1f} ms wall, "
              f"{warm_cpu * 1e3:.1f} ms CPU (target {SINGLE_RUN_TARGET_S * 1e3:.0f} ms); cold {cold * 1e3:.0f} ms "
              f"(model assembly, compilation, first run); {steps} IDAS steps")
    if single["idas"][0] > SINGLE_RUN_TARGET_S:
        failed.append(f"single bao2020 run {single['idas'][0] * 1e3:.1f} ms > {SINGLE_RUN_TARGET_S * 1e3:.0f} ms")
    print(f"\nwrote {csv_path} and {png_path}")
    if failed:
        print("targets missed: " + "; ".join(failed))
    return 0


if __name__ == "__main__":
    sys.exit(main())
