"""``clutchocp optimize``: the optimal engagement pressure of a scene, verified, compared and written out."""

import time
from pathlib import Path

import numpy as np

from ..errors import ClutchocpError, ModelError
from ..output import new_figure, save_figure, write_csv, write_summary
from ..scene import default_scene, load_scene
from .baselines import baseline_label, simulate_baselines
from .bound import jerk_lower_bound
from .clamp import DEFAULT_MARGIN, check_margin, extend_to_clamp
from .problem import EngagementOCP
from .replay import CommandModel, simulate_command
from .verify import run_numbers, verify

KEYS = ("engagement_time_s", "lockup_torque_jump_Nm", "jerk_integral", "dissipated_energy_J", "peak_jerk_rad_s3",
        "peak_torque_Nm")


CLAMP_SETTLE_S = 0.3       # the whole-curve replay runs this long after the clamp ramp ends


def run_optimize(scene=None, out_dir="out/optimize", t_max=None, weights=None, intervals=100, degree=3,
                 sweep_t_max=None, progress=True, clamp_margin=DEFAULT_MARGIN):
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
    clamp_margin = check_margin(clamp_margin)          # a bad margin fails before the solve
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
    curve, whole = _clamp_curve(scene, ocp, opt, command_model, clamp_margin)
    say(f"  after lock-up: ramp to the clamp pressure {curve.clamp_pressure_Pa / 1e6:.4g} MPa by "
        f"{curve.ramp_end_s:.4g} s (capacity {curve.margin:g} x the locked torque); lock held in the IDAS replay: "
        f"{whole['lock_held']}")
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
        "clamp": whole,
        "solver": {"status": opt.stats["status"], "iterations": opt.stats["iterations"],
                   "wall_time_s": opt.stats["wall_time_s"], "build_time_s": build_time,
                   "intervals": intervals, "degree": degree, "scheme": ocp.transcription.scheme,
                   "control": opt.control, "n_variables": opt.stats["n_variables"],
                   "stages": [{k: s[k] for k in ("model", "status", "iterations", "wall_time_s", "warm_start")}
                              for s in opt.stats["stages"]]},
    }
    if sweep is not None:
        summary["sweep"] = sweep
    out.mkdir(parents=True, exist_ok=True)
    files = [_write_profile(out, opt, curve, whole["run"]), write_summary(out / "summary.json", _public(summary))]
    files += plot_optimum(out, scene, opt, replay, ocp.baseline, baselines, summary, curve)
    if sweep is not None:
        files.append(plot_pareto(out, scene, sweep, w_rel0, rate0, ocp))
    summary["files"] = [str(f) for f in files]
    summary = _public(summary)
    say(format_summary(summary))
    return summary


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
    curve = extend_to_clamp(scene, opt.command_times, opt.command, opt.t_f, margin=margin, rate_limit=rate)
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
             "capacity_margin_at_end": float(run.result["static_capacity_Nm"][-1] / torque) if lock else None,
             "run": run}
    return curve, entry


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


def _write_profile(out, opt, curve, run):
    """pressure_profile.csv: the whole usable command, engagement and clamp [s, Pa, Pa].

    Rows are the nodes of the piecewise-linear command: ``to_next`` says how the command goes on
    to the next row ("linear") or after the last one ("hold": constant). ``phase`` names the
    segment a row starts: "engagement" before lock-up, "clamp_ramp" from the lock-up row,
    "clamp_hold" on the last row. ``pressure_Pa`` is the
    pressure the collocation predicts up to lock-up and the IDAS replay of the whole curve after it.
    """
    times, command = curve.times, curve.pressures
    engaged = times <= opt.t_f
    pressure = np.where(engaged, np.interp(times, opt.t, opt.outputs["pressure_Pa"]),
                        np.interp(times, run.result.t, run.result["pressure_Pa"]))
    phase = np.where(times < opt.t_f, "engagement", "clamp_ramp").astype(object)   # the segment a row starts
    if times[-1] > opt.t_f:
        phase[-1] = "clamp_hold"
    to_next = ["linear"] * (times.size - 1) + ["hold"]
    return write_csv(out / "pressure_profile.csv",
                     {"time_s": times, "pressure_command_Pa": command, "pressure_Pa": pressure,
                      "phase": list(phase), "to_next": to_next})


def _slip(run):
    res = run.result
    t_lock = run.summary["engagement_time_s"]
    return res.t, (res.t <= t_lock) if t_lock is not None else np.ones(res.t.size, bool)


def plot_optimum(out, scene, opt, replay, baseline, baselines, summary, curve=None):
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
    if curve is not None:
        after = curve.times >= opt.t_f
        t_after = np.append(curve.times[after], 10.0 * curve.times[-1])
        p_after = np.append(curve.pressures[after], curve.pressures[-1])
        ax.plot(t_after, p_after / 1e6, color="C2", lw=1.2, ls="--",
                label=f"command after lock-up: ramp to clamp ({curve.margin:g} x locked torque)")
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
