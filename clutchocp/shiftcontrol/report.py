"""``clutchocp robust``: Monte Carlo proof of shift-control strategies over a scene's uncertainty.

Strategies (a data-driven list, :func:`build_strategies`): the scene's own profile (baseline), the
nominal optimum (``clutchocp optimize``'s curve continued by its clamp ramp), the robust feedforward
(``clutchocp.optimal.robust.solve_robust`` over the corners and the centre of the uncertainty box,
when that module is installed) and the closed loop (slip feedback on the best feedforward there is).
Each sample of the uncertainty runs every strategy on the exact model with IDAS; samples run in
parallel processes. Writes summary.json, samples.csv and three figures.
"""

import sys
import textwrap
import time
import warnings
from pathlib import Path

import numpy as np

from ..errors import ModelError, SolverError
from ..optimal.baselines import baseline_label
from ..optimal.problem import EngagementOCP
from ..output import new_figure, save_figure, write_csv, write_summary
from ..scene import default_scene, load_scene
from ..scene.uncertainty import Uncertainty
from .closed_loop import post_lock_command
from .design import pressure_limits
from .montecarlo import HISTORY_STEP, Strategy, parallel_map, run_sample, strategy_statistics
from .schedule import design_schedule
from .spec import load_slip_spec

ACCEPTANCE = {"closed_loop_jump_p95_pct": 3.0, "closed_loop_jump_worst_pct": 6.0, "closed_loop_jerk_ratio": 1.15,
              "robust_worst_jump_over_baseline": 0.5}
COLUMNS = (("engagement_time_s", "engagement_time [s]"), ("lockup_torque_jump_Nm", "jump [N m]"),
           ("jump_pct", "jump [% of locked torque]"), ("jerk_integral", "jerk_integral [rad^2/s^5]"),
           ("dissipated_energy_J", "dissipated_energy [J]"), ("peak_torque_Nm", "peak_torque [N m]"),
           ("locked_torque_Nm", "locked_torque [N m]"))
COLOURS = {"baseline": "tab:gray", "nominal_optimum": "tab:blue", "robust_feedforward": "tab:green",
           "closed_loop": "tab:red"}


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
    """(``solve_robust``, ``lock_diagonal``) of the robust feedforward (clutchocp.optimal.robust), or None if not installed."""
    try:
        from ..optimal.robust import lock_diagonal, solve_robust
    except ImportError:
        return None
    return solve_robust, lock_diagonal


def build_strategies(scene, uncertainty, spec, *, t_max=None, intervals=60, say=print):
    """The strategies compared, as plain data, and the facts about them for the summary.

    Returns
    -------
    (list of Strategy, dict)
    """
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
                               notes={"t_lock_s": opt.t_f}))
    feedforward = ("nominal_optimum", opt.command_times, opt.command)
    facts = {"t_max_s": t_max, "nominal_optimum": {k: opt.terms[k] for k in
                                                   ("engagement_time_s", "jerk_integral", "lockup_torque_jump_Nm")}}
    robust, rob = robust_solver(), None
    if robust is None:
        facts["robust_feedforward"] = "not available: clutchocp.optimal.robust is not installed"
        say("  robust feedforward: not available (clutchocp.optimal.robust is not installed); skipped")
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
    ff_label = ("nominal optimum" if margin else feedforward[0].replace("_", " ")) \
        + (f" at {spec.t_max_fraction:g} t_max" if margin else "")

    def feedforward_for(design_scene):
        # the closed loop's feedforward on a design scene: the curve chosen above on the nominal scene,
        # else the nominal optimum of the design scene (same t_max and margin)
        if feedforward[0] == "robust_feedforward":
            return feedforward[1], feedforward[2]
        same = design_scene is scene
        problem = ocp if same else EngagementOCP(design_scene, intervals=intervals)
        if same and not margin:
            return opt.command_times, opt.command
        found = problem.solve(t_max=spec.t_max_fraction * t_max, guess=opt if same else None)
        return found.command_times, found.command

    say(f"  slip feedback on the {ff_label}: {spec.label}, Ts = {spec.sample_time * 1e3:g} ms"
        + (f", scheduled on {spec.schedule_field} ({spec.schedule_points} points)" if spec.schedule_field else ""))
    schedule = design_schedule(scene, spec, uncertainty, feedforward_for, say=say)
    adaptive = spec.estimator["enabled"] and schedule.adaptation_off is None
    if schedule.adaptation_off is not None:
        say(f"  feedforward adaptation off on this scene: {schedule.adaptation_off}")
    traits = [t for t, on in (("adaptive", adaptive),
                               (f"{len(schedule.feedbacks)} designs over {schedule.field}", bool(schedule.field))) if on]
    strategies.append(Strategy("closed_loop", f"slip feedback on {ff_label}"
                               + (f" ({', '.join(traits)})" if traits else ""),
                               feedback=schedule, notes={"feedforward": feedforward[0]}))
    facts["closed_loop"] = {"feedforward": feedforward[0], "feedforward_t_max_fraction": spec.t_max_fraction,
                            "controller": spec.label, "sample_time_s": spec.sample_time,
                            "nominal_lock_s": schedule.lock_times[schedule.index(scene)],
                            "progress": spec.progress, "measured": list(schedule.feedbacks[0].measured),
                            "estimator": bool(adaptive), "estimator_off": schedule.adaptation_off,
                            "schedule": {"field": schedule.field, "values": [float(v) for v in schedule.values
                                                                             if np.isfinite(v)],
                                         "lock_times_s": schedule.lock_times}}
    return strategies, facts


