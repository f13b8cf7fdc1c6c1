"""Robust feedforward: solve time against the number of scenarios, and the corner replay.

The uncertainty box the default scene declares ([uncertainty]: friction.mu +-10 %, oil.viscosity
+-30 %, load.torque +-20 %, uniform), as ``scene.uncertainty`` gives it. Scenario sets: 1 = the
centre; 3 = centre and the two extreme corners (all low, all high); 5 = centre and four corners
that differ pairwise in two fields; 9 = the 8 corners and the centre.

Timing (``--scenarios``): for each set, the build (scenario scenes, their baseline and fastest
IDAS runs, the parametric model) and the solve (coarse presolve, re-solves that move lock-ups
between command intervals, exact polish) [s], with IPOPT iterations.

Acceptance (``--acceptance 9``): the robust command of a scenario set, the nominal optimum and the scene's
own baseline profile, each replayed with IDAS at the 8 corners and the centre: lock-up time and
torque jump at lock-up per corner; figures corner_jumps.png and commands.png in ``--out``.

Monte Carlo (``--montecarlo SAMPLES``): the robust command of the 9 box points (continued by the
clamp ramp, as ``clutchocp robust`` runs it) and the scene's own profile, open loop with IDAS, on the
seeded draws of ``clutchocp robust`` in ``--workers`` processes: share of samples locked within t_max,
|jump| as % of the locked torque (median, p95, worst), the robust worst over the baseline worst, and
samples per second (both strategies per sample).

Defaults are the settings of ``clutchocp robust`` (``ROBUST_*`` in clutchocp/shiftcontrol/workflow.py).
Run from the repository root:

    python benchmarks/bench_robust.py [--scenarios 1 3 5 9] [--intervals 12] [--presolve 0] [--jump-weight 1000]
        [--jerk-weight 0.1] [--smooth-weight 0.01] [--aggregate mean|worst|worst_jump] [--no-diagonal]
        [--t-max-margin 0.02] [--montecarlo 200 --seed 0 --workers 2] [--acceptance SCENARIOS] [--out DIR]
        [--json FILE]

The worst-jump feedforward of the README: ``--scenarios 9 --diagonal --aggregate worst_jump --jump-weight 1000
--jerk-weight 0.1 --smooth-weight 0.01 --t-max-margin 0.02`` (``--diagonal`` adds the two lock_diagonal points).
"""

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from clutchocp.engagement.run import simulate_engagement
from clutchocp.errors import ClutchocpError
from clutchocp.optimal import EngagementOCP
from clutchocp.optimal.robust import AGGREGATES, PRESOLVE_INTERVALS, RobustOCP, lock_diagonal
from clutchocp.optimal.replay import CommandModel, simulate_command
from clutchocp.output import new_figure, save_figure
from clutchocp.scene import default_scene
from clutchocp.shiftcontrol.workflow import ROBUST_AGGREGATE, ROBUST_INTERVALS, ROBUST_T_MAX_MARGIN, ROBUST_WEIGHTS

def box_points(scene):
    """(corners, centre) of the scene's uncertainty box as override dicts [SI]."""
    box = scene.uncertainty
    if not box.names:
        sys.exit(f"scene '{scene.name}' declares no [uncertainty]")
    return box.corners(), box.centre()


def scenario_set(scene, count, diagonal=False):
    """The box points of a set (1, 3, 5, 9), with ``diagonal`` the lock_diagonal points of the box added."""
    corners, centre = box_points(scene)
    sets = {1: [centre], 3: [corners[0], centre, corners[-1]],
            5: [centre, corners[0], corners[3], corners[5], corners[6]], 9: corners + [centre]}
    if count not in sets:
        sys.exit(f"--scenarios: choose from {sorted(sets)}")
    return sets[count] + (lock_diagonal(scene, corners) if diagonal else [])


def solve(scene, scenarios, intervals, weights, t_max_margin=0.0, aggregate="mean", presolve=PRESOLVE_INTERVALS):
    start = time.perf_counter()
    problem = RobustOCP(scene, scenarios, intervals=intervals, jump="penalty")
    problem.fastest_lockups()
    build = time.perf_counter() - start
    start = time.perf_counter()
    result = problem.solve(weights=weights, t_max=problem.ocp.default_t_max(),
                           t_max_margin=t_max_margin, aggregate=aggregate, presolve_intervals=presolve or None)
    total = time.perf_counter() - start
    return problem, result, build, total


