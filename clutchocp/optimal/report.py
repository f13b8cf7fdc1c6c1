"""``clutchocp optimize``: the optimal engagement pressure of a scene, verified, compared and written out."""

import time
from pathlib import Path

import numpy as np

from ..errors import ClutchocpError, ModelError
from ..output import new_figure, save_figure, write_csv, write_summary
from ..scene import default_scene, load_scene
from .baselines import baseline_label, simulate_baselines, tune_fill_pulse
from .bound import jerk_lower_bound
from .problem import EngagementOCP
from .replay import CommandModel
from .verify import HOLD_DELAY, holding_pressure, run_numbers, verify

KEYS = ("engagement_time_s", "lockup_torque_jump_Nm", "jerk_integral", "dissipated_energy_J", "peak_jerk_rad_s3",
        "peak_torque_Nm")
COMPARE_KEYS = KEYS + ("locked_torque_Nm", "kiss_time_s", "kiss_speed_m_s", "kiss_jerk_rad_s3")
# Minimum engagement time (a little command smoothing keeps the command regular).
FAST_WEIGHTS = {"jerk": 0.0, "time": 1.0, "smooth": 0.01}


def run_optimize(scene=None, out_dir="out/optimize", t_max=None, weights=None, intervals=100, degree=3,
                 sweep_t_max=None, progress=True):
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
    if scene is None:
        scene = default_scene()
    elif isinstance(scene, (str, Path)):
        scene = load_scene(scene)
    out = Path(out_dir)
    start = time.perf_counter()
    say(f"optimize {scene.name}: building the collocation problem ({intervals} intervals, degree {degree})")
    ocp = EngagementOCP(scene, intervals=intervals, degree=degree)
    build_time = time.perf_counter() - start
    opt = ocp.solve(t_max=t_max, weights=weights)
    say(f"  IPOPT {opt.stats['status']}: {opt.stats['iterations']} iterations, {opt.stats['wall_time_s']:.2f} s")
    verifier = ocp.exact if ocp.polish else ocp
    command_model = CommandModel(scene, opt.control)
    check, replay = verify(verifier, opt, model=command_model)
    say(f"  IDAS re-simulation: lock-up {_fmt(check['idas']['engagement_time_s'], 's')}, "
        f"jump {_fmt(check['torque_jump_Nm'], 'N m')}")
    # the calibration shape "fill pulse, hold, ramp" is that of a pressure-applied piston
    fill = _fill_comparison(ocp, opt, check, command_model, intervals, degree, say) \
        if len(opt.phases) > 1 and ocp.apply_pressure > 0 else None
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
        "jerk_lower_bound": bound,
        "jerk_lower_bound_ratio": opt.terms["slip_jerk_integral"] / bound,
        "initial_slip_rad_s": w_rel0,
        "initial_slip_rate_rad_s2": rate0,
        "limits": {"t_max_s": opt.t_max if np.isfinite(opt.t_max) else None, "e_max_J": opt.e_max,
                   "max_pressure_Pa": ocp.p_max,
                   "rate_limit_Pa_s": ocp.rate_limit if np.isfinite(ocp.rate_limit) else None,
                   "lock_margin": ocp.lock_margin},
        "weights": opt.weights,
        "phases": [{k: ph[k] for k in ("name", "mode", "t_start_s", "t_end_s", "intervals")} for ph in opt.phases],
        "lockup_definition": _lockup_definition(ocp),
        "solver": {"status": opt.stats["status"], "iterations": opt.stats["iterations"],
                   "wall_time_s": opt.stats["wall_time_s"], "build_time_s": build_time,
                   "intervals": intervals, "degree": degree, "scheme": ocp.transcription.scheme,
                   "control": opt.control, "n_variables": opt.stats["n_variables"],
                   "stages": [{k: s[k] for k in ("model", "status", "iterations", "wall_time_s", "warm_start")}
                              for s in opt.stats["stages"]]},
    }
    if "fill_time_s" in opt.terms:
        summary["optimal"].update(fill_time_s=opt.terms["fill_time_s"], kiss_speed_m_s=opt.terms["kiss_speed_m_s"])
    if sweep is not None:
        summary["sweep"] = sweep
    if fill is not None:
        summary["fill_comparison"] = fill["summary"]
    out.mkdir(parents=True, exist_ok=True)
    files = [_write_profile(out, ocp, opt), write_summary(out / "summary.json", summary)]
    files += plot_optimum(out, scene, opt, replay, ocp.baseline, baselines, summary)
    if ocp.model.has_piston:
        files.append(plot_piston(out, scene, replay, ocp.baseline))
    if fill is not None:
        files.append(plot_fill_comparison(out, scene, fill))
    if sweep is not None:
        files.append(plot_pareto(out, scene, sweep, w_rel0, rate0, ocp))
    summary["files"] = [str(f) for f in files]
    say(format_summary(summary))
    return summary


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


