"""The figures of ``clutchocp optimize``: the optimum and its IDAS replay against the baselines.

Each function draws results it is given (an optimum, IDAS runs, the summary) and saves a PNG; nothing
here computes a result.
"""

import numpy as np

from ..errors import ModelError
from ..output import new_figure, save_figure
from ..plotting import clip_spike, finish, scene_title
from .bound import jerk_lower_bound
from .outcome import format_quantity
from .verify import output_held


def result_figure(result):
    """The pressure figure of an :class:`~clutchocp.optimal.outcome.OptimizationResult`
    (:func:`pressure_figure`)."""
    return pressure_figure(result.scene, result.optimum, result.replay, result.ocp.baseline, result.summary,
                           result.curve, result.clamp_run)


def _slip(run):
    res = run.result
    t_lock = run.summary["engagement_time_s"]
    return res.t, (res.t <= t_lock) if t_lock is not None else np.ones(res.t.size, bool)


def plot_optimum(out, scene, opt, replay, baseline, baselines, summary, curve=None, clamp_run=None):
    """Pressure, torque, speeds and jerk of the optimum (IDAS replay) against the baseline; baselines bar chart."""
    files = []
    runs = (("optimal (IDAS replay)", replay, "C0"), (f"baseline ({summary['baseline']['profile']})", baseline, "C3"))
    files.append(save_figure(pressure_figure(scene, opt, replay, baseline, summary, curve, clamp_run),
                             out / "pressure.png"))

    fig, (ax,) = new_figure()
    for label, run, color in runs:
        ax.plot(run.result.t, run.result["total_torque_Nm"], color=color, label=label)
    ax.set(xlabel="time [s]", ylabel="clutch torque [N m]", title=scene_title(scene, "clutch torque"))
    _locks(ax, runs)
    ax.legend(fontsize=8)
    files.append(save_figure(fig, out / "torque.png"))
    files.append(save_figure(jerk_figure(scene, runs), out / "jerk.png"))

    fig, (ax,) = new_figure()
    for label, run, color in runs:
        ax.plot(run.result.t, run.result["w_in_rad_s"], color=color, label=f"{label}: input")
        ax.plot(run.result.t, run.result["w_out_rad_s"], color=color, ls="--", label=f"{label}: output")
    ax.set(xlabel="time [s]", ylabel="speed [rad/s]", title=scene_title(scene, "speeds"))
    _locks(ax, runs)
    ax.legend(fontsize=7)
    files.append(save_figure(fig, out / "speeds.png"))

    w_rel0, rate0 = summary["initial_slip_rad_s"], summary["initial_slip_rate_rad_s2"]
    share = summary["jerk_lower_bound"] / summary["slip_jerk_lower_bound"] if summary["slip_jerk_lower_bound"] else 0.0
    files.append(plot_baselines(out, scene_title(scene, "jerk against engagement time"), summary, baselines,
                                lambda T: jerk_lower_bound(w_rel0, rate0, T) * share))
    return files