def replay_numbers(run, t_max):
    t_lock = run.summary["engagement_time_s"]
    return {"lock_time_s": t_lock, "jump_Nm": run.summary["lockup_torque_jump_Nm"],
            "locks_within_t_max": t_lock is not None and t_lock <= t_max}


def label(overrides, centre):
    return " ".join(f"{name.split('.')[-1]}{'+' if overrides[name] > centre[name] else '-'}"
                    if not np.isclose(overrides[name], centre[name]) else f"{name.split('.')[-1]}0"
                    for name in centre)


def acceptance(scene, intervals, weights, out, count=9, t_max_margin=0.0, aggregate="mean", diagonal=False,
               presolve=PRESOLVE_INTERVALS):
    corners, centre = box_points(scene)
    problem, robust, build, total = solve(scene, scenario_set(scene, count, diagonal), intervals, weights,
                                          t_max_margin, aggregate, presolve)
    t_max = problem.ocp.default_t_max()       # the limit the replays are judged by
    print(f"robust ({count} scenarios, {intervals} intervals): build {build:.1f} s, solve {total:.1f} s, "
          f"{robust.stats['iterations']} iterations", file=sys.stderr)
    nominal = EngagementOCP(scene, intervals=intervals, baseline=problem.ocp.baseline).solve(t_max=t_max)
    # (the nominal optimum uses the whole t_max: it is the "nominal optimum")
    rows = []
    for overrides in corners + [centre]:
        s = scene.with_overrides(overrides)
        model = CommandModel(s, "linear")
        t_end = 3.0 * t_max
        row = {"corner": label(overrides, centre), "overrides": overrides,
               "baseline": replay_numbers(simulate_engagement(s), t_max),
               "nominal_optimum": replay_numbers(simulate_command(s, nominal.command_times, nominal.command, t_end,
                                                                  model=model, control="linear"), t_max),
               "robust_optimum": replay_numbers(simulate_command(s, robust.command_times, robust.command, t_end,
                                                                 model=model, control="linear"), t_max)}
        rows.append(row)
    summary = {"t_max_s": t_max, "t_max_solved_s": robust.t_max, "aggregate": aggregate, "intervals": intervals,
               "weights": weights, "scenarios": count + (len(robust.scenarios) - count),
               "robust_build_s": build, "corners": rows,
               "robust_solve_s": total, "robust_iterations": robust.stats["iterations"],
               "robust_collocation_jumps_Nm": [s.terms["lockup_torque_jump_Nm"] for s in robust.scenarios],
               "robust_collocation_lock_times_s": robust.lock_times.tolist()}
    for key in ("baseline", "nominal_optimum", "robust_optimum"):
        jumps = [abs(r[key]["jump_Nm"]) for r in rows if r[key]["jump_Nm"] is not None]
        summary[key] = {"all_lock_within_t_max": all(r[key]["locks_within_t_max"] for r in rows),
                        "worst_abs_jump_Nm": max(jumps) if jumps else None,
                        "locked": sum(r[key]["lock_time_s"] is not None for r in rows)}
    plot(out, scene, rows, robust, nominal, problem, t_max, count)
    return summary


def plot(out, scene, rows, robust, nominal, problem, t_max, count):
    out.mkdir(parents=True, exist_ok=True)
    names = [r["corner"] for r in rows]
    strategies = (("baseline", "baseline (scene profile)", "C3"), ("nominal_optimum", "nominal optimum", "C1"),
                  ("robust_optimum", f"robust optimum (solved on {count} scenarios)", "C0"))
    fig, (ax1, ax2) = new_figure(2, width=5.5)
    x = np.arange(len(rows))
    for k, (key, text, color) in enumerate(strategies):
        jumps = [abs(r[key]["jump_Nm"]) if r[key]["jump_Nm"] is not None else np.nan for r in rows]
        locks = [r[key]["lock_time_s"] if r[key]["lock_time_s"] is not None else np.nan for r in rows]
        ax1.bar(x + (k - 1) * 0.27, jumps, width=0.27, color=color, label=text)
        ax2.bar(x + (k - 1) * 0.27, locks, width=0.27, color=color, label=text)
        for i, value in enumerate(locks):
            if np.isnan(value):
                ax2.text(i + (k - 1) * 0.27, 0.01, "no lock", rotation=90, fontsize=6, ha="center", va="bottom")
    ax2.axhline(t_max, color="k", ls="--", lw=0.8, label=f"t_max = {t_max:.3f} s")
    ax1.set(ylabel="|torque jump at lock-up| [N m]", title="IDAS replay at the 8 box corners and the centre")
    ax2.set(ylabel="lock-up time [s]", title="lock-up time (same replays)")
    for ax in (ax1, ax2):
        ax.set_xticks(x, names, rotation=60, fontsize=7)
        ax.legend(fontsize=7)
    save_figure(fig, out / "corner_jumps.png")

    fig, (ax,) = new_figure()
    ax.plot(nominal.command_times, nominal.command / 1e6, color="C1", label="nominal optimum (command)")
    ax.plot(robust.command_times, robust.command / 1e6, color="C0", label=f"robust optimum, {count} scenarios (command)")
    base = problem.ocp.baseline.result
    ax.plot(base.t, base["pressure_Pa"] / 1e6, color="C3", lw=0.8, label="baseline (pressure, centre)")
    for t_lock in robust.lock_times:
        ax.axvline(t_lock, color="C0", lw=0.5, ls=":")
    ax.set(xlabel="time [s]", ylabel="pressure [MPa]", xlim=(0, 1.2 * t_max),
           title=f"{scene.name}: commands (dotted: robust lock-up per scenario)")
    ax.legend(fontsize=8)
    save_figure(fig, out / "commands.png")


