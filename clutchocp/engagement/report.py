"""Files of an engagement run: summary.json, timeseries.csv and PNG figures."""

from pathlib import Path

import numpy as np

from ..output import new_figure, save_figure, write_csv, write_summary


def write_engagement(run, out_dir):
    """Write the summary, the time series and the figures of an engagement run.

    Parameters
    ----------
    run : clutchocp.engagement.run.EngagementResult
    out_dir : str or pathlib.Path
        Created if needed.

    Returns
    -------
    list of pathlib.Path
        The files written.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    series = run.series()
    columns = {name: [str(v) for v in values] if name == "mode" else np.asarray(values, dtype=float)
               for name, values in series.items()}
    files = [write_summary(out / "summary.json", run.summary), write_csv(out / "timeseries.csv", columns)]
    files += plot_engagement(run, out)
    return files


def _finish(fig, ax, run, path, legend=True):
    """Mark the lock-up time, add the legend and save the figure; returns its path."""
    t_lock = run.summary["engagement_time_s"]
    if t_lock is not None:
        ax.axvline(t_lock, color="0.5", lw=0.8, ls="--", label="lock-up")
    if legend:
        ax.legend(fontsize=8)
    return save_figure(fig, path)


def plot_engagement(run, out):
    """Gaps, speeds, torque components and pressure against time, one PNG each."""
    res, model, name = run.result, run.model, run.summary["scene"]
    t = res.t
    files = []

    fig, (ax,) = new_figure()
    for i in range(model.n):
        ax.plot(t, res[f"h_{i + 1}_m"] * 1e6, label=f"film {i + 1}")
    ax.set(xlabel="time [s]", ylabel="film thickness [um]", title=f"{name}: oil films")
    ax.set_yscale("log")
    files.append(_finish(fig, ax, run, out / "gaps.png"))

    fig, (ax,) = new_figure()
    ax.plot(t, res["w_in_rad_s"], label="input")
    ax.plot(t, res["w_out_rad_s"], label="output")
    ax.set(xlabel="time [s]", ylabel="speed [rad/s]", title=f"{name}: speeds")
    files.append(_finish(fig, ax, run, out / "speeds.png"))

    fig, (ax,) = new_figure()
    ax.plot(t, res["viscous_torque_Nm"], label="viscous")
    ax.plot(t, res["contact_torque_Nm"], label="asperity contact")
    ax.plot(t, res["total_torque_Nm"], "k", lw=1.5, label="total")
    ax.set(xlabel="time [s]", ylabel="clutch torque [N m]", title=f"{name}: torque components")
    files.append(_finish(fig, ax, run, out / "torque.png"))

    fig, (ax,) = new_figure()
    ax.plot(t, res["pressure_Pa"] / 1e6)
    ax.set(xlabel="time [s]", ylabel="pressure [MPa]", title=f"{name}: engagement pressure")
    files.append(_finish(fig, ax, run, out / "pressure.png", legend=False))
    files.append(plot_heat(run, out / "heat.png"))
    return files


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
           title=f"specific energy {summary['specific_energy_J_mm2']:.3g} J/mm^2 "
                 f"over {summary['friction_area_mm2']:.0f} mm^2 of friction area")
    fig.suptitle(f"{summary['scene']}: heat of {what} at the friction interfaces")
    if model.thermal.present:
        hot = axes[0]
        hot.plot(t, res["interface_temperature_C"], "k", lw=1.5, label="interface (contact)")
        hot.plot(t, res["T_separator"], "C0", label="separators (bulk)")
        hot.plot(t, res["T_friction"], "C1", label="friction plates (bulk)")
        hot.axhline(model.thermal.T_oil, color="C2", ls=":", label="oil")
        if max_temperature_C is not None:
            hot.axhline(max_temperature_C, color="k", ls="--", lw=0.8, label="interface limit")
        hot.set(xlabel="time [s]", ylabel="temperature [degC]",
                title=f"peak interface temperature {summary['peak_interface_temperature_C']:.1f} degC (lumped)")
        if summary["engagement_time_s"] is not None:
            hot.axvline(summary["engagement_time_s"], color="0.5", lw=0.8, ls="--", label="lock-up")
        hot.legend(fontsize=8)
    return _finish(fig, ax, run, path)


def format_summary(summary):
    """A few lines for the terminal."""
    def num(key, unit, fmt="{:.4g}"):
        value = summary[key]
        return "never" if value is None else f"{fmt.format(value)} {unit}"

    lines = [
        f"scene {summary['scene']}: {summary['n_states']} states, final mode {summary['final_mode']}",
        f"  engagement (lock-up) time   {num('engagement_time_s', 's')}",
        f"  lock-up torque jump         {num('lockup_torque_jump_Nm', 'N m')}",
        f"  peak torque                 {num('peak_torque_Nm', 'N m')}",
        f"  peak output jerk            {num('peak_jerk_rad_s3', 'rad/s^3')}",
        f"  dissipated energy           {num('dissipated_energy_J', 'J')}",
        f"  specific energy             {num('specific_energy_J_mm2', 'J/mm^2', '{:.4g}')}",
        f"  peak specific power         {num('peak_specific_power_W_mm2', 'W/mm^2', '{:.4g}')}",
        *([f"  peak interface temperature  {num('peak_interface_temperature_C', 'degC', '{:.1f}')}"]
          if "peak_interface_temperature_C" in summary else []),
        f"  energy balance error        {num('energy_balance_rel_error', '(relative)', '{:.2e}')}",
        f"  wall time                   {num('wall_time_s', 's', '{:.3f}')}",
    ]
    return "\n".join(lines)
