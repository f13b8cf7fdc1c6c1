"""``clutchocp optimize``: the optimal engagement pressure of a scene, verified, compared and written out."""

import time
from pathlib import Path

import numpy as np

from ..engagement.report import plot_heat
from ..errors import ClutchocpError, ModelError
from ..output import new_figure, save_figure, shown, write_csv, write_summary, writes_folder
from ..scene import default_scene, load_scene
from .baselines import baseline_label, simulate_baselines, tune_fill_pulse
from .outcome import OptimizationResult
from .bound import jerk_lower_bound
from .heat import heat_check
from .clamp import DEFAULT_MARGIN, check_margin, extend_to_clamp
from .problem import EngagementOCP
from .mesh import solve_verified
from .replay import CommandModel, simulate_command
from .verify import holding_pressure, run_numbers, verify

KEYS = ("engagement_time_s", "lockup_torque_jump_Nm", "jerk_integral", "dissipated_energy_J", "peak_jerk_rad_s3",
        "peak_torque_Nm")
COMPARE_KEYS = KEYS + ("locked_torque_Nm", "kiss_time_s", "kiss_speed_m_s", "kiss_jerk_rad_s3")
# Minimum engagement time (a little command smoothing keeps the command regular).
FAST_WEIGHTS = {"jerk": 0.0, "time": 1.0, "smooth": 0.01}


CLAMP_SETTLE_S = 0.3       # the whole-curve replay runs this long after the clamp ramp ends


