"""The strategies of ``clutchocp robust`` and their Monte Carlo over a scene's uncertainty: the numbers.

Strategies (a data-driven list, :func:`build_strategies`): the scene's own profile (baseline), the
nominal optimum (``clutchocp optimize``'s curve continued by its clamp ramp), the robust feedforward
(:func:`clutchocp.optimal.robust.solve_robust` over the corners and the centre of the uncertainty
box) and the closed loop (slip feedback on the best feedforward there is). Each sample of the
uncertainty runs every strategy on the exact model with IDAS (:func:`monte_carlo`); samples run in
parallel processes. :mod:`clutchocp.shiftcontrol.figures` draws the results and
:mod:`clutchocp.shiftcontrol.report` writes them.
"""

import os
import time
import warnings

import numpy as np

from ..errors import ModelError, PhysicalRangeError, SolverError
from ..optimal.baselines import baseline_label
from ..optimal.problem import LOCK_MARGIN, EngagementOCP
from ..optimal.robust import lock_diagonal, solve_robust
from .closed_loop import post_lock_command
from .design import pressure_limits
from .montecarlo import Strategy, parallel_map, run_sample, strategy_statistics
from .schedule import design_schedule

STRATEGIES = ("baseline", "nominal_optimum", "robust_feedforward", "closed_loop")
ACCEPTANCE = {"robust_worst_jump_over_baseline": 0.5}
COLUMNS = (("engagement_time_s", "engagement_time [s]"), ("lockup_torque_jump_Nm", "jump [N m]"),
           ("jump_pct", "jump [% of locked torque]"), ("jerk_integral", "jerk_integral [rad^2/s^5]"),
           ("dissipated_energy_J", "dissipated_energy [J]"), ("peak_torque_Nm", "peak_torque [N m]"),
           ("locked_torque_Nm", "locked_torque [N m]"))


# The robust feedforward over the box points and two points on the diagonal between the first and the
# last corner to lock, with the settings it converges with on the default scene (README, "Robust
# feedforward"): 12 command steps without a presolve (15 took 777 s, 20 stopped in IPOPT), the worst
# |jump| share as the objective (epigraph) with small jerk and smoothness weights, the jump as a
# penalty (the jump condition of optimize is infeasible over the box), and every scenario locked by
# 0.98 t_max, so that the clutches between them lock within t_max.
ROBUST_INTERVALS = 12
ROBUST_WEIGHTS = {"jump": 1000.0, "jerk": 0.1, "smooth": 0.01}
ROBUST_AGGREGATE = "worst_jump"
ROBUST_T_MAX_MARGIN = 0.02


def robust_solver():
    """(``solve_robust``, ``lock_diagonal``) of the robust feedforward; None leaves the robust feedforward out
    (a test replaces this to skip the expensive solve or to stand in for it)."""
    return solve_robust, lock_diagonal


def check_strategies(names):
    """The strategies asked for, in the canonical order (ModelError for an unknown or missing name)."""
    names = tuple(names)
    unknown = [n for n in names if n not in STRATEGIES]
    if unknown or not names:
        raise ModelError(f"--strategies {','.join(names) or '(none)'}: allowed are {', '.join(STRATEGIES)} "
                         "(a comma-separated subset)")
    return tuple(n for n in STRATEGIES if n in names)


