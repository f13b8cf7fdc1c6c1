"""``clutchocp control``: static map, linearisation, controller design and closed loop of an HVD scene.

:func:`run_control` runs the whole chain on a scene and a controller spec, prints a short summary
and writes into ``out_dir``:

* ``summary.json``  operating point, linear model (poles, zeros, DC gains), margins at every
  scheduled point, closed-loop metrics on the nonlinear plant (units in the key names);
* ``static_map.csv``, ``design_points.csv``, ``closed_loop.csv`` (time series);
* ``static_map.png``, ``bode.png``, ``step.png`` (linear closed loops), ``closed_loop.png``.
"""

import time
from pathlib import Path

import control
import numpy as np
from matplotlib.ticker import FormatStrFormatter, LogLocator, NullFormatter

from ..output import new_figure, save_figure, shown, write_csv, write_summary, writes_folder
from ..scene import Scene, load_scene
from .closed_loop import make_scenario, simulate_closed_loop
from .design import design, frequency_response, pressure_limits
from .model import HvdModel
from .spec import ControllerSpec, load_controller
from .steady import static_map

DEFAULT_CONTROLLER = "lqi"


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
    wall = time.perf_counter()
    scene = scene if isinstance(scene, Scene) else load_scene(scene)
    spec = controller if isinstance(controller, ControllerSpec) else load_controller(controller or DEFAULT_CONTROLLER)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    model = HvdModel(scene)
    data = static_map(model)
    sched = design(model, spec, map_data=data)
    scenario = make_scenario(model, spec)
    run = simulate_closed_loop(model, sched.controller, scenario)
    summary = _summary(model, spec, sched, run, data)
    summary["wall_time_s"] = time.perf_counter() - wall
    files = [write_summary(out / "summary.json", summary)]
    files += _write_tables(out, model, sched, run, data)
    files += _figures(out, model, spec, sched, run, data, scenario)
    if verbose:
        print(format_summary(summary))
        print(f"wrote {len(files)} files to {shown(out)}: {', '.join(f.name for f in files)}")
    return summary


def nominal_point(sched, scenario_fraction):
    """The design point closest to a speed fraction (the summary's operating point)."""
    return min(sched.points, key=lambda p: abs(p.fraction - scenario_fraction))


def _csv_margin(value):
    """A margin for the CSV: the number, or "inf" when there is no crossover."""
    return float(value) if np.isfinite(value) else "inf"


def _finite_or_none(value):
    return float(value) if np.isfinite(value) else None


def _summary(model, spec, sched, run, data):
    nominal = nominal_point(sched, spec.scenario["setpoints"][-1])
    op = nominal.point
    lin = nominal.linear
    worst = sched.worst_margins()
    inside = data["within_valve_range"] > 0
    metrics = dict(run.metrics)
    return {
        "scene": model.scene.name,
        "controller": spec.label,
        "controller_type": spec.type,
        "sample_time_s": spec.sample_time,
        "operating_point": {
            "speed_rad_s": op.speed,
            "speed_fraction_of_rated": op.speed / model.rated_speed,
            "pressure_Pa": op.pressure,
            "film_m": float(op.films[0]),
            "films_m": [float(h) for h in op.films],
            "film_ratio": op.outputs["film_ratio_1"],
            "viscous_torque_Nm": op.outputs["viscous_torque_Nm"],
            "contact_torque_Nm": op.outputs["contact_torque_Nm"],
            "contact_pressure_Pa": op.outputs["contact_pressure_Pa"],
        },
        "linear": {
            "states": list(model.x),
            "inputs": list(model.u),
            "outputs": ["w_out_rad_s"],
            "poles": lin["poles"],
            "zeros": lin["zeros_from_p_cmd"],
            "dc_gain_speed_per_pressure_rad_s_Pa": lin["dc_gain"]["w_out_rad_s/p_cmd"],
            "dc_gain_speed_per_load_rad_s_Nm": lin["dc_gain"]["w_out_rad_s/load_torque"],
        },
        "margins": {
            "gain_margin_dB": _finite_or_none(worst["gain_margin_dB"]),
            "phase_margin_deg": _finite_or_none(worst["phase_margin_deg"]),
            "sensitivity_peak": worst["sensitivity_peak"],
            "all_points_stable": all(p.margins["stable"] for p in sched.points),
            "points": [{"speed_fraction": p.fraction, "speed_rad_s": p.point.speed, "pressure_Pa": p.point.pressure,
                        "gain_margin_dB": _finite_or_none(p.margins["gain_margin_dB"]),
                        "phase_margin_deg": _finite_or_none(p.margins["phase_margin_deg"]),
                        "sensitivity_peak": p.margins["sensitivity_peak"],
                        "crossover_rad_s": p.margins["crossover_rad_s"],
                        "poles": p.linear["poles"]} for p in sched.points],
        },
        "closed_loop": metrics,
        "static_map": {
            "speed_min_in_valve_range_rad_s": float(data["speed_rad_s"][inside].min()) if inside.any() else None,
            "speed_max_in_valve_range_rad_s": float(data["speed_rad_s"][inside].max()) if inside.any() else None,
            "pressure_min_Pa": model.p_min,
            "pressure_max_Pa": model.p_max,
        },
    }


