"""Figures of an engagement run: films, speeds, torque, pressure and force, Zhang's torque response, heat,
and the one-figure overview of ``EngagementResult.plot``. Figures read a run; runs never import them."""

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ..output import new_figure, save_figure
from ..plotting import finish, scene_title
from .measures import pressure_rise_time


def _mark_lockup(ax, run):
    """A dashed line at the lock-up time, in the legend as 'lock-up at ... s'."""
    t_lock = run.summary["engagement_time_s"]
    if t_lock is not None:
        ax.axvline(t_lock, color="0.5", lw=0.8, ls="--", label=f"lock-up at {t_lock:.4g} s")


def _finish(fig, ax, run, path, legend=True):
    """Mark the lock-up time, add the legend and save the figure; returns its path."""
    _mark_lockup(ax, run)
    if legend:
        ax.legend(fontsize=8)
    return save_figure(fig, path)


def _early_window(t, values, fraction=0.99):
    """End of the early transient [s]: when every series has made ``fraction`` of its total change."""
    ends = []
    for y in values:
        change = np.abs(y - y[0])
        total = change[-1] if change[-1] > 0 else change.max()
        if total > 0:
            ends.append(t[np.argmax(change >= fraction * total)])
    return max(ends) if ends else t[-1]


def plot_engagement(run, out):
    """Gaps, speeds, torque components and pressure against time, one PNG each."""
    res, model = run.result, run.model
    t = res.t
    files = []

    # films: the squeeze phase is often a few % of the run, so the left panel shows it alone
    films = [res[f"h_{i + 1}_m"] * 1e6 for i in range(model.n)]
    t_early = min(1.5 * _early_window(t, films), t[-1])
    fig, (ax0, ax) = new_figure(2, width=5.0)
    for ax_ in (ax0, ax):
        for i, h in enumerate(films):
            ax_.plot(t, h, label=f"film {i + 1}")
        ax_.set_yscale("log")
        ax_.grid(alpha=0.3, which="both")
    ax0.set(xlabel="time [s]", ylabel="film thickness [um]", xlim=(t[0], t_early),
            title=f"the first {t_early:.3g} s")
    ax.set(xlabel="time [s]", ylabel="film thickness [um]", title="whole run")
    fig.suptitle(scene_title(model.scene, "oil films"))
    _mark_lockup(ax0, run)
    files.append(_finish(fig, ax, run, out / "gaps.png"))
    files.append(plot_film_pressure(run, out / "film_pressure.png", t_early))

    fig, (ax,) = new_figure()
    ax.plot(t, res["w_in_rad_s"], label="input")
    ax.plot(t, res["w_out_rad_s"], label="output")
    ax.set(xlabel="time [s]", ylabel="speed [rad/s]", title=scene_title(model.scene, "speeds"))
    files.append(_finish(fig, ax, run, out / "speeds.png"))

    fig, (ax,) = new_figure()
    ax.plot(t, res["viscous_torque_Nm"], label="viscous")
    ax.plot(t, res["contact_torque_Nm"], label="asperity contact")
    ax.plot(t, res["total_torque_Nm"], "k", lw=1.5, label="total")
    ax.set(xlabel="time [s]", ylabel="clutch torque [N m]", title=scene_title(model.scene, "torque components"))
    files.append(_finish(fig, ax, run, out / "torque.png"))

    # pressure and the force that presses the pack: for a spring-applied clutch the pressure
    # (the release pressure) may stay zero while the springs press the plates
    fig, (ax0, ax) = new_figure(2, width=5.0)
    ax0.plot(t, res["pressure_Pa"] / 1e6, label="pressure")
    ax0.set(xlabel="time [s]", ylabel="pressure [MPa]", title="actuation pressure")
    if model.piston.spring_applied:
        ax0.set_title("release pressure (spring-applied piston)")
    fig.suptitle(scene_title(model.scene, "pressure and the force on the plates"))
    if not np.any(res["pressure_Pa"]):
        ax0.text(0.5, 0.6, "the pressure stays 0:\nthe springs engage the clutch\n(force: right panel)",
                 transform=ax0.transAxes, ha="center", fontsize=9)
    force, label = model.piston.force_output        # the piston's drive, or the pressure force on the pack
    ax.plot(t, res[force] / 1e3, color="C2", label=label)
    ax.plot(t, res["contact_force_N"] / 1e3, color="C1", lw=1, label="asperity contact (each film carries it)")
    ax.set(xlabel="time [s]", ylabel="force [kN]", title="force pressing the plates")
    _mark_lockup(ax0, run)
    ax0.legend(fontsize=8)
    files.append(_finish(fig, ax, run, out / "pressure.png"))
    if run.summary["torque_response_time_stable_s"] is not None:
        files.append(plot_torque_response(run, out / "torque_response.png"))
    files.append(plot_heat(run, out / "heat.png"))
    return files