def build_strategies(scene, uncertainty, spec, *, t_max=None, intervals=60, say=print, chosen=STRATEGIES):
    """The strategies compared, as plain data, and the facts about them for the summary.

    Only the ``chosen`` ones are made (the nominal optimum is always solved: it sets t_max, the closed loop
    tracks it and its jerk is the closed loop's yardstick; with the closed loop but not the nominal optimum
    chosen it is run on the nominal clutch alone, ``notes["centre_only"]``).

    Returns
    -------
    (list of Strategy, dict)
    """
    chosen = check_strategies(chosen)
    variant = scene.variant("actuation")
    if variant not in ("valve_lag", "step"):
        raise ModelError(f"actuation.model = '{variant}': the Monte Carlo runs the baseline as a constant pressure "
                         "command, which needs actuation.model = 'valve_lag' or 'step'")
    p_lo, p_hi = pressure_limits(scene, spec)
    rate = (p_hi - p_lo) / spec.rate_limit_time
    p_set = scene.value("actuation.pressure")
    strategies = [Strategy("baseline", f"baseline ({baseline_label(scene)})", np.array([0.0, 1.0]),
                           np.array([p_set, p_set]))]
    say(f"robust {scene.name}: nominal optimum ({intervals} intervals)")
    ocp = EngagementOCP(scene, intervals=intervals)
    opt = ocp.solve(t_max=t_max)
    t_max = opt.t_max
    times, values = post_lock_command(scene, opt.command_times, opt.command, opt.t_f, rate)
    strategies.append(Strategy("nominal_optimum", "nominal optimum + clamp", times, values,
                               notes={"t_lock_s": opt.t_f, "centre_only": "nominal_optimum" not in chosen}))
    feedforward = ("nominal_optimum", opt.command_times, opt.command)
    facts = {"t_max_s": t_max, "nominal_optimum": {k: opt.terms[k] for k in
                                                   ("engagement_time_s", "jerk_integral", "lockup_torque_jump_Nm")}}
    wanted = "robust_feedforward" in chosen or ("closed_loop" in chosen and spec.feedforward_curve == "robust")
    robust, rob = robust_solver() if wanted else None, None
    if not wanted:
        facts["robust_feedforward"] = "not asked for (--strategies)"
    elif robust is None:
        facts["robust_feedforward"] = "left out"
        say("  robust feedforward: left out")
    else:
        solve_robust, lock_diagonal = robust
        corners = uncertainty.corners()
        scenarios = corners + [uncertainty.centre()] + lock_diagonal(scene, corners)
        say(f"  robust feedforward over {len(scenarios)} scenarios ({ROBUST_INTERVALS} intervals, {ROBUST_AGGREGATE} "
            f"objective, jump weight {ROBUST_WEIGHTS['jump']:g}, lock-up by {1 - ROBUST_T_MAX_MARGIN:g} t_max)")
        try:
            # one command rarely lets every scenario lock without a jump: the jump is a penalty
            rob = solve_robust(scene, scenarios, t_max=t_max, intervals=ROBUST_INTERVALS, jump="penalty",
                               weights=ROBUST_WEIGHTS, aggregate=ROBUST_AGGREGATE,
                               t_max_margin=ROBUST_T_MAX_MARGIN, presolve_intervals=None)
            failure = None if rob.success else f"IPOPT stopped with {rob.stats.get('status')}"
        except SolverError as exc:
            failure = str(exc)
        if failure is not None:    # the other strategies still say something: go on without it
            warnings.warn(f"robust feedforward over {len(scenarios)} scenarios did not converge ({failure}); "
                          "the Monte Carlo goes on without it")
            facts["robust_feedforward"] = f"not converged: {failure}"
            rob = None
    if rob is not None:
        t_end_command = float(max(s.t_f for s in rob.scenarios))
        r_times, r_values = post_lock_command(scene, rob.command_times, rob.command, t_end_command, rate)
        if "robust_feedforward" in chosen:
            strategies.append(Strategy("robust_feedforward", "robust feedforward + clamp", r_times, r_values))
        if spec.feedforward_curve == "robust":
            feedforward = ("robust_feedforward", np.asarray(rob.command_times), np.asarray(rob.command))
        facts["robust_feedforward"] = {"scenarios": len(scenarios), "intervals": ROBUST_INTERVALS,
                                       "aggregate": ROBUST_AGGREGATE, "weights": ROBUST_WEIGHTS,
                                       "t_max_margin": ROBUST_T_MAX_MARGIN,
                                       "lock_times_s": [float(s.t_f) for s in rob.scenarios],
                                       "stats": {k: v for k, v in rob.stats.items()
                                                 if isinstance(v, (bool, int, float, str))}}
    if spec.feedforward_curve == "robust" and rob is None:
        say("  feedforward.curve = 'robust' but no robust feedforward converged: the loop tracks the nominal optimum")
    margin = feedforward[0] == "nominal_optimum" and spec.t_max_fraction < 1.0
    if margin:
        # the loop tracks a nominal optimum that locks with a time margin, so that
        # a slower clutch can still lock within t_max (feedforward.t_max_fraction of the spec)
        say(f"  nominal optimum for the closed loop at {spec.t_max_fraction:g} x t_max = "
            f"{spec.t_max_fraction * t_max:.4g} s")
        feedforward = ("nominal_optimum_with_margin",) + feedforward[1:]
    reserve = spec.pressure_reserve if feedforward[0] != "robust_feedforward" else 0.0
    if reserve > 0:
        p_top = pressure_limits(scene, spec)[1]
        if reserve >= p_top:
            raise PhysicalRangeError(f"feedforward.pressure_reserve = {reserve / 1e6:g} MPa: must be below the "
                                     f"loop's pressure limit {p_top / 1e6:g} MPa")
        # the feedforward keeps a pressure reserve for the feedback: its optimum is solved with the limit lowered
        say(f"  nominal optimum for the closed loop with a pressure reserve of {reserve / 1e6:g} MPa "
            f"(limit {(p_top - reserve) / 1e6:g} MPa)")
    # the nominal optimum the loop tracks may land further above the locked torque (feedforward.lock_margin)
    landing = spec.lock_margin if feedforward[0] != "robust_feedforward" else LOCK_MARGIN
    if landing != LOCK_MARGIN:
        say(f"  nominal optimum for the closed loop landing {100 * landing:g} % above the locked torque")
    own = not margin and reserve == 0 and landing == LOCK_MARGIN
    ff_label = ("nominal optimum" if not own else feedforward[0].replace("_", " ")) \
        + (f" at {spec.t_max_fraction:g} t_max" if margin else "") \
        + (f" with a {reserve / 1e6:g} MPa reserve" if reserve > 0 else "") \
        + (f" landing {100 * landing:g} % above the locked torque" if landing != LOCK_MARGIN else "")

    def feedforward_for(design_scene):
        # the closed loop's feedforward on a design scene: the curve chosen above on the nominal scene,
        # else the nominal optimum of the design scene (same t_max and margin)
        if feedforward[0] == "robust_feedforward":
            return feedforward[1], feedforward[2]
        same = design_scene is scene
        if reserve > 0:
            design_scene = with_pressure_limit(design_scene, pressure_limits(design_scene, spec)[1] - reserve)
        problem = ocp if same and reserve == 0 and landing == LOCK_MARGIN else \
            EngagementOCP(design_scene, intervals=intervals, lock_margin=landing)
        if same and own:
            return opt.command_times, opt.command
        found = problem.solve(t_max=spec.t_max_fraction * t_max, guess=opt if same else None)
        return found.command_times, found.command

    if "closed_loop" in chosen:
        say(f"  slip feedback on the {ff_label}: {spec.label}, Ts = {spec.sample_time * 1e3:g} ms"
            + (f", scheduled on {spec.schedule_field} ({spec.schedule_points} points)" if spec.schedule_field else ""))
        schedule = design_schedule(scene, spec, uncertainty, feedforward_for, say=say)
        if schedule.adaptation_off is not None:
            say(f"  feedforward adaptation off on this scene: {schedule.adaptation_off}")
        strategies.append(_closed_loop_strategy(spec, schedule, ff_label, feedforward[0]))
        facts["closed_loop"] = _closed_loop_facts(scene, spec, schedule, feedforward[0])
    strategies = [s for s in strategies if s.name in chosen or s.notes.get("centre_only")]
    return strategies, facts