def run_robust(scene=None, out_dir="out/robust", *, samples=200, seed=0, uncertain=(), t_max=None,
               controller="slip_lqr", workers=None, intervals=60, progress=True):
    """Monte Carlo of the shift-control strategies of a scene; writes summary.json, samples.csv, figures.

    Parameters
    ----------
    scene : Scene, str or Path, optional
        Engagement scene (default: the default scene).
    out_dir : str or Path
    samples : int
        Number of draws of the uncertainty.
    seed : int
        Seed of the draws (same seed, same draws, same numbers).
    uncertain : sequence of str
        ``"part.key=spec"`` texts added to (or replacing) the scene's [uncertainty].
    t_max : float, optional
        Engagement-time limit [s] of the optimisations and of the lock-within-t_max share
        (default: the lock-up time of the scene's own profile, as ``clutchocp optimize``).
    controller : str or Path
        Slip-feedback spec (built-in name or TOML file).
    workers : int, optional
        Processes (default: the local cores).
    intervals : int
        Collocation intervals of the optimisations.

    Returns
    -------
    dict: the summary (plus ``files``).
    """
    say = (lambda *a: print(*a, file=sys.stderr)) if progress else (lambda *a: None)
    if scene is None:
        scene = default_scene()
    elif isinstance(scene, (str, Path)):
        scene = load_scene(scene)
    for name, value, allowed in (("samples", samples, False), ("workers", workers, True),
                                 ("intervals", intervals, False)):
        if value is None and allowed:
            continue
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
            raise ModelError(f"{name} = {value!r}: must be a whole number >= 1")
    spec = load_slip_spec(controller)
    uncertainty = Uncertainty.from_scene(scene, extra=tuple(uncertain))
    if not uncertainty:
        raise ModelError(f"scene '{scene.name}' declares no uncertainty: add an [uncertainty] table or "
                         "--uncertain \"friction.mu=uniform 10 %\"")
    nominal = scene.without_uncertainty()
    start = time.perf_counter()
    strategies, facts = build_strategies(nominal, uncertainty, spec, t_max=t_max, intervals=intervals, say=say)
    t_max = facts["t_max_s"]
    t_end = 1.5 * t_max + 0.05
    draws = [uncertainty.centre()] + uncertainty.samples(samples, seed=seed)
    tasks = [{"scene_raw": nominal.raw, "scene_path": nominal.path, "overrides": d, "index": i - 1,
              "strategies": strategies, "t_max": t_max, "t_end": t_end} for i, d in enumerate(draws)]
    setup = time.perf_counter() - start
    bar = _progress_bar(len(tasks), progress)
    mc_start = time.perf_counter()
    results = parallel_map(run_sample, tasks, workers=workers, progress=bar)
    mc_time = time.perf_counter() - mc_start
    if bar is not None:
        bar.close()
    rows = [row for sample_rows in results for row in sample_rows]
    centre = [r for r in rows if r["sample"] == -1]
    drawn = [r for r in rows if r["sample"] >= 0]
    stats = strategy_statistics(drawn)
    summary = {
        "scene": scene.name, "samples": samples, "seed": seed, "uncertainty": uncertainty.to_dict(),
        "t_max_s": t_max, "run_end_s": t_end, "strategies": {s.name: s.label for s in strategies},
        "statistics": stats,
        "nominal": {r["strategy"]: {k: r[k] for k, _ in COLUMNS} | {"locked": r["locked"]} for r in centre},
        "acceptance": acceptance(stats, centre),
        "facts": facts,
        "timing": {"setup_s": setup, "monte_carlo_s": mc_time, "samples_per_s": len(tasks) / mc_time,
                   "workers": workers or _cpu_count()},
        "controller": {"name": spec.label, "sample_time_s": spec.sample_time, "lqi": spec.lqi,
                       "anti_windup": spec.anti_windup, "progress": spec.progress,
                       "feedforward_t_max_fraction": spec.t_max_fraction,
                       "measure_pressure": spec.measure_pressure, "rate_limit_time_s": spec.rate_limit_time},
    }
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    files = [write_summary(out / "summary.json", summary), _write_samples(out / "samples.csv", rows, uncertainty)]
    files += plot_jump_vs_fields(out, drawn, uncertainty, strategies)
    files.append(plot_distributions(out, drawn, strategies, t_max))
    files.append(plot_envelopes(out, drawn, centre, strategies, t_max))
    summary["files"] = [str(f) for f in files]
    if progress:
        print(format_summary(summary))
    return summary