MAX_FILMS_LABELLED = 8


def plot_film_pressure(run, path, t_early):
    """The mean gauge pressure of each film against the cavitation pressure, the lowest a film holds
    (``film.cavitation_pressure``, drawn as a line); dashed, the averaged Reynolds film at the same closing
    speed without that limit (below the line the film has cavitated). Left panel the first ``t_early``
    seconds (the squeeze, to scale), right panel the rest of the run scaled to its own values and the
    limit (where suction after the squeeze shows); returns the PNG path."""
    from matplotlib.lines import Line2D

    res, model, summary = run.result, run.model, run.summary
    t = res.t
    p_cav = summary["film_cavitation_pressure_Pa"] / 1e6
    later = t >= t_early
    rest = later.sum() > 1 and t_early < t[-1]
    fig, (ax0, ax) = new_figure(2, width=5.0)
    shown = []
    for k in range(1, model.n + 1):
        color = f"C{(k - 1) % 10}"
        mean = res[f"film_{k}_mean_pressure_Pa"] / 1e6
        reynolds = res[f"film_{k}_reynolds_pressure_Pa"] / 1e6
        for panel in (ax0, ax):
            panel.plot(t, mean, color=color, lw=1.2)
            panel.plot(t, reynolds, color=color, lw=0.8, ls="--")
        shown += [mean[later], reynolds[later]] if rest else []
        if model.n <= MAX_FILMS_LABELLED or k in (1, model.n):
            ax.plot([], [], color=color, lw=1.2, label=f"film {k}")
    ax.add_line(Line2D([], [], color="0.3", lw=0.8, ls="--", label="dashed: the Reynolds film without the limit"))
    for panel in (ax0, ax):
        panel.axhline(p_cav, color="k", lw=1.0, ls=":",
                      label=f"cavitation pressure {p_cav:.3g} MPa" if panel is ax else None)
        panel.axhline(0.0, color="0.6", lw=0.5)
        panel.grid(alpha=0.3)
        panel.set(xlabel="time [s]", ylabel="mean film pressure, gauge [MPa]")
    ax0.set(xlim=(t[0], t_early), title=f"the first {t_early:.3g} s")
    lowest = (f"lowest {summary['min_film_pressure_Pa']:.3g} Pa, film {summary['min_film_pressure_film']} "
              f"at {summary['min_film_pressure_time_s']:.3g} s")
    if rest:
        values = np.concatenate([v[np.isfinite(v)] for v in shown] + [[p_cav, 0.0]])
        low, high = values.min(), values.max()
        pad = 0.08 * (high - low)
        ax.set(xlim=(t_early, t[-1]), ylim=(low - pad, high + pad), title=f"after {t_early:.3g} s; {lowest}")
    else:
        ax.set_title(f"whole run; {lowest}")
    fig.suptitle(scene_title(model.scene, "film pressures and the cavitation limit"))
    _mark_lockup(ax0, run)
    return _finish(fig, ax, run, path)


def plot_torque_response(run, path):
    """Zhang's torque response: the torques from the start to a few response times past 50 % pressure,
    with the stable torque, its 90 % level and the end of both response times marked."""
    res, model, summary = run.result, run.model, run.summary
    t50 = pressure_rise_time(model, res, 0.5)
    stable = summary["stable_torque_Nm"]
    ends = {"stable": t50 + summary["torque_response_time_stable_s"]}
    if summary["torque_response_time_s"] is not None:
        ends["peak"] = t50 + summary["torque_response_time_s"]
    t_show = min(res.t[-1], t50 + 3 * (max(ends.values()) - t50))
    keep = res.t <= t_show
    t = res.t[keep]
    fig, (ax,) = new_figure(width=7.4, height=4.6)
    ax.plot(t, np.abs(res["viscous_torque_Nm"][keep]), label="viscous")
    ax.plot(t, np.abs(res["contact_torque_Nm"][keep]), label="asperity contact")
    ax.plot(t, np.abs(res["total_torque_Nm"][keep]), "k--", lw=1.2, label="total")
    ax.axhline(stable, color="C3", ls="--", lw=0.8, label=f"stable torque {stable:.4g} N m")
    ax.axhline(0.9 * stable, color="C3", ls=":", lw=0.8, label="90 % of the stable torque")
    ax.axvline(t50, color="0.5", lw=0.8, label=f"50 % of set pressure, {t50 * 1e3:.1f} ms")
    ax.axvline(ends["stable"], color="C3", lw=1.2,
               label=f"to 90 % stable: {summary['torque_response_time_stable_s'] * 1e3:.1f} ms (Zhang)")
    if "peak" in ends:
        ax.axvline(ends["peak"], color="C4", lw=1.2,
                   label=f"to 90 % of the peak: {summary['torque_response_time_s'] * 1e3:.1f} ms")
    pressure_axis = ax.twinx()
    pressure_axis.plot(t, res["pressure_Pa"][keep] / 1e6, color="0.6", lw=0.8)
    pressure_axis.set_ylabel("pressure [MPa] (grey)")
    ax.set_zorder(pressure_axis.get_zorder() + 1)      # torques and legend above the pressure curve
    ax.patch.set_visible(False)
    ax.set(xlabel="time [s]", ylabel="clutch torque [N m]",
           title=scene_title(model.scene, "torque response from 50 % pressure"))
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.12, 1.0), borderaxespad=0)
    return save_figure(fig, path)