@writes_folder
def run_optimize(scene=None, out_dir="out/optimize", t_max=None, weights=None, intervals=100, degree=3,
                 sweep_t_max=None, progress=True, max_temperature_C=None, max_specific_power_W_mm2=None,
                 clamp_margin=DEFAULT_MARGIN):
    """Optimal engagement pressure of a scene: solve, verify with IDAS, compare, write files.

    Parameters
    ----------
    scene : clutchocp.scene.Scene, str or pathlib.Path, optional
        Scene, built-in scene name or file (default: the default scene).
    out_dir : str or pathlib.Path
        Output folder (created): pressure_profile.csv, summary.json, PNG figures.
    t_max : float, optional
        Largest engagement time [s] (default: the lock-up time of the scene's own profile;
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
    clamp_margin : float
        Static torque capacity at the clamp pressure over the locked torque (>= 1): after lock-up
        the command ramps at the rate limit to that clamp pressure and holds it
        (:mod:`clutchocp.optimal.clamp`); pressure_profile.csv holds the whole curve.

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
    files = [_write_profile(out, result), write_summary(out / "summary.json", summary)]
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
                   progress=False, max_temperature_C=None, max_specific_power_W_mm2=None, clamp_margin=DEFAULT_MARGIN):
    """Solve, verify with IDAS and compare with the baselines, without writing files.

    Parameters are those of :func:`run_optimize` (``scene`` may also be a name or a path).

    Returns
    -------
    clutchocp.optimal.outcome.OptimizationResult
        ``summary`` (as written to summary.json), the problem, the optimum, its IDAS replay and
        the baseline runs; ``table()`` and ``plot()`` for a look.
    """
    say = print if progress else (lambda *a, **k: None)
    clamp_margin = check_margin(clamp_margin)          # a bad margin fails before the solve
    if scene is None:
        scene = default_scene()
    elif isinstance(scene, (str, Path)):
        scene = load_scene(scene)
    start = time.perf_counter()
    say(f"optimize {scene.name}: building the collocation problem ({intervals} intervals, degree {degree})")
    ocp = EngagementOCP(scene, intervals=intervals, degree=degree, max_temperature_C=max_temperature_C,
                        max_specific_power_W_mm2=max_specific_power_W_mm2)
    build_time = time.perf_counter() - start
    command_model = CommandModel(scene, ocp.transcription.control)
    solved = solve_verified(ocp, t_max=t_max, weights=weights, command_model=command_model, say=say)
    ocp, opt, check, replay = solved["ocp"], solved["optimum"], solved["check"], solved["replay"]
    graded = sum(h["stage"] == "graded mesh" and "failed" not in h for h in solved["history"])
    say(f"  IPOPT {opt.stats['status']}: {opt.stats['iterations']} iterations, {opt.stats['wall_time_s']:.2f} s"
        + (f" (after {graded} mesh refinement(s))" if graded else ""))
    say(f"  IDAS re-simulation: lock-up {_fmt(check['idas']['engagement_time_s'], 's')}, "
        f"jump {_fmt(check['torque_jump_Nm'], 'N m')}")
    # the calibration shape "fill pulse, hold, ramp" is that of a pressure-applied piston
    fill = _fill_comparison(ocp, opt, check, command_model, intervals, degree, say) \
        if len(opt.phases) > 1 and ocp.apply_pressure > 0 else None
    curve, whole = _clamp_curve(scene, ocp, opt, command_model, clamp_margin)
    say(f"  after lock-up: ramp to the clamp pressure {curve.clamp_pressure_Pa / 1e6:.4g} MPa by "
        f"{curve.ramp_end_s:.4g} s ({_clamp_basis(curve)}); lock held in the IDAS replay: {whole['lock_held']}")
    baselines = simulate_baselines(scene)
    w_rel0, rate0 = ocp.initial_slip()
    bound = jerk_lower_bound(w_rel0, rate0, opt.t_f)
    sweep = _sweep(ocp, opt, sorted(sweep_t_max), weights, say) if sweep_t_max is not None and len(sweep_t_max) else None

    summary = {
        "scene": scene.name,
        "optimal": {k: opt.terms[k] for k in KEYS + ("slip_jerk_integral",)},
        "baseline": dict(run_numbers(ocp.baseline), profile=baseline_label(scene)),
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
        "limits": {"t_max_s": opt.t_max if np.isfinite(opt.t_max) else None, "e_max_J": opt.e_max,
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
                              for s in opt.stats["stages"]]},
    }
    summary["heat"] = heat_check(ocp, opt, replay)
    if "fill_time_s" in opt.terms:
        summary["optimal"].update(fill_time_s=opt.terms["fill_time_s"], kiss_speed_m_s=opt.terms["kiss_speed_m_s"])
    if sweep is not None:
        summary["sweep"] = sweep
    if fill is not None:
        summary["fill_comparison"] = fill["summary"]
    return OptimizationResult(scene, summary, ocp, opt, replay, baselines, fill=fill, curve=curve,
                              clamp_run=whole["run"])


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
                            t_scale=ocp.scales.time_s, progress=say)
    base = tuned["numbers"]
    # 0.1 % below the baseline's peak: IDAS samples between the collocation points see a little more
    jerk_max = 0.999 * min(base["peak_jerk_rad_s3"] or cap, cap)
    fast_ocp = EngagementOCP(ocp.scene, intervals=intervals, degree=degree, jerk_max=jerk_max, baseline=ocp.baseline)
    say(f"  minimum-time optimum with |jerk| <= {jerk_max:.4g} rad/s^3")
    fast = fast_ocp.solve(weights=FAST_WEIGHTS, guess=opt)
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
    say(f"  minimum time: {_fmt(numbers['engagement_time_s'], 's')} "
        f"(kiss speed {_fmt(numbers['kiss_speed_m_s'], 'm/s')}) "
        f"against the tuned fill pulse {_fmt(base['engagement_time_s'], 's')} "
        f"(kiss speed {_fmt(base['kiss_speed_m_s'], 'm/s')})")
    return {"summary": summary, "optimal_run": fast_run, "baseline_run": tuned["run"], "baseline": tuned}


def _public(summary):
    """The summary without the replay run object (kept for the CSV and the figures)."""
    out = dict(summary)
    out["clamp"] = {k: v for k, v in summary["clamp"].items() if k != "run"}
    return out


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
                            clamp_pressure=given)
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


def _clamp_basis(curve):
    """How the clamp pressure was chosen (for progress lines and legends)."""
    if curve.margin is None:
        return "holding pressure: the lock carries no torque"
    return f"capacity {curve.margin:g} x the locked torque"


def _fmt(value, unit, fmt="{:.4g}"):
    return "none" if value is None else f"{fmt.format(value)} {unit}"


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
                              **{k: res.terms[k] for k in KEYS + ("slip_jerk_integral",)}}
            say(f"  sweep [{done}/{total}] t_max = {t_max:.4g} s: jerk integral {res.terms['jerk_integral']:.4g} "
                f"rad^2/s^5, energy {res.terms['dissipated_energy_J']:.4g} J ({res.stats['iterations']} iterations, "
                f"{res.stats['wall_time_s']:.2f} s)")
    return [results[v] for v in values]


def _write_profile(out, result):
    """pressure_profile.csv: the whole usable command, engagement and clamp [s, Pa, Pa].

    Rows are the nodes of the piecewise-linear command: ``to_next`` says how the command goes on
    to the next row ("linear") or after the last one ("hold": constant). ``phase`` names the
    segment a row starts: "engagement" before lock-up, "clamp_ramp" from the lock-up row,
    "clamp_hold" on the last row. ``pressure_Pa`` is the
    pressure the collocation predicts up to lock-up and the IDAS replay of the whole curve after it.
    """
    return write_csv(out / "pressure_profile.csv", profile_columns(result.optimum, result.curve, result.clamp_run))


def profile_columns(opt, curve, run):
    """The columns of pressure_profile.csv (see :func:`_write_profile`): {name with unit: array}."""
    times, command = curve.times, curve.pressures
    engaged = times <= opt.t_f
    pressure = np.where(engaged, np.interp(times, opt.t, opt.outputs["pressure_Pa"]),
                        np.interp(times, run.result.t, run.result["pressure_Pa"]))
    phase = np.where(times < opt.t_f, "engagement", "clamp_ramp").astype(object)   # the segment a row starts
    if times[-1] > opt.t_f:
        phase[-1] = "clamp_hold"
    to_next = ["linear"] * (times.size - 1) + ["hold"]
    return {"time_s": times, "pressure_command_Pa": command, "pressure_Pa": pressure,
            "phase": list(phase), "to_next": to_next}


def _slip(run):
    res = run.result
    t_lock = run.summary["engagement_time_s"]
    return res.t, (res.t <= t_lock) if t_lock is not None else np.ones(res.t.size, bool)


def plot_optimum(out, scene, opt, replay, baseline, baselines, summary, curve=None, clamp_run=None):
    """Pressure, torque, speeds and jerk of the optimum (IDAS replay) against the baseline; baselines bar chart."""
    files = []
    name = scene.name
    runs = (("optimal (IDAS replay)", replay, "C0"), (f"baseline ({summary['baseline']['profile']})", baseline, "C3"))
    files.append(save_figure(pressure_figure(scene, opt, replay, baseline, summary, curve, clamp_run),
                             out / "pressure.png"))

    for key, ylabel, fname, title in (("total_torque_Nm", "clutch torque [N m]", "torque.png", "clutch torque"),
                                      ("output_jerk_rad_s3", "output jerk [rad/s^3]", "jerk.png", "output jerk")):
        fig, (ax,) = new_figure()
        for label, run, color in runs:
            t, slip = _slip(run)
            values = run.result[key]
            ax.plot(t if key != "output_jerk_rad_s3" else t[slip],
                    values if key != "output_jerk_rad_s3" else values[slip], color=color, label=label)
        ax.set(xlabel="time [s]", ylabel=ylabel, title=f"{name}: {title}")
        _locks(ax, runs)
        ax.legend(fontsize=8)
        files.append(save_figure(fig, out / fname))

    fig, (ax,) = new_figure()
    for label, run, color in runs:
        ax.plot(run.result.t, run.result["w_in_rad_s"], color=color, label=f"{label}: input")
        ax.plot(run.result.t, run.result["w_out_rad_s"], color=color, ls="--", label=f"{label}: output")
    ax.set(xlabel="time [s]", ylabel="speed [rad/s]", title=f"{name}: speeds")
    _locks(ax, runs)
    ax.legend(fontsize=7)
    files.append(save_figure(fig, out / "speeds.png"))

    w_rel0, rate0 = summary["initial_slip_rad_s"], summary["initial_slip_rate_rad_s2"]
    share = summary["jerk_lower_bound"] / summary["slip_jerk_lower_bound"] if summary["slip_jerk_lower_bound"] else 0.0
    files.append(plot_baselines(out, name, summary, baselines, lambda T: jerk_lower_bound(w_rel0, rate0, T) * share))
    return files


def pressure_figure(scene, opt, replay, baseline, summary, curve=None, clamp_run=None):
    """The optimal command (and its continuation after lock-up, ``curve``), its IDAS replay (after
    lock-up: the replay of the whole curve, ``clamp_run``), the collocation points and the baseline's
    pressure."""
    runs = (("optimal (IDAS replay)", replay, "C0"), (f"baseline ({summary['baseline']['profile']})", baseline, "C3"))
    fig, (ax,) = new_figure()
    if opt.control == "constant":
        ax.step(np.append(opt.command_times, opt.t_f), np.append(opt.command, opt.command[-1]) / 1e6,
                where="post", color="C0", lw=0.8, alpha=0.6, label="optimal command")
    else:
        ax.plot(opt.command_times, opt.command / 1e6, color="C0", lw=0.8, alpha=0.6, label="optimal command")
    if curve is not None:       # the command after lock-up: ramp to the clamp pressure, then hold it
        after = curve.times >= opt.t_f
        t_hold = max(curve.times[-1], max(run.result.t[-1] for _, run, _ in runs))
        ax.plot(np.append(curve.times[after], t_hold), np.append(curve.pressures[after], curve.pressures[-1]) / 1e6,
                color="C2", lw=1.2, ls="--",
                label=f"command after lock-up: ramp to clamp ({_clamp_basis(curve)})")
    for label, run, color in runs:
        t, p = run.result.t, run.result["pressure_Pa"]
        if run is replay and clamp_run is not None:       # the curve a user applies, not the check's hold
            t_lock = run.summary["engagement_time_s"] or t[-1]
            t = np.concatenate([t[t <= t_lock], clamp_run.result.t[clamp_run.result.t > t_lock]])
            p = np.concatenate([p[run.result.t <= t_lock], clamp_run.result["pressure_Pa"][clamp_run.result.t > t_lock]])
        ax.plot(t, p / 1e6, color=color, label=label)
    ax.plot(opt.t, opt.outputs["pressure_Pa"] / 1e6, ".", color="C0", ms=2, label="collocation")
    ax.set(xlabel="time [s]", ylabel="pressure [MPa]", title=f"{scene.name}: engagement pressure")
    _locks(ax, runs)
    ax.legend(fontsize=8)
    return fig


def plot_baselines(out, name, summary, baselines, bound_at):
    """baselines.png: lock-up jumps, and jerk integrals against engagement time with the kinematic bound.

    ``bound_at(T)``: the kinematic lower bound of the output jerk integral for engagement time T [s].

    The jerk integral falls steeply with the engagement time (the bound ~ 1/T^3), so a slower
    profile can have less jerk than the optimum for a shorter time limit; the right panel therefore
    draws each profile at its own engagement time, beside the lower bound for every time.
    """
    fig, (ax1, ax2) = new_figure(2, width=5.2)
    labels = ["optimal"] + list(baselines)
    numbers = [dict(summary["optimal"], lockup_torque_jump_Nm=summary["verification"]["torque_jump_Nm"])] + \
        [n for _, n in baselines.values()]
    times = [n["engagement_time_s"] for n in numbers]
    jumps = [abs(n["lockup_torque_jump_Nm"] or 0.0) for n in numbers]
    colors = ["C0"] + ["C3"] * len(baselines)
    bars = ax1.bar(labels, jumps, color=colors)
    for bar, t_lock in zip(bars, times):
        ax1.annotate("never" if t_lock is None else f"{t_lock:.3g} s", (bar.get_x() + bar.get_width() / 2,
                     bar.get_height()), ha="center", va="bottom", fontsize=6)
    ax1.set(ylabel="|lock-up torque jump| [N m]", title="torque jump at lock-up (label: lock-up time)")
    ax1.tick_params(axis="x", labelrotation=60, labelsize=7)
    ok = [(t, n["jerk_integral"], lab) for t, n, lab in zip(times, numbers, labels)
          if t is not None and n["jerk_integral"] is not None]
    for t_lock, jerk, label in ok:
        is_opt = label == "optimal"
        ax2.plot(t_lock, jerk, "*" if is_opt else "o", color="C0" if is_opt else "C3", ms=12 if is_opt else 6)
        ax2.annotate(label, (t_lock, jerk), textcoords="offset points", xytext=(4, 3), fontsize=7)
    if ok:
        grid = np.linspace(0.8 * min(t for t, _, _ in ok), 1.2 * max(t for t, _, _ in ok), 200)
        bound = [bound_at(T) for T in grid]
        if max(bound) > 0:
            ax2.plot(grid, bound, "k--", lw=0.8, label="kinematic lower bound (same engagement time)")
        ax2.plot([], [], "*", color="C0", ms=10, label="optimal")
        ax2.plot([], [], "o", color="C3", label="baseline profiles")
        ax2.legend(fontsize=7)
    ax2.set(xlabel="engagement (lock-up) time [s]", ylabel="int jerk^2 dt, slip phase [rad^2/s^5]", yscale="log",
            title=f"{name}: jerk against engagement time")
    ax2.grid(alpha=0.3, which="both")
    return save_figure(fig, out / "baselines.png")


def plot_piston(out, scene, replay, baseline):
    """Piston travel, speed and spring force of the optimum (IDAS replay) and the scene's own profile."""
    fig, (ax1, ax2) = new_figure(2, width=4.8)
    runs = (("optimal (IDAS replay)", replay, "C0"), ("scene profile", baseline, "C3"))
    kisses = []
    for label, run, color in runs:
        res = run.result
        ax1.plot(res.t * 1e3, res["x0"] * 1e3, color=color, label=f"{label}: travel")
        ax2.plot(res.t * 1e3, _spring_force(run), color=color, label=f"{label}: spring")
        ax2.plot(res.t * 1e3, res["pressure_Pa"] * scene.value("piston.area"), color=color, ls="--",
                 label=f"{label}: pressure x area")
        kiss = [e.t for e in res.events if e.name == "impact"]
        kisses += kiss
        for t in kiss:
            ax1.axvline(t * 1e3, color=color, lw=0.8, ls=":")
    t_end = 1.5 * max(run.summary["engagement_time_s"] or run.result.t[-1] for _, run, _ in runs)
    travel = scene.get("piston.travel_to_pack", 0.0)
    if travel > 0:
        ax1.axhline(travel * 1e3, color="k", lw=0.8, ls=":", label="kiss point (pack reached)")
    # the stroke takes milliseconds: show it up to 4 x the later kiss (dotted lines)
    ax1.set(xlabel="time [ms]", ylabel="piston travel [mm]", title=f"{scene.name}: piston stroke to the kiss point",
            xlim=(0, (4 * max(kisses) if kisses else t_end) * 1e3))
    ax2.set(xlabel="time [ms]", ylabel="force [N]", title="spring force and hydraulic force", xlim=(0, t_end * 1e3))
    ax1.legend(fontsize=7)
    ax2.legend(fontsize=7)
    return save_figure(fig, out / "piston.png")