def format_summary(summary):
    """A few lines for the terminal."""
    op, m, cl = summary["operating_point"], summary["margins"], summary["closed_loop"]
    poles = ", ".join(f"{re:.3g}{im:+.3g}j" if im else f"{re:.3g}" for re, im in summary["linear"]["poles"])
    gm = "inf" if m["gain_margin_dB"] is None else f"{m['gain_margin_dB']:.1f}"
    lines = [
        (f"scene {summary['scene']}, controller {summary['controller']} ({summary['controller_type']}, "
         f"Ts = {summary['sample_time_s'] * 1e3:g} ms, {len(m['points'])} scheduled points)"),
        (f"  operating point      {op['speed_rad_s']:.4g} rad/s ({100 * op['speed_fraction_of_rated']:.0f} % rated) at "
         f"{op['pressure_Pa'] / 1e6:.4g} MPa, film {op['film_m'] * 1e6:.3g} um (H = {op['film_ratio']:.3g})"),
        f"  linear poles         {poles} 1/s",
        (f"  worst margins        gain {gm} dB, phase {m['phase_margin_deg']:.1f} deg, |S| peak "
         f"{m['sensitivity_peak']:.2f}"),
        (f"  nonlinear closed loop overshoot {cl['overshoot_pct']:.2f} %, 2 % settling {cl['settling_time_s']:.2f} s, "
         f"steady-state error {100 * cl['steady_state_error_rel']:.2g} %"),
        (f"                       load step peak deviation {100 * cl['load_peak_deviation_rel']:.2f} %, peak dp/dt "
         f"{cl['peak_pressure_rate_Pa_s'] / 1e6:.3g} MPa/s, {cl['time_in_saturation_s']:.2f} s saturated, "
         f"limit cycle: {'yes' if cl['limit_cycle'] else 'no'}"),
        f"  wall time            {summary['wall_time_s']:.1f} s",
    ]
    return "\n".join(lines)


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