def with_pressure_limit(scene, limit):
    """The scene with ``actuation.max_pressure`` lowered to ``limit`` [Pa], its own step pressure
    (``actuation.pressure``, the optimisation's first guess) lowered with it where it was above."""
    lowered = {"actuation.max_pressure": limit}
    step = scene.get("actuation.pressure")
    if isinstance(step, (int, float)) and step > limit:
        lowered["actuation.pressure"] = limit
    return scene.with_overrides(lowered)


def _closed_loop_strategy(spec, schedule, ff_label, feedforward):
    kalman = schedule.sensors is not None
    adaptive = spec.estimator["enabled"] and schedule.adaptation_off is None
    designs = f"{len(schedule.feedbacks)} designs over {schedule.field}"
    traits = [t for t, on in (("Kalman filter on its sensors", kalman), ("adaptive", adaptive and not kalman),
                               (designs, bool(schedule.field))) if on]
    return Strategy("closed_loop", f"slip feedback on {ff_label}" + (f" ({', '.join(traits)})" if traits else ""),
                    feedback=schedule, notes={"feedforward": feedforward})


def _closed_loop_facts(scene, spec, schedule, feedforward):
    adaptive = spec.estimator["enabled"] and schedule.adaptation_off is None
    first = schedule.feedbacks[0]
    facts = {"feedforward": feedforward, "feedforward_t_max_fraction": spec.t_max_fraction,
             "feedforward_lock_margin": spec.lock_margin,
             "controller": spec.label, "sample_time_s": spec.sample_time,
             "nominal_lock_s": schedule.lock_times[schedule.index(scene)], "progress": spec.progress,
             "measured": list(first.measured), "estimator": bool(adaptive),
             "estimator_method": spec.estimator["method"], "estimator_off": schedule.adaptation_off,
             "schedule": {"field": schedule.field, "values": [float(v) for v in schedule.values if np.isfinite(v)],
                          "lock_times_s": schedule.lock_times}}
    if schedule.sensors is not None:
        facts["sensors"] = schedule.sensors.describe()
        facts["kalman"] = {"state": list(first.names), "estimated_parameters": dict(spec.estimated_parameters),
                           "lock_slip_rad_s": [float(f.lock_slip) for f in schedule.feedbacks],
                           "lock_samples": first.lock_samples}
    return facts


