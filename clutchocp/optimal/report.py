"""``clutchocp optimize``: the optimal engagement pressure of a scene, verified, compared and written out.

The workflow of the command: its steps (solve, verify, compare, continue to the clamp pressure), the
summary and the files; the figures are :mod:`clutchocp.optimal.figures`.
"""

import time
from pathlib import Path

import numpy as np

from ..engagement.report import plot_heat, write_timeseries
from ..errors import ClutchocpError, SolverError
from ..output import shown, write_csv, write_summary, writes_folder
from ..scene import default_scene, load_scene
from .baselines import baseline_label, simulate_baselines, tune_fill_pulse
from .bound import jerk_lower_bound
from .clamp import DEFAULT_MARGIN, check_margin, extend_to_clamp
from .figures import plot_fill_comparison, plot_optimum, plot_pareto, plot_piston, result_figure
from .heat import heat_check
from .mesh import solve_verified
from .outcome import OptimizationResult, format_quantity, profile_columns
from .problem import EngagementOCP
from .replay import simulate_command
from .verify import holding_pressure, run_numbers, verify

KEYS = ("engagement_time_s", "lockup_torque_jump_Nm", "jerk_integral", "dissipated_energy_J", "peak_jerk_rad_s3",
        "peak_torque_Nm")
COMPARE_KEYS = KEYS + ("locked_torque_Nm", "kiss_time_s", "kiss_speed_m_s", "kiss_jerk_rad_s3", "min_film_pressure_Pa")
# Minimum engagement time (a little command smoothing keeps the command regular).
FAST_WEIGHTS = {"jerk": 0.0, "time": 1.0, "smooth": 0.01}


CLAMP_SETTLE_S = 0.3       # the whole-curve replay runs this long after the clamp ramp ends


@writes_folder
def run_optimize(scene=None, out_dir="out/optimize", t_max=None, weights=None, intervals=100, degree=3,
                 sweep_t_max=None, progress=True, max_temperature_C=None, max_specific_power_W_mm2=None,
                 clamp_margin=None):
    """Optimal engagement pressure of a scene: solve, verify with IDAS, compare, write files.

    Parameters
    ----------
    scene : clutchocp.scene.Scene, str or pathlib.Path, optional
        Scene, built-in scene name or file (default: the default scene).
    out_dir : str or pathlib.Path
        Output folder (created): pressure_profile.csv, timeseries.csv (the IDAS replay of the optimum, the
        columns of the simulate command), summary.json, PNG figures.
    t_max : float, optional
        Largest engagement time [s] (default: the scene's ``actuation.engagement_time_limit``, else the
        lock-up time of the scene's own profile;
        ``numpy.inf``: none, then weight the time or the energy).
    weights : dict, optional
        Objective weights (jerk, energy, time, jump, smooth); see ``clutchocp.optimal.problem``.
    intervals, degree : int
        Collocation intervals and points per interval.
    sweep_t_max : sequence of float, optional
        Engagement-time limits [s] for the jerk / engagement-time trade-off (warm-started solves;
        adds ``sweep`` to the summary and pareto.png).
    progress : bool
        Print progress lines (stages, sweep points) and the summary.
    max_temperature_C, max_specific_power_W_mm2 : float, optional
        Heat limits of the slip phase (see :mod:`clutchocp.optimal.heat`); adds ``heat`` to the summary.
    clamp_margin : float, optional
        Static torque capacity at the clamp pressure over the locked torque (>= 1): after lock-up
        the command ramps at the rate limit to that clamp pressure and holds it
        (:mod:`clutchocp.optimal.clamp`); pressure_profile.csv holds the whole curve. Default:
        ``DEFAULT_MARGIN`` (1.3), or the largest margin the pack holds if that is less (a margin given
        that the pack cannot hold is refused before solving).

    Returns
    -------
    dict
        The summary written to summary.json, plus ``files`` (the paths written).

    Raises
    ------
    ModelError, SolverError
        Infeasible limits, bad weights, a scene the optimisation does not cover, IPOPT failure.
    """
    say = print if progress else (lambda *a, **k: None)
    result = optimize_scene(scene, t_max=t_max, weights=weights, intervals=intervals, degree=degree,
                            sweep_t_max=sweep_t_max, progress=progress, max_temperature_C=max_temperature_C,
                            max_specific_power_W_mm2=max_specific_power_W_mm2, clamp_margin=clamp_margin)
    summary, scene, ocp, opt, replay = result.summary, result.scene, result.ocp, result.optimum, result.replay
    out = Path(out_dir)
    # the IDAS replay of the optimum, with the columns of the simulate command's time series
    files = [_write_profile(out, result), write_timeseries(replay, out / "timeseries.csv"),
             write_summary(out / "summary.json", summary)]
    files += plot_optimum(out, scene, opt, replay, ocp.baseline, result.baselines, summary, result.curve,
                          result.clamp_run)
    files.append(plot_heat(replay, out / "heat.png", max_temperature_C=max_temperature_C,
                           max_specific_power_W_mm2=max_specific_power_W_mm2, what="the IDAS replay of the optimum"))
    if ocp.model.has_piston:
        files.append(plot_piston(out, scene, replay, ocp.baseline))
    if result.fill is not None:
        files.append(plot_fill_comparison(out, scene, result.fill))
    if "sweep" in summary:
        files.append(plot_pareto(out, scene, summary["sweep"], summary["initial_slip_rad_s"],
                                 summary["initial_slip_rate_rad_s2"], ocp))
    summary["files"] = [shown(f) for f in files]
    say(format_summary(summary))
    return summary