def montecarlo(scene, robust, samples, seed, workers):
    """Open-loop Monte Carlo of the robust command (continued by its clamp ramp, as ``clutchocp robust``
    runs it) beside the scene's own profile: the draws of ``clutchocp robust`` (seeded), IDAS, in
    ``workers`` processes. Returns the per-strategy statistics and the samples per second."""
    from clutchocp.shiftcontrol.closed_loop import post_lock_command
    from clutchocp.shiftcontrol.design import pressure_limits
    from clutchocp.shiftcontrol.montecarlo import Strategy, parallel_map, run_sample, strategy_statistics
    from clutchocp.shiftcontrol.spec import load_slip_spec
    from clutchocp.scene.uncertainty import Uncertainty

    spec = load_slip_spec()
    uncertainty = Uncertainty.from_scene(scene)
    nominal = scene.without_uncertainty()
    p_lo, p_hi = pressure_limits(nominal, spec)
    rate = (p_hi - p_lo) / spec.rate_limit_time                  # the ramp rate of clutchocp robust
    p_set = nominal.value("actuation.pressure")
    times, values = post_lock_command(nominal, robust.command_times, robust.command, float(robust.lock_times.max()),
                                      rate)
    strategies = [Strategy("baseline", "baseline", np.array([0.0, 1.0]), np.array([p_set, p_set])),
                  Strategy("robust_feedforward", "robust feedforward + clamp", times, values)]
    t_max = robust.t_limit
    tasks = [{"scene_raw": nominal.raw, "scene_path": nominal.path, "overrides": d, "index": i, "strategies": strategies,
              "t_max": t_max, "t_end": 1.5 * t_max + 0.05}
             for i, d in enumerate(uncertainty.samples(samples, seed=seed))]
    start = time.perf_counter()
    rows = [row for sample in parallel_map(run_sample, tasks, workers=workers) for row in sample]
    wall = time.perf_counter() - start
    stats = strategy_statistics(rows)
    return {"samples": samples, "seed": seed, "workers": workers, "t_max_s": t_max, "wall_s": wall,
            "samples_per_s": samples / wall, "statistics": stats,
            "worst_jump_over_baseline": stats["robust_feedforward"]["jump_pct"]["worst"]
            / stats["baseline"]["jump_pct"]["worst"]}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenarios", type=int, nargs="*", default=[1, 3, 5, 9])
    parser.add_argument("--intervals", type=int, default=ROBUST_INTERVALS)
    parser.add_argument("--jump-weight", type=float, default=ROBUST_WEIGHTS["jump"])
    parser.add_argument("--presolve", type=int, default=0,
                        help=f"command steps of the coarse presolve (0, the default: none, start on the fine grid; "
                             f"the solver's own default is {PRESOLVE_INTERVALS})")
    parser.add_argument("--jerk-weight", type=float, default=ROBUST_WEIGHTS["jerk"])
    parser.add_argument("--smooth-weight", type=float, default=ROBUST_WEIGHTS["smooth"])
    parser.add_argument("--diagonal", action=argparse.BooleanOptionalAction, default=True,
                        help="add the lock_diagonal points of the box (first to last corner to lock) to every set")
    parser.add_argument("--acceptance", type=int, default=None, metavar="SCENARIOS",
                        help="solve with this scenario set (1, 3, 5, 9) and replay at the 9 box points")
    parser.add_argument("--t-max-margin", type=float, default=ROBUST_T_MAX_MARGIN,
                        help="every scenario locks by (1 - margin) t_max (replays judged by t_max)")
    parser.add_argument("--montecarlo", type=int, default=0, metavar="SAMPLES",
                        help="open-loop Monte Carlo of the 9-point robust command and the baseline (samples/s)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--aggregate", choices=AGGREGATES, default=ROBUST_AGGREGATE)
    parser.add_argument("--out", default="out/bench_robust")
    parser.add_argument("--json", help="also write the results to this JSON file")
    args = parser.parse_args()
    scene = default_scene()
    weights = {"jump": args.jump_weight, "jerk": args.jerk_weight, "smooth": args.smooth_weight}
    report = {"timing": [], "settings": {"intervals": args.intervals, "presolve": args.presolve, "weights": weights,
                                         "diagonal": args.diagonal,
                                         "t_max_margin": args.t_max_margin, "aggregate": args.aggregate}}
    print(f"{'scenarios':>9s} {'build [s]':>10s} {'solve [s]':>10s} {'iterations':>10s} {'IPOPT runs':>10s} "
          f"{'IPOPT [s/iteration]':>19s}")
    solved = {}
    for count in args.scenarios:
        try:
            _, result, build, total = solve(scene, scenario_set(scene, count, args.diagonal), args.intervals,
                                            weights, args.t_max_margin, args.aggregate, args.presolve)
            solved[count] = result
        except ClutchocpError as exc:
            report["timing"].append({"scenarios": count, "failed": str(exc)})
            print(f"{count:9d} failed: {exc}", flush=True)
            continue
        row = {"scenarios": count, "build_s": build, "solve_s": total, "iterations": result.stats["iterations"],
               "ipopt_s": result.stats["wall_time_s"],
               "solves": len(result.stats["stages"]), "objective": result.objective}
        report["timing"].append(row)
        print(f"{count:9d} {build:10.1f} {total:10.1f} {row['iterations']:10d} {row['solves']:10d} "
              f"{row['ipopt_s'] / max(row['iterations'], 1):19.3f}", flush=True)
    if args.montecarlo:
        robust = solved.get(9)
        if robust is None:
            robust = solve(scene, scenario_set(scene, 9, args.diagonal), args.intervals, weights,
                           args.t_max_margin, args.aggregate, args.presolve)[1]
        mc = montecarlo(scene, robust, args.montecarlo, args.seed, args.workers)
        report["montecarlo"] = mc
        print(f"Monte Carlo, open loop: {mc['samples']} samples (seed {mc['seed']}), {mc['workers']} workers, "
              f"{mc['wall_s']:.1f} s: {mc['samples_per_s']:.2f} samples/s (both strategies per sample)")
        for name, st in mc["statistics"].items():
            j = st["jump_pct"]
            print(f"  {name:>20s}: lock within t_max = {mc['t_max_s']:.4f} s: {100 * st['lock_within_t_max_share']:.1f} %,"
                  f" |jump| [% of locked torque] median {j['median']:.1f} / p95 {j['p95']:.1f} / worst {j['worst']:.1f}")
        print(f"  robust worst |jump| / baseline worst |jump| = {mc['worst_jump_over_baseline']:.3f} (target <= 0.5)")
    if args.acceptance is not None:
        acc = acceptance(scene, args.intervals, weights, Path(args.out), args.acceptance, args.t_max_margin,
                         args.aggregate, args.diagonal, args.presolve)
        report["acceptance"] = acc
        print(f"t_max = {acc['t_max_s']:.4f} s")
        print(f"{'corner':>26s} | {'baseline':>18s} | {'nominal optimum':>18s} | {'robust optimum':>18s}")
        for r in acc["corners"]:
            cells = []
            for key in ("baseline", "nominal_optimum", "robust_optimum"):
                n = r[key]
                cells.append("never locks" if n["lock_time_s"] is None
                             else f"{n['lock_time_s']:.4f} s {n['jump_Nm']:7.1f} N m")
            print(f"{r['corner']:>26s} | " + " | ".join(f"{c:>18s}" for c in cells))
        for key in ("baseline", "nominal_optimum", "robust_optimum"):
            a = acc[key]
            print(f"{key}: all lock within t_max: {a['all_lock_within_t_max']}, worst |jump| "
                  f"{a['worst_abs_jump_Nm']} N m ({a['locked']}/9 lock)")
    if args.json:
        Path(args.json).write_text(json.dumps(report, indent=2, default=float))


if __name__ == "__main__":
    main()
