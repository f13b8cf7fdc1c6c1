"""Baseline pressure profiles of a scene: a step, a linear ramp, Zhang's first-order lag, and the
calibration shape "fill pulse, hold, ramp" tuned by a small search.

Each fixed baseline is the scene with its [actuation] part replaced (same set pressure and limits),
simulated with IDAS; Zhang 2021 Eq. 7 is the lag P_s = P_o (1 - exp(-t / t_s)). The fill-pulse
baseline is a command under the optimum's own pressure and rate limits (:func:`tune_fill_pulse`).
"""

import numpy as np
from scipy.optimize import minimize

from ..engagement.run import simulate_engagement
from .replay import CommandModel, simulate_command
from .verify import JUMP_TOLERANCE, run_numbers

LAG_TIMES = (0.02, 0.04, 0.06, 0.08, 0.1)      # Zhang 2021's range of t_s [s]
RAMP_TIME = 0.1                                  # [s]
_PROFILE_KEYS = ("time_constant", "ramp_time", "file")


def baseline_scene(scene, kind, value=None):
    """The scene with the actuation replaced by a baseline profile.

    Parameters
    ----------
    scene : clutchocp.scene.Scene
    kind : {"step", "ramp", "first_order_lag"}
    value : float, optional
        Ramp time or lag time constant [s].

    Returns
    -------
    clutchocp.scene.Scene
    """
    overrides = {f"actuation.{key}": None for key in _PROFILE_KEYS}
    overrides["actuation.model"] = kind
    if kind == "ramp":
        overrides["actuation.ramp_time"] = value
    elif kind == "first_order_lag":
        overrides["actuation.time_constant"] = value
    return scene.with_overrides(overrides)


def baseline_label(scene):
    """Name of the scene's own profile as a baseline (a valve lag on a step is a first-order lag)."""
    variant = scene.variant("actuation")
    if variant in ("valve_lag", "first_order_lag"):
        return f"first-order lag, t_s = {scene.value('actuation.time_constant'):g} s"
    return variant


def simulate_baselines(scene, lags=LAG_TIMES, ramp_time=RAMP_TIME):
    """IDAS runs and numbers of the step, the ramp and the first-order lags.

    Returns
    -------
    dict
        ``{name: (EngagementResult, numbers)}`` with names ``step``, ``ramp_<T>s``, ``lag_<t_s>s``;
        ``numbers`` as :func:`clutchocp.optimal.verify.run_numbers`.
    """
    cases = {"step": baseline_scene(scene, "step"), f"ramp_{ramp_time:g}s": baseline_scene(scene, "ramp", ramp_time)}
    for t_s in lags:
        cases[f"lag_{t_s:g}s"] = baseline_scene(scene, "first_order_lag", t_s)
    out = {}
    for name, case in cases.items():
        run = simulate_engagement(case)
        out[name] = (run, run_numbers(run))
    return out


# -- the calibration shape "fill pulse, hold, ramp" -----------------------------------------------
FILL_PULSE_KEYS = ("pulse_pressure_Pa", "pulse_time_s", "hold_pressure_Pa", "hold_time_s", "ramp_rate_Pa_s")


def fill_pulse_command(pulse_pressure, pulse_time, hold_pressure, hold_time, ramp_rate, *, p_max, rate_limit,
                       p_initial=0.0):
    """Nodes of the piecewise-linear command "fill pulse, hold, ramp" [s, Pa].

    From ``p_initial`` the command rises at the rate limit to ``pulse_pressure`` and stays there
    until ``pulse_time`` (the fill pulse), moves at the rate limit to ``hold_pressure``, holds it for
    ``hold_time`` and then ramps at ``ramp_rate`` [Pa/s] up to ``p_max``: the same pressure and rate
    limits as the optimum (a step is a ramp at the rate limit).

    Returns
    -------
    (ndarray, ndarray)
        Times [s] and command values [Pa] of the nodes (linear in between, the last value after).
    """
    rise = abs(pulse_pressure - p_initial) / rate_limit
    t1 = max(pulse_time, rise)
    t2 = t1 + abs(pulse_pressure - hold_pressure) / rate_limit
    t3 = t2 + hold_time
    t4 = t3 + (p_max - hold_pressure) / ramp_rate
    times = np.array([0.0, rise, t1, t2, t3, t4])
    values = np.array([p_initial, pulse_pressure, pulse_pressure, hold_pressure, hold_pressure, p_max])
    keep = np.concatenate([[True], np.diff(times) > 1e-9])       # drop zero-length pieces
    return times[keep], values[keep]