def optimize_scene(scene=None, *, t_max=None, weights=None, intervals=100, degree=3, sweep_t_max=None,
                   progress=False, max_temperature_C=None, max_specific_power_W_mm2=None, clamp_margin=None):
    """Solve, verify with IDAS and compare with the baselines, without writing files.

    Parameters are those of :func:`run_optimize` (``scene`` may also be a name or a path).

    Returns
    -------
    clutchocp.optimal.outcome.OptimizationResult
        ``summary`` (as written to summary.json), the problem, the optimum, its IDAS replay and
        the baseline runs; ``table()`` and ``plot()`` for a look.
    """
    say = print if progress else (lambda *a, **k: None)
    margin_given = clamp_margin is not None
    clamp_margin = check_margin(clamp_margin if margin_given else DEFAULT_MARGIN)   # a bad margin fails before the solve
    if scene is None:
        scene = default_scene()
    elif isinstance(scene, (str, Path)):
        scene = load_scene(scene)
    start = time.perf_counter()
    say(f"optimize {scene.name}: building the collocation problem ({intervals} intervals, degree {degree})")
    ocp = EngagementOCP(scene, intervals=intervals, degree=degree, max_temperature_C=max_temperature_C,
                        max_specific_power_W_mm2=max_specific_power_W_mm2)
    build_time = time.perf_counter() - start
    if ocp.baseline_note:
        say(f"  {ocp.baseline_note}")
    if ocp.holds_torque:          # the clamp after lock-up must be within reach before a solve is spent
        clamp_margin = _reachable_margin(ocp, clamp_margin, margin_given, say)
    command_model = ocp.models.replay(ocp.transcription.control)
    solved = solve_verified(ocp, t_max=t_max, weights=weights, command_model=command_model, say=say)
    ocp, opt, check, replay = solved["ocp"], solved["optimum"], solved["check"], solved["replay"]
    graded = sum(h["stage"] == "graded mesh" and "failed" not in h for h in solved["history"])
    say(f"  optimum found: {opt.stats['iterations']} iterations, {opt.stats['wall_time_s']:.2f} s"
        + (f" (after {graded} mesh refinement(s))" if graded else ""))
    say(f"  IDAS re-simulation: lock-up {format_quantity(check['idas']['engagement_time_s'], 's')}, "
        f"jump {format_quantity(check['torque_jump_Nm'], 'N m')}")
    # the calibration shape "fill pulse, hold, ramp" is that of a pressure-applied piston
    fill = _fill_comparison(ocp, opt, check, command_model, intervals, degree, say) \
        if len(opt.phases) > 1 and not ocp.spring_applied else None
    if fill is not None and "failed" in fill:
        say(f"  fill-pulse comparison left out: {fill['failed']}")
    curve, whole = _clamp_curve(scene, ocp, opt, command_model, clamp_margin)
    say(f"  after lock-up: ramp to the clamp pressure {curve.clamp_pressure_Pa / 1e6:.4g} MPa by "
        f"{curve.ramp_end_s:.4g} s ({curve.basis}); lock held in the IDAS replay: {whole['lock_held']}")
    baselines = simulate_baselines(ocp.baseline_scene)
    w_rel0, rate0 = ocp.initial_slip()
    bound = jerk_lower_bound(w_rel0, rate0, opt.t_f)
    sweep = _sweep(ocp, opt, sorted(sweep_t_max), weights, say) if sweep_t_max is not None and len(sweep_t_max) else None

    summary = {
        "scene": scene.name,
        "optimal": {k: opt.terms[k] for k in KEYS + ("slip_jerk_integral", "min_film_pressure_Pa")},
        "film_cavitation_pressure_Pa": ocp.model.film.cavitation_pressure,
        "baseline": dict(run_numbers(ocp.baseline), profile=baseline_label(ocp.baseline_scene),
                         **({"note": ocp.baseline_note} if ocp.baseline_note else {})),
        "baselines": {name: numbers for name, (_, numbers) in baselines.items()},
        "verification": {k: check[k] for k in ("lock_time_rel_diff", "lock_time_resolution_s", "torque_jump_Nm",
                                              "jump_reference_Nm",
                                              "torque_jump_rel", "passed", "holding_pressure_Pa", "collocation",
                                              "idas")},
        # the bound on the same basis as optimal.jerk_integral (output jerk; the slip jerk's bound
        # times the output's share squared), and the slip-jerk bound the ratio is taken against
        "jerk_lower_bound": bound * ocp.output_jerk_share**2,
        "slip_jerk_lower_bound": bound,
        "jerk_lower_bound_ratio": opt.terms["slip_jerk_integral"] / bound,
        "initial_slip_rad_s": w_rel0,
        "initial_slip_rate_rad_s2": rate0,
        "limits": {"t_max_s": opt.t_max if np.isfinite(opt.t_max) else None,
                   "t_max_source": solved["strategy"]["solve"]["t_max_source"], "e_max_J": opt.e_max,
                   "max_pressure_Pa": ocp.p_max,
                   "rate_limit_Pa_s": ocp.rate_limit if np.isfinite(ocp.rate_limit) else None,
                   "lock_margin": ocp.lock_margin},
        "weights": opt.weights,
        "phases": [{k: ph[k] for k in ("name", "mode", "t_start_s", "t_end_s", "intervals")} for ph in opt.phases],
        "mesh": {"refinements": sum(h["stage"] == "graded mesh" and "failed" not in h for h in solved["history"]),
                 "solves": solved["history"]},
        "lockup_definition": _lockup_definition(ocp),
        "clamp": {k: v for k, v in whole.items() if k != "run"},
        "solver": {"status": opt.stats["status"], "iterations": opt.stats["iterations"],
                   "wall_time_s": opt.stats["wall_time_s"], "build_time_s": build_time,
                   "intervals": intervals, "degree": degree, "scheme": ocp.transcription.scheme,
                   "control": opt.control, "n_variables": opt.stats["n_variables"],
                   "stages": [{k: s[k] for k in ("model", "status", "iterations", "wall_time_s", "warm_start")}
                              for s in opt.stats["stages"]],
                   "attempts": {name: how["attempts"] for name, how in solved["strategy"].items()}},
    }
    summary["heat"] = heat_check(ocp, opt, replay)
    if "fill_time_s" in opt.terms:
        summary["optimal"].update(fill_time_s=opt.terms["fill_time_s"], kiss_speed_m_s=opt.terms["kiss_speed_m_s"])
    if sweep is not None:
        summary["sweep"] = sweep
    if fill is not None:
        summary["fill_comparison"] = fill["summary"]
    if fill is not None and "failed" in fill:
        fill = None
    return OptimizationResult(scene, summary, ocp, opt, replay, baselines, fill=fill, curve=curve,
                              clamp_run=whole["run"], figure=result_figure)


