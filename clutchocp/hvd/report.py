"""``clutchocp control``: static map, linearisation, controller design and closed loop of an HVD scene.

:func:`run_control` runs the whole chain on a scene and a controller spec, prints a short summary
and writes into ``out_dir``:

* ``summary.json``  operating point, linear model (poles, zeros, DC gains), margins at every
  scheduled point, closed-loop metrics on the nonlinear plant (units in the key names);
* ``static_map.csv``, ``design_points.csv``, ``closed_loop.csv`` (time series);
* ``static_map.png``, ``bode.png``, ``step.png`` (linear closed loops), ``closed_loop.png``.
"""

from pathlib import Path

import numpy as np

from ..output import shown, write_csv, write_summary, writes_folder
from .figures import draw_control
from .workflow import control_workflow, format_summary


@writes_folder
def run_control(scene, controller=None, out_dir="out/control", verbose=True):
    """Design and check a speed controller for an HVD scene; write the report files.

    Parameters
    ----------
    scene : Scene, str or pathlib.Path
        An HVD scene or its name/path (e.g. ``"liao2021_hvd"``).
    controller : ControllerSpec, str, pathlib.Path or None
        A controller spec or its name/path (``"lqi"``, ``"pi"``, a TOML file); None: ``"lqi"``.
    out_dir : str or pathlib.Path
        Output folder (created).
    verbose : bool
        Print the summary.

    Returns
    -------
    dict
        The contents of summary.json.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    result = control_workflow(scene, controller)
    files = [write_summary(out / "summary.json", result.summary)]
    files += _write_tables(out, result.model, result.design, result.closed_loop, result.map_data)
    files += draw_control(out, result)
    if verbose:
        print(format_summary(result.summary))
        print(f"wrote {len(files)} files to {shown(out)}: {', '.join(f.name for f in files)}")
    return result.summary


def _csv_margin(value):
    """A margin for the CSV: the number, or "inf" when there is no crossover."""
    return float(value) if np.isfinite(value) else "inf"


def _write_tables(out, model, sched, run, data):
    files = []
    cols = {"film_1_m": data["film_1_m"], "pressure_Pa": data["pressure_Pa"], "speed_rad_s": data["speed_rad_s"],
            "speed_fraction_of_rated": data["speed_rad_s"] / model.rated_speed,
            "film_ratio": data["film_ratio"], "viscous_torque_Nm": data["viscous_torque_Nm"],
            "contact_torque_Nm": data["contact_torque_Nm"], "contact_pressure_Pa": data["contact_pressure_Pa"],
            "within_valve_range": data["within_valve_range"].astype(int)}
    files.append(write_csv(out / "static_map.csv", cols))
    pts = sched.points
    cols = {"speed_fraction": [p.fraction for p in pts], "speed_rad_s": [p.point.speed for p in pts],
            "pressure_Pa": [p.point.pressure for p in pts], "film_1_m": [p.point.films[0] for p in pts],
            "k_p_Pa_s_rad": [p.k_p for p in pts], "k_i_Pa_rad": [p.k_i for p in pts]}
    for j, name in enumerate(model.x):
        cols[f"K_{name}"] = [p.K_x[j] for p in pts]
    cols["gain_margin_dB"] = [_csv_margin(p.margins["gain_margin_dB"]) for p in pts]
    cols["phase_margin_deg"] = [_csv_margin(p.margins["phase_margin_deg"]) for p in pts]
    cols["sensitivity_peak"] = [p.margins["sensitivity_peak"] for p in pts]
    cols["crossover_rad_s"] = [p.margins["crossover_rad_s"] for p in pts]
    files.append(write_csv(out / "design_points.csv", cols))
    s = run.series
    names = ["t", "setpoint", "reference", "w", "command", "p"] + model.film_names + [
        "load_input", "integral", "viscous_torque_Nm", "contact_torque_Nm", "clutch_torque_Nm", "load_torque_Nm",
        "contact_pressure_Pa", "pressure_rate_Pa_s"]
    units = {"t": "time_s", "setpoint": "setpoint_rad_s", "reference": "filtered_reference_rad_s",
             "w": "speed_rad_s", "command": "pressure_command_Pa", "p": "pressure_Pa", "load_input": "load_step_Nm",
             "integral": "integral_term_Pa"}
    cols = {units.get(n, f"{n}_m" if n.startswith("h_") else n): s[n] for n in names}
    files.append(write_csv(out / "closed_loop.csv", cols))
    return files