def tune_fill_pulse(scene, *, jerk_cap, p_max, rate_limit, t_scale, jump_limit=JUMP_TOLERANCE, max_evaluations=60,
                    progress=None, model=None):
    """The "fill pulse, hold, ramp" command that locks up soonest with peak jerk <= ``jerk_cap`` and
    a lock-up jump within ``jump_limit`` of the locked torque (the conditions the optimum meets).

    A Nelder-Mead search (scipy) over the five parameters of :func:`fill_pulse_command` (pulse
    pressure 0-100 % of p_max, pulse time 0-40 ms, hold pressure 0-50 % of p_max, hold time 0-0.3 s,
    ramp rate 0.2-200 MPa/s on a log scale), each candidate simulated with IDAS on the exact model;
    the cost is the lock-up time over ``t_scale`` plus 50 log(1 + e_j) + 5 log(1 + e_s), with e_j the
    relative excess of the peak jerk over the cap and e_s that of |jump| over ``jump_limit`` x the
    locked torque (1000 if it never locks, so that any lock-up is better).

    Parameters
    ----------
    scene : clutchocp.scene.Scene
    jerk_cap : float
        Largest peak jerk allowed [rad/s^3] (fill and slip, as :func:`clutchocp.optimal.verify.run_numbers`).
    p_max, rate_limit : float
        Pressure [Pa] and rate [Pa/s] limits (those of the optimum).
    t_scale : float
        Reference engagement time [s] (cost scale, run length 4 x).
    jump_limit : float
        Largest |lock-up torque jump| over the locked torque.
    max_evaluations : int
        IDAS runs allowed to the search.
    progress : callable, optional
        Called with a line per 10 evaluations.
    model : clutchocp.optimal.replay.CommandModel, optional
        The piecewise-linear command model of ``scene`` already built.

    Returns
    -------
    dict
        ``parameters`` (FILL_PULSE_KEYS), ``times``/``command`` (the nodes), ``numbers`` (run_numbers
        of its IDAS run), ``run`` and ``evaluations``.
    """
    model = CommandModel(scene, "linear") if model is None else model
    p0 = scene.value("actuation.initial_pressure")
    cache = {}

    def params(z):
        z = np.clip(z, 0.0, 1.0)
        return (p_max * z[0], 0.04 * z[1], 0.5 * p_max * z[2], 0.3 * z[3], 10 ** (5.3 + 3.0 * z[4]))

    def evaluate(z):
        key = tuple(np.round(np.clip(z, 0.0, 1.0), 12))
        if key not in cache:
            times, values = fill_pulse_command(*params(z), p_max=p_max, rate_limit=rate_limit, p_initial=p0)
            run = simulate_command(scene, times, values, 4.0 * t_scale, model=model, control="linear", points=801)
            numbers = run_numbers(run)
            if numbers["engagement_time_s"] is None:
                cost = 1000.0
            else:
                excess = max(0.0, numbers["peak_jerk_rad_s3"] / jerk_cap - 1.0)
                locked = max(abs(numbers["locked_torque_Nm"]), 1e-9)
                jump = abs(numbers["lockup_torque_jump_Nm"]) / (jump_limit * locked)
                cost = (numbers["engagement_time_s"] / t_scale + 50.0 * np.log1p(excess)
                        + 5.0 * np.log1p(max(0.0, jump - 1.0)))
            cache[key] = (cost, times, values, run, numbers)
            if progress and len(cache) % 10 == 0:
                best = min(cache.values(), key=lambda c: c[0])
                progress(f"  fill-pulse baseline search: {len(cache)} runs, best cost {best[0]:.4g}")
        return cache[key][0]

    z0 = np.array([0.05, 0.25, 0.35, 0.1, 0.1])      # a soft fill (75 kPa for 10 ms), 0.26 MPa hold
    minimize(evaluate, z0, method="Nelder-Mead",
             options={"maxfev": max_evaluations, "initial_simplex": _simplex(z0), "xatol": 1e-3, "fatol": 1e-4})
    key, (cost, times, values, run, numbers) = min(cache.items(), key=lambda item: item[1][0])
    return {"parameters": dict(zip(FILL_PULSE_KEYS, params(np.array(key)))), "times": times, "command": values,
            "numbers": numbers, "run": run, "evaluations": len(cache), "cost": cost}


def _simplex(z0, step=0.25):
    """A starting simplex around z0 (steps towards the middle of [0, 1])."""
    rows = [z0]
    for i in range(z0.size):
        z = z0.copy()
        z[i] += step if z[i] < 0.5 else -step
        rows.append(z)
    return np.array(rows)
