"""Solve time of the default optimal-engagement problem against the mesh, cold and warm.

For N = 50, 100, 200 intervals (degree 3, Radau) it reports

* build: the collocation NLP and its derivative functions (both stages) [s];
* cold: IPOPT from the IDAS run of the scene's own profile (smooth solve + exact polish) [s, iterations];
* warm: from the optimum, the same problem and a t_max 2 % tighter (one step of a sweep) [s, iterations];
* the objective and jerk-integral error against a fine-mesh reference (N = 400).

Timings are the median of ``--repeat`` solves. Run from the repository root:

    python benchmarks/bench_optimize.py [--intervals 50 100 200] [--reference 400] [--repeat 3]
        [--degree 3] [--scheme radau] [--control constant] [--json FILE]

With ``--scenes [NAME ...]`` it instead times the optimum of each engagement scene (all of models/ when
no name is given; default weights and t_max, the first of ``--intervals``) as ``clutchocp optimize``
solves it (:func:`clutchocp.optimal.mesh.solve_verified`: solve, verify with IDAS, grade the mesh and
solve again while the replay misses its tolerances):

* cold: from the IDAS run of the scene's own profile, all solves summed (a phased problem's coarse
  start, the solve, the graded-mesh solves) [s, iterations];
* warm, same scene: from that optimum, on its final mesh;
* warm, changed scene: input speed - 2 %, from the optimum of the unchanged scene (same mesh, with
  its multipliers), as one step of a sweep;
* the IDAS verification of the cold optimum: lock-up time difference and |jump| share, passed or not.

Timings are IPOPT wall times as measured around the solver calls, the median of ``--repeat`` for the
warm solves (the cold one runs once per scene: it includes the refinement).
"""

import argparse
import json
import statistics
import time

import os

from clutchocp.engagement.run import simulate_engagement
from clutchocp.optimal import EngagementOCP
from clutchocp.optimal.mesh import solve_verified
from clutchocp.scene import default_scene, list_scenes, load_scene

SPEED_STEP = 0.98               # the "slightly changed scene" of the warm start: input speed - 2 %


def timed_solve(ocp, repeat, **kwargs):
    """Median wall time of IPOPT (as measured around the solver calls) and the last result."""
    results = [ocp.solve(**kwargs) for _ in range(repeat)]
    return statistics.median(r.stats["wall_time_s"] for r in results), results[-1]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--intervals", type=int, nargs="+", default=[50, 100, 200])
    parser.add_argument("--degree", type=int, default=3)
    parser.add_argument("--scheme", choices=("radau", "legendre"), default="radau")
    parser.add_argument("--control", choices=("linear", "constant"), default="linear")
    parser.add_argument("--reference", type=int, default=400, help="intervals of the fine-mesh reference")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--json", help="also write the table to this JSON file")
    parser.add_argument("--scenes", nargs="*", help="time each scene's optimum instead (cold and warm); "
                        "no name: every engagement scene in models/")
    args = parser.parse_args()
    if args.scenes is not None:
        names = args.scenes or sorted(sc.name for sc in list_scenes() if sc.kind == "engagement")
        bench_scenes(names, args.intervals[0], args.repeat, args.json)
        return

    scene = default_scene()
    baseline = simulate_engagement(scene)
    t_max = baseline.summary["engagement_time_s"]
    rows = []
    for n in args.intervals:
        start = time.perf_counter()
        ocp = EngagementOCP(scene, intervals=n, degree=args.degree, scheme=args.scheme, control=args.control,
                            baseline=baseline)
        ocp.solver(), ocp.solver(warm=True), ocp.exact.solver(warm=True)
        build = time.perf_counter() - start
        cold_time, cold = timed_solve(ocp, args.repeat, t_max=t_max)
        warm_time, warm = timed_solve(ocp, args.repeat, t_max=t_max, guess=cold)
        step_time, step = timed_solve(ocp, args.repeat, t_max=0.98 * t_max, guess=cold)
        rows.append({"intervals": n, "degree": args.degree, "scheme": args.scheme, "control": args.control,
                     "n_variables": cold.stats["n_variables"],
                     "build_s": build, "cold_s": cold_time, "cold_iterations": cold.stats["iterations"],
                     "warm_same_s": warm_time, "warm_same_iterations": warm.stats["iterations"],
                     "warm_step_s": step_time, "warm_step_iterations": step.stats["iterations"],
                     "objective": cold.objective, "jerk_integral": cold.terms["jerk_integral"], "result": cold})
        print(f"N = {n}: cold {cold_time:.3f} s ({cold.stats['iterations']} it), warm same {warm_time:.3f} s, "
              f"warm t_max-2% {step_time:.3f} s", flush=True)

    finest = max(rows, key=lambda r: r["intervals"])["result"]
    ref = EngagementOCP(scene, intervals=args.reference, degree=args.degree, scheme=args.scheme,
                        control=args.control, baseline=baseline).solve(
        t_max=t_max, guess=finest)
    print(f"\nreference N = {args.reference}: objective {ref.objective:.10g}, jerk integral "
          f"{ref.terms['jerk_integral']:.10g} rad^2/s^5 ({ref.stats['iterations']} iterations)\n")
    header = (f"{'N':>5} {'vars':>6} {'build s':>8} {'cold s':>7} {'it':>4} {'warm s':>7} {'it':>3} "
              f"{'step s':>7} {'it':>3} {'obj rel err':>12} {'jerk rel err':>12}")
    print(header)
    for r in rows:
        r["objective_rel_error"] = abs(r["objective"] - ref.objective) / abs(ref.objective)
        r["jerk_integral_rel_error"] = abs(r["jerk_integral"] - ref.terms["jerk_integral"]) / ref.terms["jerk_integral"]
        print(f"{r['intervals']:>5} {r['n_variables']:>6} {r['build_s']:>8.2f} {r['cold_s']:>7.3f} "
              f"{r['cold_iterations']:>4} {r['warm_same_s']:>7.3f} {r['warm_same_iterations']:>3} "
              f"{r['warm_step_s']:>7.3f} {r['warm_step_iterations']:>3} {r['objective_rel_error']:>12.3e} "
              f"{r['jerk_integral_rel_error']:>12.3e}")
    if args.json:
        with open(args.json, "w", encoding="utf-8") as fh:
            json.dump({"reference_intervals": args.reference, "reference_objective": ref.objective,
                       "rows": [{k: v for k, v in r.items() if k != "result"} for r in rows]}, fh, indent=2)