def jerk_figure(scene, runs):
    """The jerk of each run over its slip phase (the fill and the slip, up to lock-up).

    The jerk that matters is the driven side's: the output's, or for a brake (output held, w_out = 0
    throughout) the braked input's, -dT/dt / I_in (as the optimiser's jerk term and its IDAS check
    take it, :func:`clutchocp.optimal.verify.run_numbers`). The axis is scaled to the slip phase:
    the jump of the jerk when the piston meets the pack (the kiss, a fraction of a millisecond) is
    annotated with its size instead of setting the scale. Where the first tenth of the engagement
    holds jerk five times larger than the rest (the pressure rise of a long brake engagement), a
    second panel shows the rest on its own scale.
    """
    series = [(label, color) + _jerk(scene, run) for label, run, color in runs]
    # the squeeze films stop the piston within ~0.1 ms of the kiss; 2 % of the engagement covers it
    t_end = max((t[-1] for _, _, t, _, _ in series if t.size), default=1.0)
    kisses = [[e.t for e in run.result.events if e.name == "impact"][:1] for _, run, _ in runs]
    windows = [(k[0], k[0] + 0.02 * t_end) if k else None for k in kisses]

    def outside(t, window):
        return np.ones(t.size, bool) if window is None else (t < window[0]) | (t > window[1])

    split = 0.1 * t_end
    early = max(np.max(np.abs(j[(t <= split) & outside(t, w)]), initial=0.0)
                for (_, _, t, j, _), w in zip(series, windows))
    late = max(np.max(np.abs(j[t > split]), initial=0.0) for _, _, t, j, _ in series)
    fig, axes = new_figure(2 if early > 5 * late > 0 else 1, width=5.0 if early > 5 * late > 0 else 6.4)
    held = any(h for *_, h in series)
    side = "input" if held else "output"
    for ax in axes:
        for label, color, t, jerk, _ in series:
            ax.plot(t, jerk, color=color, label=label)
        ax.set(xlabel="time [s]", ylabel=f"{side} jerk [rad/s^3]")
        ax.grid(alpha=0.3)
    for (label, _, t, jerk, _), window in zip(series, windows):
        if window is not None and t.size:
            clip_spike(axes[0], t, jerk, window, what=f"kiss ({label.split(' (')[0]})", unit="rad/s^3")
    what = "input jerk (a brake: the output is held)" if held else "output jerk"
    _locks(axes[0], runs)
    if len(axes) == 1:
        axes[0].set_title(scene_title(scene, f"{what} up to lock-up"))
    else:
        fig.suptitle(scene_title(scene, f"{what} up to lock-up"))
        axes[0].set_title("the whole engagement")
        rest = [j[t > split] for _, _, t, j, _ in series]
        lo, hi = min(r.min() for r in rest if r.size), max(r.max() for r in rest if r.size)
        pad = 0.08 * (hi - lo or 1.0)
        axes[1].set(ylim=(lo - pad, hi + pad), title=f"after the first {split:.3g} s, on its own scale")
        _locks(axes[1], runs)
        axes[1].set_xlim(split, 1.05 * t_end)
    axes[-1].legend(fontsize=8)
    return fig


def _jerk(scene, run):
    """(times [s], jerk [rad/s^3], output held?) of a run over its fill and slip phases."""
    t, slip = _slip(run)
    if output_held(run.model):     # one sample per time (an event repeats its time), then -dT/dt / I_in
        ts, first = np.unique(t[slip], return_index=True)
        torque = run.result["total_torque_Nm"][slip][first]
        jerk = -np.gradient(torque, ts) / scene.value("driveline.input_inertia") if ts.size > 1 else 0 * ts
        return ts, jerk, True
    return t[slip], run.result["output_jerk_rad_s3"][slip], False


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
                label=f"command after lock-up: ramp to clamp ({curve.basis})")
    for label, run, color in runs:
        t, p = run.result.t, run.result["pressure_Pa"]
        if run is replay and clamp_run is not None:       # the curve a user applies, not the check's hold
            t_lock = run.summary["engagement_time_s"] or t[-1]
            t = np.concatenate([t[t <= t_lock], clamp_run.result.t[clamp_run.result.t > t_lock]])
            p = np.concatenate([p[run.result.t <= t_lock], clamp_run.result["pressure_Pa"][clamp_run.result.t > t_lock]])
        ax.plot(t, p / 1e6, color=color, label=label)
    ax.plot(opt.t, opt.outputs["pressure_Pa"] / 1e6, ".", color="C0", ms=2, label="collocation")
    ax.set(xlabel="time [s]", ylabel="pressure [MPa]", title=scene_title(scene, "engagement pressure"))
    _locks(ax, runs)
    ax.legend(fontsize=8)
    return finish(fig)


def plot_baselines(out, title, summary, baselines, bound_at):
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
            title=title)
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
    ax1.set(xlabel="time [ms]", ylabel="piston travel [mm]", title=scene_title(scene, "piston stroke to the kiss point"),
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
    fig.suptitle(scene_title(scene, "minimum-time optimum against the tuned fill pulse")
                 + f" at equal peak jerk ({cap:.4g} rad/s^3, both "
                 f"IDAS): lock-up at {format_quantity(times[0], 's')} against {format_quantity(times[1], 's')}", fontsize=10)
    axes[2].axhline(-cap, color="k", lw=0.8, ls="--")
    t_end = 1.2 * max(run.summary["engagement_time_s"] or run.result.t[-1] for _, run, _ in runs)
    for ax, ylabel, title in zip(axes, ("valve pressure [MPa]", "clutch torque [N m]", "output jerk [rad/s^3]"),
                                 ("pressure", "torque (dotted: lock-up)", "jerk up to lock-up")):
        ax.set(xlabel="time [s]", ylabel=ylabel, title=title, xlim=(0, t_end))
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
           title=scene_title(scene, "jerk against engagement time"))
    ax.legend(fontsize=8)
    return save_figure(fig, out / "pareto.png")