def _write_profile(out, ocp, opt):
    """pressure_profile.csv: time, command and pressure [s, Pa, Pa].

    Piecewise-linear command: its nodes (linear in between). Piecewise-constant command: the value
    from each time on. After lock-up (the last time) the command is the holding pressure of the
    verification (summary: verification.holding_pressure_Pa; the last row of a constant command).
    """
    times = np.append(opt.command_times, opt.t_f * (1 + HOLD_DELAY)) if opt.control == "constant" \
        else opt.command_times.copy()
    command = np.append(opt.command, holding_pressure(ocp, opt)) if opt.control == "constant" else opt.command
    pressure = np.interp(times, opt.t, opt.outputs["pressure_Pa"])
    return write_csv(out / "pressure_profile.csv",
                     {"time_s": times, "pressure_command_Pa": command, "pressure_Pa": pressure})


def _slip(run):
    res = run.result
    t_lock = run.summary["engagement_time_s"]
    return res.t, (res.t <= t_lock) if t_lock is not None else np.ones(res.t.size, bool)


def plot_optimum(out, scene, opt, replay, baseline, baselines, summary):
    """Pressure, torque, speeds and jerk of the optimum (IDAS replay) against the baseline; baselines bar chart."""
    files = []
    name = scene.name
    runs = (("optimal (IDAS replay)", replay, "C0"), (f"baseline ({summary['baseline']['profile']})", baseline, "C3"))

    fig, (ax,) = new_figure()
    if opt.control == "constant":
        ax.step(np.append(opt.command_times, opt.t_f), np.append(opt.command, opt.command[-1]) / 1e6,
                where="post", color="C0", lw=0.8, alpha=0.6, label="optimal command")
    else:
        ax.plot(opt.command_times, opt.command / 1e6, color="C0", lw=0.8, alpha=0.6, label="optimal command")
    for label, run, color in runs:
        ax.plot(run.result.t, run.result["pressure_Pa"] / 1e6, color=color, label=label)
    ax.plot(opt.t, opt.outputs["pressure_Pa"] / 1e6, ".", color="C0", ms=2, label="collocation")
    ax.set(xlabel="time [s]", ylabel="pressure [MPa]", title=f"{name}: engagement pressure")
    _locks(ax, runs)
    ax.legend(fontsize=8)
    files.append(save_figure(fig, out / "pressure.png"))

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

    fig, (ax1, ax2) = new_figure(2, width=4.8)
    labels = ["optimal"] + list(baselines)
    jumps = [abs(summary["verification"]["torque_jump_Nm"] or 0.0)] + \
        [abs(n["lockup_torque_jump_Nm"] or 0.0) for _, n in baselines.values()]
    jerks = [summary["optimal"]["jerk_integral"]] + [n["jerk_integral"] or 0.0 for _, n in baselines.values()]
    colors = ["C0"] + ["C3"] * len(baselines)
    ax1.bar(labels, jumps, color=colors)
    ax1.set(ylabel="|lock-up torque jump| [N m]", title="torque jump at lock-up")
    ax2.bar(labels, jerks, color=colors)
    ax2.set(ylabel="int jerk^2 dt [rad^2/s^5]", title="jerk integral (slip phase)")
    for ax in (ax1, ax2):
        ax.tick_params(axis="x", labelrotation=60, labelsize=7)
    files.append(save_figure(fig, out / "baselines.png"))
    return files


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
    """Mark the lock-up times and show the time axis up to 1.5 x the later one."""
    t_end = max([run.summary["engagement_time_s"] or run.result.t[-1] for _, run, _ in runs])
    ax.set_xlim(0.0, 1.5 * t_end)
    for _, run, color in runs:
        t_lock = run.summary["engagement_time_s"]
        if t_lock is not None:
            ax.axvline(t_lock, color=color, lw=0.8, ls=":")


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
    return "\n".join(lines)


def _num(value):
    return "none" if value is None else f"{value:.4g}"