def _figures(out, model, spec, sched, run, data, scenario):
    files = []
    rated = model.rated_speed
    # static map
    fig, (a1, a2) = new_figure(2, width=5.2)
    inside = data["within_valve_range"] > 0
    a1.plot(data["pressure_Pa"] / 1e6, data["speed_rad_s"] / rated * 100, "-", color="0.6", label="outside valve range")
    a1.plot(data["pressure_Pa"][inside] / 1e6, data["speed_rad_s"][inside] / rated * 100, "-", lw=2, label="in range")
    a1.plot([p.point.pressure / 1e6 for p in sched.points], [100 * p.point.speed / rated for p in sched.points],
            "ko", mfc="none", label="scheduled points")
    for k, lim in enumerate((model.p_min, model.p_max)):
        a1.axvline(lim / 1e6, color="0.5", ls=":", lw=0.8, label="valve limits" if k == 0 else None)
    a1.set(xlabel="control pressure [MPa]", ylabel="output speed [% rated]", title=f"{model.scene.name}: static map")
    a1.legend(fontsize=8)
    a2.plot(data["film_ratio"], data["viscous_torque_Nm"], label="viscous")
    a2.plot(data["film_ratio"], data["contact_torque_Nm"], label="asperity")
    a2.set_xscale("log")
    a2.xaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))   # a log axis over less than a decade
    a2.xaxis.set_major_formatter(FormatStrFormatter("%g"))            # showed one label only
    a2.xaxis.set_minor_formatter(NullFormatter())
    a2.set(xlabel="film ratio h/sigma [-] (first film)", ylabel="torque [N m]", title="viscous to mixed friction")
    a2.legend(fontsize=8)
    for ax in (a1, a2):
        ax.grid(alpha=0.3)
    files.append(save_figure(fig, out / "static_map.png"))
    # Bode of the loop at every scheduled point
    fig, (a1, a2) = new_figure(2, width=5.2)
    for p in sched.points:
        omega = np.geomspace(1e-3, np.pi / spec.sample_time, 600)
        L = frequency_response(p.loop, omega)
        a1.loglog(omega, np.abs(L), label=f"{p.fraction:g} rated")
        a2.semilogx(omega, np.degrees(np.unwrap(np.angle(L))))
    a1.axhline(1.0, color="0.5", lw=0.8)
    a2.axhline(-180.0, color="0.5", lw=0.8)
    a1.set(xlabel="frequency [rad/s]", ylabel="|L|", title=f"loop gain ({spec.label}, broken at the plant input)")
    a2.set(xlabel="frequency [rad/s]", ylabel="phase of L [deg]", title="loop phase")
    a1.legend(fontsize=7)
    for ax in (a1, a2):
        ax.grid(alpha=0.3, which="both")
    files.append(save_figure(fig, out / "bode.png"))
    # linear closed-loop steps (reference filter included)
    fig, (ax,) = new_figure()
    t = np.arange(0.0, 10.0, spec.sample_time)
    for p in sched.points:
        y = linear_step(p, sched.controller, spec, t)
        ax.plot(t, y, label=f"{p.fraction:g} rated")
    ax.set(xlabel="time [s]", ylabel="speed / setpoint step [-]", title="linear closed loop, unit setpoint step")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    files.append(save_figure(fig, out / "step.png"))
    # nonlinear closed loop
    s = run.series
    fig, axes = new_figure(3, width=4.6)
    axes[0].plot(s["t"], s["w"] / rated * 100, label="speed")
    axes[0].plot(s["t"], s["setpoint"] / rated * 100, "k:", lw=1, label="setpoint")
    axes[0].plot(s["t"], s["reference"] / rated * 100, "--", lw=1, label="filtered reference")
    axes[0].set(xlabel="time [s]", ylabel="output speed [% rated]", title=f"{model.scene.name}, {spec.label}")
    axes[0].legend(fontsize=8)
    axes[1].plot(s["t"], s["command"] / 1e6, label="command")
    axes[1].plot(s["t"], s["p"] / 1e6, label="valve pressure")
    p_lo, p_hi = pressure_limits(model, spec)
    axes[1].axhline(p_hi / 1e6, color="C3", ls="--", lw=0.8, label=f"valve limits {p_lo / 1e6:.3g} / {p_hi / 1e6:.3g} MPa")
    axes[1].axhline(p_lo / 1e6, color="C3", ls="--", lw=0.8)
    axes[1].set(xlabel="time [s]", ylabel="pressure [MPa]", title="control pressure")
    axes[1].legend(fontsize=8)
    for name in model.film_names:
        axes[2].semilogy(s["t"], s[name] * 1e6, label=name)
    axes[2].set(xlabel="time [s]", ylabel="film [um]", title="film thickness")
    step = spec.scenario["load_step"]
    for ax in axes:
        ax.grid(alpha=0.3)
        for k, t_step in enumerate(scenario.load_times):
            ax.axvline(t_step, color="0.3", ls=":", lw=1.0,
                       label=f"load steps: +{100 * step:g} %, then -{100 * step:g} % of the fan torque" if k == 0
                       else None)
    for ax in axes[:2]:
        ax.legend(fontsize=7)
    files.append(save_figure(fig, out / "closed_loop.png"))
    return files


def linear_step(point, controller, spec, t):
    """Speed response of the linear closed loop at a design point to a unit setpoint step.

    The controller is linearised as implemented: its gains at the point, the slopes of the
    interpolated trim u_op(r), x_op(r) on the interval above the point, and the setpoint filter.
    """
    Ts = spec.sample_time
    g_ff, state_per_speed = controller.schedule_slopes(point.point.speed)
    loop = point.closed_loop(Ts, g_ff, state_per_speed)
    if controller.reference_time_constant > 0:
        a = np.exp(-Ts / controller.reference_time_constant)
        stage = control.ss([[a]], [[1 - a]], [[1.0]], [[0.0]], dt=Ts)
        loop = control.series(stage, stage, loop)
    _, y = control.forced_response(loop, T=t, U=np.ones_like(t))
    return np.asarray(y).ravel()