def _reachable_margin(ocp, margin, given, say):
    """The clamp margin to use: ``margin`` if the pack can hold it; a default one lowered to the most the
    pack holds (said in a progress line); a given one refused (ModelError, with the largest it can be)."""
    clamp = ocp.models.clamp()
    if given:
        clamp.clamp_pressure(margin)
        return margin
    largest = clamp.largest_margin()
    if largest >= margin:
        return margin
    lowered = np.floor(largest * 1000) / 1000
    say(f"  clamp: the pack holds at most {largest:.4g} x the locked torque; the clamp margin is {lowered:g} "
        f"instead of {margin:g}")
    return check_margin(lowered)


def _lockup_definition(ocp):
    """How lock-up and its jump are defined for this scene (one line for summary.json)."""
    if ocp.holds_torque:
        return "lock-up: w_in = w_out; jump = locked torque - slipping torque at that instant"
    side = "the input comes to rest (output held: a brake)" if ocp.output_held else "w_out reaches w_in"
    return (f"lock-up: {side}; the locked clutch carries no torque, so the jump is the torque step at that "
            f"instant (minus the slipping torque before it), measured against the peak slipping torque")


def _fill_comparison(ocp, opt, check, command_model, intervals, degree, say):
    """The minimum-time optimum against the tuned "fill pulse, hold, ramp" at equal peak jerk.

    The baseline is tuned (:func:`tune_fill_pulse`) to lock up soonest with its peak jerk (the jerk
    just after the kiss included) within the peak jerk of the main optimum's slip phase at its
    collocation points and its lock-up jump within the verification tolerance;
    the optimum is then re-solved for minimum engagement time with |jerk| <= the baseline's peak
    jerk (warm start from the main optimum) and verified with IDAS.
    """
    felt = "slip_jerk_rad_s3" if ocp.output_held else "output_jerk_rad_s3"
    first_slip_interval = sum(ph["intervals"] for ph in opt.phases[:-1])
    cap = float(np.max(np.abs(opt.outputs_points[felt][first_slip_interval:])))
    say(f"  fill-pulse baseline: tuning for the shortest lock-up with peak jerk <= {cap:.4g} rad/s^3 "
        f"(the main optimum's slip-phase peak; the jerk just after the kiss included)")
    tuned = tune_fill_pulse(ocp.scene, jerk_cap=cap, p_max=ocp.p_max, rate_limit=ocp.rate_limit,
                            t_scale=ocp.scales.time_s, progress=say, model=ocp.models.replay("linear"))
    base = tuned["numbers"]
    # 0.1 % below the baseline's peak: IDAS samples between the collocation points see a little more
    jerk_max = 0.999 * min(base["peak_jerk_rad_s3"] or cap, cap)
    fast_ocp = EngagementOCP(ocp.scene, intervals=intervals, degree=degree, jerk_max=jerk_max, baseline=ocp.baseline,
                             models=ocp.models)
    say(f"  minimum-time optimum with |jerk| <= {jerk_max:.4g} rad/s^3")
    try:
        fast = fast_ocp.solve(t_max=opt.t_max, weights=FAST_WEIGHTS, guess=opt)
    except SolverError as exc:       # a comparison, not the optimum: the optimize result stands without it
        return {"failed": str(exc), "summary": {"failed": str(exc)}, "baseline": tuned}
    fast_check, fast_run = verify(fast_ocp.exact, fast, model=command_model)
    numbers = fast_check["idas"]
    summary = {
        "jerk_cap_rad_s3": jerk_max,
        "weights": fast.weights,
        "optimal": {k: numbers[k] for k in COMPARE_KEYS},
        "optimal_verification_passed": fast_check["passed"],
        "baseline": {k: base[k] for k in COMPARE_KEYS},
        "baseline_parameters": tuned["parameters"],
        "baseline_evaluations": tuned["evaluations"],
        "optimal_faster": bool(base["engagement_time_s"] is None
                               or numbers["engagement_time_s"] < base["engagement_time_s"]),
    }
    say(f"  minimum time: {format_quantity(numbers['engagement_time_s'], 's')} "
        f"(kiss speed {format_quantity(numbers['kiss_speed_m_s'], 'm/s')}) "
        f"against the tuned fill pulse {format_quantity(base['engagement_time_s'], 's')} "
        f"(kiss speed {format_quantity(base['kiss_speed_m_s'], 'm/s')})")
    return {"summary": summary, "optimal_run": fast_run, "baseline_run": tuned["run"], "baseline": tuned}