def monte_carlo(nominal, uncertainty, strategies, facts, *, samples, seed, workers=None, progress=None):
    """Every strategy on the centre of the uncertainty and on ``samples`` draws of it.

    Parameters
    ----------
    nominal : Scene
        The scene without its uncertainty.
    uncertainty : Uncertainty
    strategies, facts :
        From :func:`build_strategies` (``facts["t_max_s"]`` sets the run length 1.5 t_max + 0.05 s).
    samples, seed : int
        Draws of the uncertainty and their seed.
    workers : int, optional
        Processes (default: the local cores).
    progress : callable, optional
        ``progress(done, total)`` after each sample (see :func:`~clutchocp.shiftcontrol.montecarlo.parallel_map`).

    Returns
    -------
    (rows, run_end_s, monte_carlo_s, n_tasks)
        ``rows``: one per sample (``sample`` -1: the centre) and strategy.
    """
    t_max = facts["t_max_s"]
    t_end = 1.5 * t_max + 0.05
    draws = [uncertainty.centre()] + uncertainty.samples(samples, seed=seed)
    tasks = [{"scene_raw": nominal.raw, "scene_path": nominal.path, "overrides": d, "index": i - 1, "seed": seed,
              "strategies": strategies, "t_max": t_max, "t_end": t_end} for i, d in enumerate(draws)]
    start = time.perf_counter()
    results = parallel_map(run_sample, tasks, workers=workers, progress=progress)
    mc_time = time.perf_counter() - start
    return [row for sample_rows in results for row in sample_rows], t_end, mc_time, len(tasks)


def robust_summary(scene, spec, uncertainty, strategies, facts, rows, *, samples, seed, t_end, timing):
    """The numbers of summary.json: statistics per strategy over the draws, the nominal clutch, acceptance."""
    centre = [r for r in rows if r["sample"] == -1]
    stats = strategy_statistics([r for r in rows if r["sample"] >= 0])
    return {
        "scene": scene.name, "samples": samples, "seed": seed, "uncertainty": uncertainty.to_dict(),
        "t_max_s": facts["t_max_s"], "run_end_s": t_end, "strategies": {s.name: s.label for s in strategies},
        "statistics": stats,
        "nominal": {r["strategy"]: {k: r[k] for k, _ in COLUMNS} | {"locked": r["locked"]} for r in centre},
        "acceptance": acceptance(stats, centre, [r for r in rows if r["sample"] >= 0], spec.acceptance,
                                 facts["t_max_s"]),
        "facts": facts,
        "timing": timing,
        "controller": {"name": spec.label, "sample_time_s": spec.sample_time, "lqi": spec.lqi,
                       "anti_windup": spec.anti_windup, "progress": spec.progress,
                       "feedforward_t_max_fraction": spec.t_max_fraction,
                       "feedforward_lock_margin": spec.lock_margin,
                       "measure_pressure": spec.measure_pressure, "rate_limit_time_s": spec.rate_limit_time},
    }


