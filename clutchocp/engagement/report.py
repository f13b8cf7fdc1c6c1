"""The simulate command's files of an engagement run (summary.json, timeseries.csv, the PNG figures of
:mod:`clutchocp.engagement.figures`) and its lines for the terminal."""

from pathlib import Path

import numpy as np

from ..output import write_csv, write_summary
from .figures import plot_engagement, plot_heat  # noqa: F401  plot_heat: imported from here by the optimal floor


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
        f"  torque response (Zhang)     {num('torque_response_time_stable_s', 's')} to 90 % of the stable "
        f"{num('stable_torque_Nm', 'N m')}; {num('torque_response_time_s', 's')} to 90 % of the peak",
        f"  dissipated energy           {num('dissipated_energy_J', 'J')}",
        f"  specific energy             {num('specific_energy_J_mm2', 'J/mm^2', '{:.4g}')}",
        f"  peak specific power         {num('peak_specific_power_W_mm2', 'W/mm^2', '{:.4g}')}",
        *([f"  peak interface temperature  {num('peak_interface_temperature_C', 'degC', '{:.1f}')}"]
          if "peak_interface_temperature_C" in summary else []),
        f"  energy balance error        {num('energy_balance_rel_error', '(relative)', '{:.2e}')}",
        f"  wall time                   {num('wall_time_s', 's', '{:.3f}')}",
    ]
    return "\n".join(lines)