def _clamp_curve(scene, ocp, opt, command_model, margin):
    """The optimal command continued by the ramp to the clamp pressure, and its IDAS replay.

    Returns
    -------
    (ClampedCommand, dict)
        The curve and the summary entry ``clamp`` (with the replay run under ``run``).
    """
    rate = ocp.rate_limit if np.isfinite(ocp.rate_limit) else None
    # a lock that carries no torque (brake, unloaded prescribed input) has no capacity to size a clamp
    # by: the command goes to the holding pressure of the verification (the larger of the last command
    # and the scene's set pressure; the smaller for a spring-applied piston)
    given = None if ocp.holds_torque else holding_pressure(ocp, opt)
    curve = extend_to_clamp(scene, opt.command_times, opt.command, opt.t_f, margin=margin, rate_limit=rate,
                            clamp_pressure=given, model=ocp.models.clamp() if given is None else None)
    t_end = curve.ramp_end_s + CLAMP_SETTLE_S
    run = simulate_command(scene, curve.times, curve.pressures, t_end, model=command_model, control="linear",
                           points=601)
    lock = [e.t for e in run.result.events if e.name == "lockup"]
    unlock = [e.t for e in run.result.events if e.name == "unlock"]
    torque = run.result["total_torque_Nm"][-1]
    entry = {"margin": curve.margin, "clamp_pressure_Pa": curve.clamp_pressure_Pa,
             "locked_torque_Nm": curve.locked_torque_Nm, "ramp_start_s": curve.ramp_start_s,
             "ramp_end_s": curve.ramp_end_s, "rate_limit_Pa_s": curve.rate_limit_Pa_s,
             "replay_end_s": t_end, "lock_time_s": lock[0] if lock else None,
             "lock_held": bool(lock) and not unlock,
             "capacity_margin_at_end": float(run.result["static_capacity_Nm"][-1] / torque)
             if lock and abs(torque) > 1e-9 else None,
             "run": run}
    return curve, entry