def _spring_force(run):
    """|spring force| [N] along a run from the piston travel (Bao Eq. 21 springs)."""
    s = run.model.scene
    k = s.value("piston.spring_stiffness") * s.value("piston.spring_count")
    sign = -1.0 if s.variant("piston") == "spring_applied" else 1.0
    return k * (s.value("piston.spring_preload") + sign * run.result["x0"])


def plot_fill_comparison(out, scene, fill):
    """Pressure, torque and jerk of the minimum-time optimum against the tuned fill pulse (both IDAS)."""
    fig, axes = new_figure(3, width=4.2)
    cap = fill["summary"]["jerk_cap_rad_s3"]
    runs = (("minimum-time optimum", fill["optimal_run"], "C0"),
            ("tuned fill pulse, hold, ramp", fill["baseline_run"], "C3"))
    for label, run, color in runs:
        res = run.result
        t_lock = run.summary["engagement_time_s"]
        axes[0].plot(res.t, res["pressure_Pa"] / 1e6, color=color, label=label)
        axes[1].plot(res.t, res["total_torque_Nm"], color=color, label=label)
        mask = res.t <= (t_lock if t_lock is not None else res.t[-1])
        axes[2].plot(res.t[mask], res["output_jerk_rad_s3"][mask], color=color, label=label)
        for ax in axes:
            if t_lock is not None:
                ax.axvline(t_lock, color=color, lw=0.8, ls=":")
    axes[2].axhline(cap, color="k", lw=0.8, ls="--", label="peak-jerk limit (both)")
    times = [run.summary["engagement_time_s"] for _, run, _ in runs]
    fig.suptitle(f"Minimum-time optimum against the tuned fill pulse at equal peak jerk ({cap:.4g} rad/s^3, both "
                 f"IDAS): lock-up at {_fmt(times[0], 's')} against {_fmt(times[1], 's')}", fontsize=10)
    axes[2].axhline(-cap, color="k", lw=0.8, ls="--")
    t_end = 1.2 * max(run.summary["engagement_time_s"] or run.result.t[-1] for _, run, _ in runs)
    for ax, ylabel, title in zip(axes, ("valve pressure [MPa]", "clutch torque [N m]", "output jerk [rad/s^3]"),
                                 ("pressure", "torque (dotted: lock-up)", "jerk up to lock-up")):
        ax.set(xlabel="time [s]", ylabel=ylabel, title=f"{scene.name}: {title}", xlim=(0, t_end))
        ax.legend(fontsize=7)
    return save_figure(fig, out / "fill_comparison.png")