def _cpu_count():
    import os
    return os.cpu_count() or 1


def _progress_bar(total, enabled):
    if not enabled:
        return None
    from tqdm import tqdm
    bar = tqdm(total=total, desc="samples", unit="sample", file=sys.stderr)

    def update(done, _total):
        bar.n = done
        bar.refresh()
    update.close = bar.close
    return update


def acceptance(stats, centre):
    """The acceptance checks of the shift-control targets (JSON-ready): the numbers, their limits and pass/fail."""
    out = {}
    cl = stats.get("closed_loop")
    if cl is not None:
        nominal = {r["strategy"]: r for r in centre}
        jerk_cl, jerk_opt = nominal["closed_loop"]["jerk_integral"], nominal["nominal_optimum"]["jerk_integral"]
        ratio = jerk_cl / jerk_opt if jerk_cl is not None and jerk_opt else None
        out["closed_loop"] = {
            "lock_within_t_max_share": cl["lock_within_t_max_share"],
            "jump_p95_pct": cl["jump_pct"]["p95"], "jump_worst_pct": cl["jump_pct"]["worst"],
            "nominal_jerk_over_nominal_optimum": ratio,
            "limits": {"lock_within_t_max_share": 1.0, "jump_p95_pct": ACCEPTANCE["closed_loop_jump_p95_pct"],
                       "jump_worst_pct": ACCEPTANCE["closed_loop_jump_worst_pct"],
                       "nominal_jerk_over_nominal_optimum": ACCEPTANCE["closed_loop_jerk_ratio"]},
        }
        out["closed_loop"]["passed"] = bool(
            cl["lock_within_t_max_share"] == 1.0 and cl["jump_pct"]["p95"] is not None
            and cl["jump_pct"]["p95"] <= ACCEPTANCE["closed_loop_jump_p95_pct"]
            and cl["jump_pct"]["worst"] <= ACCEPTANCE["closed_loop_jump_worst_pct"]
            and ratio is not None and ratio <= ACCEPTANCE["closed_loop_jerk_ratio"])
    rob, base = stats.get("robust_feedforward"), stats.get("baseline")
    if rob is not None and base is not None:
        worst_r, worst_b = rob["jump_pct"]["worst"], base["jump_pct"]["worst"]
        out["robust_feedforward"] = {
            "lock_within_t_max_share": rob["lock_within_t_max_share"], "jump_worst_pct": worst_r,
            "baseline_jump_worst_pct": worst_b,
            "passed": bool(rob["lock_within_t_max_share"] == 1.0 and worst_r is not None and worst_b is not None
                           and worst_r <= ACCEPTANCE["robust_worst_jump_over_baseline"] * worst_b)}
    return out


def _write_samples(path, rows, uncertainty):
    fields = list(uncertainty.names)
    columns = {"sample": [r["sample"] for r in rows], "strategy": [r["strategy"] for r in rows]}
    for f in fields:
        columns[f] = [r.get(f) for r in rows]
    columns["locked"] = [int(r["locked"]) for r in rows]
    columns["locked_within_t_max"] = [int(r["locked_within_t_max"]) for r in rows]
    for key, name in COLUMNS:
        columns[name] = ["" if r[key] is None else r[key] for r in rows]
    return write_csv(path, columns)


def _label(key):
    return {"friction.mu": "friction coefficient [-]", "oil.viscosity": "oil viscosity [Pa s]",
            "load.torque": "load torque [N m]"}.get(key, key)


def plot_jump_vs_fields(out, rows, uncertainty, strategies):
    """|jump| at lock-up against each numeric uncertain field, one panel per field; no-lock samples on top."""
    numeric = [s.key for s in uncertainty.spreads if s.kind != "values"]
    if not numeric:
        return []
    fig, axes = new_figure(len(numeric), width=4.6, height=4.3)
    values = [r["jump_pct"] for r in rows if r["jump_pct"] is not None]
    floor = max(min(values + [2.0]) * 0.5, 1e-3)
    top = max(values + [1.0]) * 2.0
    for ax, key in zip(axes, numeric):
        for s in strategies:
            mine = [r for r in rows if r["strategy"] == s.name]
            x = [r[key] for r in mine if r["jump_pct"] is not None]
            y = [max(r["jump_pct"], floor) for r in mine if r["jump_pct"] is not None]
            ax.scatter(x, y, s=9, alpha=0.6, color=COLOURS.get(s.name), label=s.label)
            miss = [r[key] for r in mine if r["jump_pct"] is None]
            if miss:
                ax.scatter(miss, [top] * len(miss), marker="x", s=18, color=COLOURS.get(s.name))
        ax.axhline(3.0, color="k", lw=0.8, ls="--")
        ax.set_xlabel(_label(key))
        ax.set_ylabel("|torque jump at lock-up| [% of locked torque]")
        ax.set_yscale("log")
        ax.set_ylim(floor, top * 1.5)
        ax.grid(alpha=0.3, which="both")
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=len(strategies), fontsize=8)
    fig.suptitle(f"Torque jump at lock-up over {len({r['sample'] for r in rows})} samples "
                 f"(x at the top: no lock-up; dashed: 3 %)", fontsize=10)
    return [save_figure(fig, out / "jump_vs_fields.png")]


