"""Solve time of the default optimal-engagement problem against the mesh, cold and warm.

For N = 50, 100, 200 intervals (degree 3, Radau) it reports

* build: the collocation NLP and its derivative functions (both stages) [s];
* cold: IPOPT from the IDAS run of the scene's own profile (smooth solve + exact polish) [s, iterations];
* warm: from the optimum, the same problem and a t_max 2 % tighter (one step of a sweep) [s, iterations];
* the objective and jerk-integral error against a fine-mesh reference (N = 400).

Timings are the median of ``--repeat`` solves. Run from the repository root:

    python benchmarks/bench_optimize.py [--intervals 50 100 200] [--reference 400] [--repeat 3]
        [--degree 3] [--scheme radau] [--control constant] [--json FILE]

With ``--scenes NAME ...`` it instead times the optimum of each engagement scene (default weights and
t_max, the first of ``--intervals``): cold (from the IDAS run of the scene's own profile) and warm
(from that optimum: the same problem, and a t_max 2 % tighter), with the IDAS verification of the
cold optimum. Scenes without a pressure limit get the one in ``SCENE_OVERRIDES``.
"""

import argparse
import json
import statistics
import time

from clutchocp.engagement.run import simulate_engagement
from clutchocp.optimal import EngagementOCP, verify
from clutchocp.scene import default_scene, load_scene

# Values the seed scenes do not give, as a user sets them with optimize --set.
SCENE_OVERRIDES = {"zhang2021": {"actuation.max_pressure": "1.2 MPa"},
                   "bao2020": {"actuation.max_pressure": "80 MPa", "actuation.initial_pressure": "63.66 MPa"}}


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
    parser.add_argument("--scenes", nargs="+", help="time each scene's optimum instead (cold and warm)")
    args = parser.parse_args()
    if args.scenes:
        bench_scenes(args.scenes, args.intervals[0], args.repeat, args.json)
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
    for name in names:
        scene = load_scene(name, overrides=SCENE_OVERRIDES.get(name))
        start = time.perf_counter()
        ocp = EngagementOCP(scene, intervals=intervals)
        ocp.solver(), ocp.solver(warm=True), ocp.exact.solver(warm=True)
        build = time.perf_counter() - start
        t_max = ocp.default_t_max()
        cold_time, cold = timed_solve(ocp, repeat, t_max=t_max)
        warm_time, warm = timed_solve(ocp, repeat, t_max=t_max, guess=cold)
        step_time, step = timed_solve(ocp, repeat, t_max=0.98 * t_max, guess=cold)
        check, _ = verify(ocp.exact, cold)
        rows.append({"scene": name, "phases": [p["name"] for p in cold.phases], "intervals": intervals,
                     "n_variables": cold.stats["n_variables"], "build_s": build,
                     "cold_s": cold_time, "cold_iterations": cold.stats["iterations"],
                     "warm_same_s": warm_time, "warm_same_iterations": warm.stats["iterations"],
                     "warm_step_s": step_time, "warm_step_iterations": step.stats["iterations"],
                     "engagement_time_s": cold.t_f, "idas_lock_rel_diff": check["lock_time_rel_diff"],
                     "idas_jump_rel": check["torque_jump_rel"], "idas_passed": check["passed"]})
        print(f"{name}: cold {cold_time:.3f} s, warm same {warm_time:.3f} s, warm t_max-2% {step_time:.3f} s",
              flush=True)
    print(f"\n{'scene':>18} {'phases':>10} {'vars':>6} {'build s':>8} {'cold s':>7} {'it':>4} {'warm s':>7} {'it':>3} "
          f"{'step s':>7} {'it':>3} {'t_f s':>7} {'IDAS lock':>9} {'IDAS jump':>9}")
    for r in rows:
        print(f"{r['scene']:>18} {'+'.join(r['phases']):>10} {r['n_variables']:>6} {r['build_s']:>8.2f} "
              f"{r['cold_s']:>7.3f} {r['cold_iterations']:>4} {r['warm_same_s']:>7.3f} {r['warm_same_iterations']:>3} "
              f"{r['warm_step_s']:>7.3f} {r['warm_step_iterations']:>3} {r['engagement_time_s']:>7.4f} "
              f"{r['idas_lock_rel_diff']:>9.2e} {r['idas_jump_rel']:>9.2e}")
    if json_path:
        with open(json_path, "w", encoding="utf-8") as fh:
            json.dump(rows, fh, indent=2)


if __name__ == "__main__":
    main()