def _locks(ax, runs):
    """Mark the lock-up times (in the legend) and show the time axis up to 1.5 x the later one."""
    t_end = max([run.summary["engagement_time_s"] or run.result.t[-1] for _, run, _ in runs])
    ax.set_xlim(0.0, 1.5 * t_end)
    for label, run, color in runs:
        t_lock = run.summary["engagement_time_s"]
        if t_lock is not None:
            ax.axvline(t_lock, color=color, lw=0.8, ls=":", label=f"lock-up, {label.split(' (')[0]}: {t_lock:.4g} s")


def plot_pareto(out, scene, sweep, w_rel0, rate0, ocp):
    """Jerk integral against engagement time of the sweep, with the kinematic lower bound."""
    ok = [p for p in sweep if p["status"] != "failed"]
    if not ok:
        raise ModelError("--sweep-t-max: no engagement-time limit of the sweep could be solved")
    t = np.array([p["engagement_time_s"] for p in ok])
    jerk = np.array([p["jerk_integral"] for p in ok])
    fig, (ax,) = new_figure()
    ax.plot(t, jerk, "o-", label="optimum (output jerk)")
    grid = np.linspace(t.min(), t.max(), 100)
    share = ocp.output_jerk_share
    ax.plot(grid, [jerk_lower_bound(w_rel0, rate0, T) * share**2 for T in grid], "k--", lw=0.8,
            label="kinematic lower bound")
    ax.set(xlabel="engagement time [s]", ylabel="int jerk^2 dt [rad^2/s^5]", yscale="log",
           title=f"{scene.name}: jerk against engagement time")
    ax.legend(fontsize=8)
    return save_figure(fig, out / "pareto.png")


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
    heat = summary.get("heat")
    if heat is not None and "peak_interface_temperature_C" in heat["idas"]:
        lines.append(f"  peak interface temperature: {heat['collocation']['peak_interface_temperature_C']:.2f} degC "
                     f"(IDAS {heat['idas']['peak_interface_temperature_C']:.2f} degC)")
    return "\n".join(lines)


def _num(value):
    return "none" if value is None else f"{value:.4g}"