def bench_scenes(names, intervals, repeat, json_path=None):
    """Cold and warm solve time of each scene's optimum, with its IDAS check."""
    rows = []
    print(f"load average before: {' '.join(f'{v:.2f}' for v in os.getloadavg())}", flush=True)
    for name in names:
        scene = load_scene(name)
        start = time.perf_counter()
        ocp = EngagementOCP(scene, intervals=intervals)
        ocp.solver(), ocp.exact.solver()
        build = time.perf_counter() - start
        solved = solve_verified(ocp)
        ocp, cold, check = solved["ocp"], solved["optimum"], solved["check"]
        history = solved["history"]
        ocp.solver(warm=True), ocp.exact.solver(warm=True)
        warm_time, warm = timed_solve(ocp, repeat, t_max=cold.t_max, guess=cold)
        meshes = {ph: part.transcription.mesh for (ph, _), part in zip(ocp.phase_modes, ocp.phased.parts)
                  if not part.transcription.uniform}
        changed = EngagementOCP(scene.with_overrides({"driveline.input_speed": SPEED_STEP
                                                      * scene.value("driveline.input_speed")}),
                                intervals=intervals, meshes=meshes)
        changed.solver(warm=True), changed.exact.solver(warm=True)
        step_time, step = timed_solve(changed, repeat, t_max=cold.t_max, guess=cold)
        rows.append({"scene": name, "phases": [p["name"] for p in cold.phases], "intervals": intervals,
                     "n_variables": cold.stats["n_variables"], "build_s": build, "solves": len(history),
                     "cold_s": sum(h.get("wall_time_s", 0.0) for h in history),
                     "cold_iterations": sum(h.get("iterations", 0) for h in history),
                     "warm_same_s": warm_time, "warm_same_iterations": warm.stats["iterations"],
                     "warm_same_warm_start": warm.stats["warm_start"],
                     "warm_speed_s": step_time, "warm_speed_iterations": step.stats["iterations"],
                     "warm_speed_warm_start": step.stats["warm_start"],
                     "engagement_time_s": cold.t_f, "t_max_s": cold.t_max,
                     "stages": [h["stage"] for h in history],
                     "first_check": next({"lock_rel_diff": h["lock_time_rel_diff"], "jump_rel": h["torque_jump_rel"]}
                                         for h in history if h["stage"] == "solve"),
                     "idas_lock_rel_diff": check["lock_time_rel_diff"],
                     "idas_jump_rel": check["torque_jump_rel"], "idas_passed": check["passed"]})
        print(f"{name}: {len(history)} solve(s), cold {rows[-1]['cold_s']:.3f} s, warm same {warm_time:.3f} s, "
              f"warm input speed -2 % {step_time:.3f} s; load {os.getloadavg()[0]:.2f}", flush=True)
    print(f"\n{'scene':>26} {'phases':>10} {'vars':>6} {'build s':>8} {'solves':>6} {'cold s':>7} {'it':>4} "
          f"{'warm s':>7} {'it':>3} {'speed s':>7} {'it':>3} {'t_f s':>7} {'lock diff':>9} {'|jump|':>8} {'ok':>3}")
    for r in rows:
        print(f"{r['scene']:>26} {'+'.join(r['phases']):>10} {r['n_variables']:>6} {r['build_s']:>8.2f} "
              f"{r['solves']:>6} {r['cold_s']:>7.2f} {r['cold_iterations']:>4} {r['warm_same_s']:>7.2f} "
              f"{r['warm_same_iterations']:>3} {r['warm_speed_s']:>7.2f} {r['warm_speed_iterations']:>3} "
              f"{r['engagement_time_s']:>7.4f} {_pct(r['idas_lock_rel_diff']):>9} {_pct(r['idas_jump_rel']):>8} "
              f"{'yes' if r['idas_passed'] else 'no':>3}")
    print(f"load average after: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")
    if json_path:
        with open(json_path, "w", encoding="utf-8") as fh:
            json.dump(rows, fh, indent=2)


def _pct(value):
    return "-" if value is None else f"{100 * value:.3g} %"


if __name__ == "__main__":
    main()
