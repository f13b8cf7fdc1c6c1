"""The chain of ``clutchocp control`` on an HVD scene: static map, design, closed loop, the summary numbers.

:func:`control_workflow` computes; :mod:`clutchocp.hvd.figures` draws its results and
:mod:`clutchocp.hvd.report` writes them.
"""

import time
from dataclasses import dataclass

import control
import numpy as np

from ..scene import Scene, load_scene
from .closed_loop import make_scenario, simulate_closed_loop
from .design import design
from .model import HvdModel
from .spec import ControllerSpec, load_controller
from .steady import static_map

DEFAULT_CONTROLLER = "lqi"


@dataclass
class ControlRun:
    """Everything the chain computed on one scene and spec."""

    model: HvdModel
    spec: ControllerSpec
    map_data: dict          # static map (clutchocp.hvd.steady.static_map)
    design: object          # ScheduledDesign
    scenario: object        # Scenario of the closed-loop test
    closed_loop: object     # ClosedLoopResult on the nonlinear plant
    summary: dict           # the numbers of summary.json


def control_workflow(scene, controller=None):
    """Design and check a speed controller for an HVD scene (nothing written).

    Parameters
    ----------
    scene : Scene, str or pathlib.Path
        An HVD scene or its name/path (e.g. ``"liao2021_hvd"``).
    controller : ControllerSpec, str, pathlib.Path or None
        A controller spec or its name/path (``"lqi"``, ``"pi"``, a TOML file); None: ``"lqi"``.

    Returns
    -------
    ControlRun
        Its ``summary`` holds ``wall_time_s``, the time of the whole chain.
    """
    wall = time.perf_counter()
    scene = scene if isinstance(scene, Scene) else load_scene(scene)
    spec = controller if isinstance(controller, ControllerSpec) else load_controller(controller or DEFAULT_CONTROLLER)
    model = HvdModel(scene)
    data = static_map(model)
    sched = design(model, spec, map_data=data)
    scenario = make_scenario(model, spec)
    run = simulate_closed_loop(model, sched.controller, scenario)
    summary = summarize(model, spec, sched, run, data)
    summary["wall_time_s"] = time.perf_counter() - wall
    return ControlRun(model, spec, data, sched, scenario, run, summary)


def nominal_point(sched, scenario_fraction):
    """The design point closest to a speed fraction (the summary's operating point)."""
    return min(sched.points, key=lambda p: abs(p.fraction - scenario_fraction))


def _finite_or_none(value):
    return float(value) if np.isfinite(value) else None


def summarize(model, spec, sched, run, data):
    """The numbers of summary.json (without the wall time): operating point, linear model, margins, closed loop."""
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