def _sweep(ocp, opt, values, weights, say):
    """Solve for each t_max, warm-starting each from its neighbour nearest the main optimum."""
    results = {}
    above = [v for v in values if v >= opt.t_max]
    below = [v for v in values if v < opt.t_max][::-1]
    total, done = len(values), 0
    for chain in (above, below):
        guess = opt
        for t_max in chain:
            done += 1
            try:
                res = ocp.solve(t_max=t_max, weights=weights, guess=guess)
            except ClutchocpError as exc:
                results[t_max] = {"t_max_s": t_max, "status": "failed", "message": str(exc)}
                say(f"  sweep [{done}/{total}] t_max = {t_max:.4g} s: {exc}")
                continue
            guess = res
            results[t_max] = {"t_max_s": t_max, "status": res.stats["status"],
                              "iterations": res.stats["iterations"], "wall_time_s": res.stats["wall_time_s"],
                              **{k: res.terms[k] for k in KEYS + ("slip_jerk_integral", "min_film_pressure_Pa")}}
            say(f"  sweep [{done}/{total}] t_max = {t_max:.4g} s: jerk integral {res.terms['jerk_integral']:.4g} "
                f"rad^2/s^5, energy {res.terms['dissipated_energy_J']:.4g} J ({res.stats['iterations']} iterations, "
                f"{res.stats['wall_time_s']:.2f} s)")
    return [results[v] for v in values]


def _write_profile(out, result):
    """pressure_profile.csv: the whole usable command, engagement and clamp [s, Pa, Pa]
    (columns: :func:`~clutchocp.optimal.outcome.profile_columns`)."""
    return write_csv(out / "pressure_profile.csv", profile_columns(result.optimum, result.curve, result.clamp_run))


def format_summary(summary):
    """A few lines for the terminal."""
    opt, base, ver = summary["optimal"], summary["baseline"], summary["verification"]
    lines = [(f"scene {summary['scene']}: optimal engagement pressure ({summary['solver']['status']}, "
              f"{summary['solver']['iterations']} iterations, {summary['solver']['wall_time_s']:.2f} s)"),
             f"  {'':28s} {'optimal':>12s} {'baseline':>12s}"]
    for key, label, unit in (("engagement_time_s", "engagement time", "s"),
                             ("lockup_torque_jump_Nm", "lock-up torque jump", "N m"),
                             ("jerk_integral", "int jerk^2 dt", "rad^2/s^5"),
                             ("peak_jerk_rad_s3", "peak jerk", "rad/s^3"),
                             ("dissipated_energy_J", "dissipated energy", "J")):
        lines.append(f"  {label + ' [' + unit + ']':28s} {_num(opt[key]):>12s} {_num(base[key]):>12s}")
    lines.append(f"  baseline: {base['profile']}")
    lines.append(f"  IDAS check: lock-up {_num(ver['idas']['engagement_time_s'])} s "
                 f"(rel. diff {_num(ver['lock_time_rel_diff'])}), jump {_num(ver['torque_jump_Nm'])} N m "
                 f"-> {'passed' if ver['passed'] else 'FAILED'}")
    lines.append(f"  jerk integral / kinematic lower bound: {summary['jerk_lower_bound_ratio']:.3g}")
    lines.append(f"  lowest mean film pressure: {_num(opt['min_film_pressure_Pa'])} Pa (IDAS "
                 f"{_num(ver['idas']['min_film_pressure_Pa'])} Pa, film {ver['idas']['min_film_pressure_film']}; "
                 f"cavitation at {summary['film_cavitation_pressure_Pa']:.4g} Pa)")
    heat = summary.get("heat")
    if heat is not None and "peak_interface_temperature_C" in heat["idas"]:
        lines.append(f"  peak interface temperature: {heat['collocation']['peak_interface_temperature_C']:.2f} degC "
                     f"(IDAS {heat['idas']['peak_interface_temperature_C']:.2f} degC)")
    return "\n".join(lines)


def _num(value):
    return "none" if value is None else f"{value:.4g}"