def plot_heat(run, path, *, max_temperature_C=None, max_specific_power_W_mm2=None, what="the engagement"):
    """Specific power of the friction area against time, and the plate temperatures if the scene
    has a [thermal] part (left panel), with the limits given drawn as lines; returns the PNG path.
    ``what`` names the run in the title (e.g. "the IDAS replay of the optimum")."""
    res, model, summary = run.result, run.model, run.summary
    t = res.t
    fig, axes = new_figure(2 if model.thermal.present else 1)
    ax = axes[-1]
    ax.plot(t, res["interface_heat_power_W"] / summary["friction_area_mm2"], color="C3", label="specific power")
    if max_specific_power_W_mm2 is not None:
        ax.axhline(max_specific_power_W_mm2, color="k", ls="--", lw=0.8, label="limit")
    ax.set(xlabel="time [s]", ylabel="specific power [W/mm^2]",
           title=f"specific energy {summary['specific_energy_J_mm2']:.3g} J/mm^2\n"
                 f"over {summary['friction_area_mm2']:.0f} mm^2 of friction area")
    fig.suptitle(scene_title(model.scene, f"heat of {what} at the friction interfaces"))
    if model.thermal.present:
        hot = axes[0]
        hot.plot(t, res["interface_temperature_C"], "k", lw=1.5, label="interface: lining surface, separator")
        for j in range(1, model.thermal.cells):
            hot.plot(t, res[f"T_lining_{j}"], color="C1", lw=0.6, alpha=0.6,
                     label="inside the lining (surface to core)" if j == 1 else None)
        hot.plot(t, res["T_core"], "C4", label="friction-plate core")
        hot.plot(t, res["friction_plate_temperature_C"], "C1", lw=1.5, label="friction plates (bulk)")
        hot.axhline(model.thermal.T_oil, color="C2", ls=":", label="oil")
        if max_temperature_C is not None:
            hot.axhline(max_temperature_C, color="k", ls="--", lw=0.8, label="interface limit")
        hot.set(xlabel="time [s]", ylabel="temperature [degC]",
                title=f"peak: interface {summary['peak_interface_temperature_C']:.1f} degC,\nfriction plates "
                      f"{summary['peak_friction_plate_temperature_C']:.1f} degC (bulk)")
        if summary["engagement_time_s"] is not None:
            hot.axvline(summary["engagement_time_s"], color="0.5", lw=0.8, ls="--", label="lock-up")
        hot.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0)
    return _finish(fig, ax, run, path)


def overview_figure(run):
    """One figure of a run (``EngagementResult.plot``): films, speeds, clutch torque and pressure.

    Returns
    -------
    matplotlib.figure.Figure
    """
    res, model = run.result, run.model
    t = res.t
    fig = Figure(figsize=(11.0, 7.0), layout="constrained")
    FigureCanvasAgg(fig)
    axes = [fig.add_subplot(2, 2, k + 1) for k in range(4)]
    for i in range(model.n):
        axes[0].plot(t, res[f"h_{i + 1}_m"] * 1e6, label=f"film {i + 1}")
    axes[0].set(ylabel="film thickness [um]", yscale="log", title="oil films")
    fig.suptitle(scene_title(model.scene, "engagement"))
    axes[1].plot(t, res["w_in_rad_s"], label="input")
    axes[1].plot(t, res["w_out_rad_s"], label="output")
    axes[1].set(ylabel="speed [rad/s]", title="speeds")
    axes[2].plot(t, res["viscous_torque_Nm"], label="viscous")
    axes[2].plot(t, res["contact_torque_Nm"], label="asperity contact")
    axes[2].plot(t, res["total_torque_Nm"], "k", lw=1.5, label="total")
    axes[2].set(ylabel="clutch torque [N m]", title="torque")
    axes[3].plot(t, res["pressure_Pa"] / 1e6, label="pressure")
    axes[3].set(ylabel="pressure [MPa]", title="actuation pressure")
    for ax in axes:
        ax.set_xlabel("time [s]")
        ax.grid(alpha=0.3)
        _mark_lockup(ax, run)
        ax.legend(fontsize=7)
    return finish(fig)