def plot_distributions(out, rows, strategies, t_max):
    """Box plots per strategy: |jump| [% of locked torque] and engagement time [s] (with t_max)."""
    fig, (ax1, ax2) = new_figure(2, width=5.6, height=4.6)
    names = [s.name for s in strategies]
    share = {n: 100 * np.mean([r["locked_within_t_max"] for r in rows if r["strategy"] == n]) for n in names}
    labels = [textwrap.fill(s.label, 22) + f"\nlocked in t_max: {share[s.name]:.0f} %" for s in strategies]
    for ax, key, title in ((ax1, "jump_pct", "|torque jump at lock-up| [% of locked torque]"),
                           (ax2, "engagement_time_s", "lock-up time [s]")):
        data = [[max(r[key], 1e-3) for r in rows if r["strategy"] == n and r[key] is not None] or [np.nan]
                for n in names]
        box = ax.boxplot(data, whis=(5, 95), showfliers=True, patch_artist=True)
        for patch, n in zip(box["boxes"], names):
            patch.set_facecolor(COLOURS.get(n, "white"))
            patch.set_alpha(0.5)
        ax.set_xticks(range(1, len(names) + 1), labels, fontsize=7)
        ax.set_ylabel(title)
        ax.grid(alpha=0.3, axis="y")
    ax1.axhline(3.0, color="k", lw=0.8, ls="--", label="3 %")
    ax1.set_yscale("log")
    ax1.set_ylim(bottom=min(ax1.get_ylim()[0], 1.0))
    ax1.legend(fontsize=7)
    ax2.axhline(t_max, color="k", lw=0.8, ls="--", label=f"t_max = {t_max:.3f} s")
    ax2.legend(fontsize=7)
    fig.suptitle("Distributions per strategy (box: quartiles, whiskers: 5-95 %; share locked within t_max "
                 "under each name)", fontsize=10)
    return save_figure(fig, out / "distributions.png")


def plot_envelopes(out, rows, centre, strategies, t_max):
    """Envelopes (min-max and 5-95 %) of slip, clutch torque and pressure over time, per strategy."""
    signals = (("w_rel_rad_s", "slip speed [rad/s]", 1.0), ("total_torque_Nm", "clutch torque [N m]", 1.0),
               ("pressure_Pa", "clutch pressure [MPa]", 1e-6))
    fig, axes = new_figure(len(strategies), width=3.6, height=7.5)
    fig.clear()
    grid = fig.add_gridspec(len(signals), len(strategies))
    for j, s in enumerate(strategies):
        mine = [r for r in rows if r["strategy"] == s.name]
        nominal = next((r for r in centre if r["strategy"] == s.name), None)
        for i, (key, label, scale) in enumerate(signals):
            ax = fig.add_subplot(grid[i, j])
            data = np.array([r["history"][key] for r in mine]) * scale
            t = np.arange(data.shape[1]) * HISTORY_STEP
            colour = COLOURS.get(s.name, "tab:blue")
            ax.fill_between(t, data.min(0), data.max(0), color=colour, alpha=0.2, lw=0, label="min-max")
            ax.fill_between(t, np.percentile(data, 5, 0), np.percentile(data, 95, 0), color=colour, alpha=0.45,
                            lw=0, label="5-95 %")
            if nominal is not None:
                ax.plot(t, nominal["history"][key] * scale, color="k", lw=0.9, label="nominal clutch")
            ax.axvline(t_max, color="k", lw=0.6, ls="--")
            ax.grid(alpha=0.3)
            if i == 0:
                ax.set_title(textwrap.fill(s.label, 48), fontsize=8)
            if j == 0:
                ax.set_ylabel(label)
            if i == len(signals) - 1:
                ax.set_xlabel("time [s]")
            if i == 0 and j == 0:
                ax.legend(fontsize=6)
    fig.suptitle(f"Time histories over {len({r['sample'] for r in rows})} samples (dashed: t_max)", fontsize=10)
    return save_figure(fig, out / "envelopes.png")


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