def cpu_count():
    """The local cores (the default number of processes)."""
    return os.cpu_count() or 1


def acceptance(stats, centre, rows, targets, t_max):
    """The acceptance checks of the shift-control targets (JSON-ready): the numbers, their limits and pass/fail.

    The closed loop's targets are the spec's ``[acceptance]``: every draw locked by ``lock_by_t_max`` x t_max,
    the 95th percentile and the largest |jump| [% of the locked torque], the nominal clutch's jerk integral
    over the nominal optimum's.
    """
    out = {}
    cl = stats.get("closed_loop")
    if cl is not None:
        nominal = {r["strategy"]: r for r in centre}
        jerk_cl = nominal["closed_loop"]["jerk_integral"]
        jerk_opt = nominal["nominal_optimum"]["jerk_integral"] if "nominal_optimum" in nominal else None
        ratio = jerk_cl / jerk_opt if jerk_cl is not None and jerk_opt else None
        mine = [r for r in rows if r["strategy"] == "closed_loop"]
        by = targets["lock_by_t_max"]
        share = sum(r["engagement_time_s"] is not None and r["engagement_time_s"] <= by * t_max for r in mine) \
            / max(len(mine), 1)
        late = max((r["engagement_time_s"] for r in mine if r["engagement_time_s"] is not None), default=None)
        out["closed_loop"] = {
            "lock_by_limit_share": share, "latest_lock_over_t_max": late / t_max if late is not None else None,
            "lock_within_t_max_share": cl["lock_within_t_max_share"],
            "jump_p95_pct": cl["jump_pct"]["p95"], "jump_worst_pct": cl["jump_pct"]["worst"],
            "nominal_jerk_over_nominal_optimum": ratio,
            "limits": {"lock_by_t_max": by, "lock_by_limit_share": 1.0, "jump_p95_pct": targets["jump_p95_pct"],
                       "jump_worst_pct": targets["jump_worst_pct"],
                       "nominal_jerk_over_nominal_optimum": targets["jerk_ratio"]},
        }
        out["closed_loop"]["passed"] = bool(
            share == 1.0 and cl["jump_pct"]["p95"] is not None
            and cl["jump_pct"]["p95"] <= targets["jump_p95_pct"]
            and cl["jump_pct"]["worst"] <= targets["jump_worst_pct"]
            and ratio is not None and ratio <= targets["jerk_ratio"])
    rob, base = stats.get("robust_feedforward"), stats.get("baseline")
    if rob is not None and base is not None:
        worst_r, worst_b = rob["jump_pct"]["worst"], base["jump_pct"]["worst"]
        out["robust_feedforward"] = {
            "lock_within_t_max_share": rob["lock_within_t_max_share"], "jump_worst_pct": worst_r,
            "baseline_jump_worst_pct": worst_b,
            "passed": bool(rob["lock_within_t_max_share"] == 1.0 and worst_r is not None and worst_b is not None
                           and worst_r <= ACCEPTANCE["robust_worst_jump_over_baseline"] * worst_b)}
    return out


def format_summary(summary):
    """A short human summary of a Monte Carlo run."""
    lines = [f"robust {summary['scene']}: {summary['samples']} samples (seed {summary['seed']}), "
             f"t_max = {summary['t_max_s']:.4g} s, {summary['timing']['samples_per_s']:.3g} samples/s"]
    for name, st in summary["statistics"].items():
        j = st["jump_pct"]
        fmt = (lambda v: "-" if v is None else f"{v:.3g}")
        lines.append(f"  {name:<20} locked within t_max {100 * st['lock_within_t_max_share']:5.1f} %, |jump| % "
                     f"median {fmt(j['median'])}, p95 {fmt(j['p95'])}, worst {fmt(j['worst'])}; "
                     f"jerk integral median {fmt(st['jerk_integral']['median'])}")
    for name, acc in summary["acceptance"].items():
        lines.append(f"  acceptance {name}: {'passed' if acc['passed'] else 'not met'}")
    return "\n".join(lines)
