"""Design of the TCU's slip controller with a Kalman filter (``[estimator] method = "kalman"``).

1. Replay the feedforward on the exact nominal model with IDAS (as :func:`~clutchocp.shiftcontrol.design.
   design_slip_feedback`): the nominal trajectory, its lock-up time t_lock, the samples t_0 .. t_N-1.
2. The TCU's model per sample (:class:`~clutchocp.shiftcontrol.observer.TCUModelBuilder`): the exact
   slip linearisation with the estimated parameters' columns, the pressure sensor's lag and offset,
   the valve dead time the TCU assumes; its noise from the sensor models and the spec.
3. The time-varying Kalman filter on it (:func:`clutchocp.control.kalman.tvkf`).
4. The time-varying LQR (:func:`clutchocp.control.lqr.tvlqr`) on the same model augmented with the
   slip-error integral z_k+1 = z_k + dt_k (slip row) xi_k, with the weights of the spec on scaled
   deviations (Bryson's rule, as the difference design): the parameters and the previous correction
   are states too, so the gains on them are the feedforward that compensates a clutch the estimate
   says is off (uncontrollable constants with no weight of their own: the finite-horizon Riccati
   recursion needs no stabilisability).
5. The lock-up threshold: ``lock.slip``, or 4 standard deviations of the measured slip at the nominal
   lock-up speed (the two speed readings' variances), and the clamp pressure of the design scene.
"""

from dataclasses import dataclass

import numpy as np

from ..control.lqr import tvlqr
from ..engagement.run import EngagementResult
from ..errors import ModelError
from ..optimal.clamp import DEFAULT_MARGIN, ClampModel
from ..optimal.replay import CommandModel, simulate_command
from .design import _slip_trajectory, feedforward_lock, pressure_limits
from .linearize import parametric_linearization
from .observer import TCUModel, TCUModelBuilder, sample_grid
from .sensors import first_order_lag
from .tcu import TCUFeedback

LOCK_SIGMAS = 4.0        # the automatic lock-up threshold, in standard deviations of the measured slip


@dataclass
class TCUDesign:
    """The designed controller and what it was designed on."""

    feedback: TCUFeedback
    nominal: EngagementResult
    t_lock: float
    model: TCUModel
    K: np.ndarray              # (N, n + 1)
    M: np.ndarray              # (N, n, p)
    P_prior: np.ndarray        # (N + 1, n, n)
    P_post: np.ndarray         # (N, n, n)
    builder: TCUModelBuilder = None    # the model's builder (its sample maps along moved trajectories)


def check_parameters(scene, names):
    """The estimated parameters must be numeric fields of the scene (ModelError naming the field otherwise)."""
    for name in names:
        try:
            value = scene.value(name)
        except Exception:
            raise ModelError(f"estimator.parameters.\"{name}\": the scene '{scene.name}' has no such field") from None
        if isinstance(value, bool) or not isinstance(value, (int, float)) or value == 0:
            raise ModelError(f"estimator.parameters.\"{name}\": must be a non-zero numeric field of the scene "
                             f"(its relative change is estimated), got {value!r}")


def design_tcu_feedback(scene, command_times, command, spec, sensors, *, model=None):
    """The TCU's slip controller with a Kalman filter for a feedforward on a scene (see the module docstring).

    Parameters
    ----------
    scene : clutchocp.scene.Scene
        The nominal (design) scene.
    command_times, command : array
        The feedforward [s], [Pa] (piecewise linear, last value held).
    spec : SlipControlSpec
        With ``estimator.method = "kalman"``.
    sensors : clutchocp.shiftcontrol.sensors.Sensors
    model : CommandModel, optional

    Returns
    -------
    TCUDesign
    """
    if scene.get("driveline.input") != "inertia" or scene.get("driveline.output", "inertia") != "inertia" \
            or scene.get("driveline.shaft_stiffness") is not None:
        raise ModelError("estimator.method = \"kalman\": needs driveline.input = \"inertia\", driveline.output = "
                         "\"inertia\" and no shaft compliance (the filter reads both rigid rotors' speeds)")
    names = tuple(spec.estimated_parameters)
    check_parameters(scene, names)
    model = model or CommandModel(scene, "linear")
    Ts = spec.sample_time
    times, values = np.asarray(command_times, float), np.asarray(command, float)
    p_lo, p_hi = pressure_limits(scene, spec)
    horizon, t_lock, starts = feedforward_lock(scene, times, values, Ts, model)
    D = sensors.valve.assumed_dead_time
    grid = sample_grid(starts, t_lock, Ts, D)
    nominal = simulate_command(scene, times, values, min(horizon, t_lock + 2 * Ts), model=model, control="linear",
                               points=101, extra_times=grid[grid < t_lock])
    lin = parametric_linearization(scene, names)
    t_slip, x_slip, z_slip = _slip_trajectory(nominal, lin.all_states, lin.z_names)

    def trajectory(t):
        t = min(t, t_slip[-1])
        x = np.array([np.interp(t, t_slip, x_slip[:, j]) for j in range(x_slip.shape[1])])
        z = np.array([np.interp(t, t_slip, z_slip[:, j]) for j in range(z_slip.shape[1])])
        return x, z, float(np.interp(t, times, values))

    pressure_reference = _pressure_reference(sensors, t_slip, x_slip[:, lin.all_states.index("p_valve")]) \
        if "p_valve" in lin.all_states and sensors.pressure is not None else None
    builder = TCUModelBuilder(lin, trajectory, sensors, spec,
                              (scene.value("driveline.input_inertia"), scene.value("driveline.output_inertia")),
                              scene.value("driveline.input_torque"), pressure_reference)
    tcu_model = builder.build(starts, t_lock, Ts)
    M, P_prior, P_post = tcu_model.kalman()
    w_rel0 = float(trajectory(0.0)[0][lin.all_states.index("w_in")] - trajectory(0.0)[0][lin.all_states.index("w_out")])
    K = _tcu_lqr(spec.lqi, tcu_model, w_rel0, t_lock, p_hi - p_lo)
    lock = next((e for e in nominal.result.events if e.name == "lockup"), None)
    w_lock = lock.x_after["w_in"] if lock is not None and "w_in" in lock.x_after else float(x_slip[-1, 0])
    lock_slip = spec.lock["slip"]
    if lock_slip is None:
        variance = sensors.input_speed.variance(w_lock, Ts) + sensors.output_speed.variance(w_lock, Ts)
        lock_slip = max(LOCK_SIGMAS * np.sqrt(variance), 1e-9 * abs(w_lock))
    engagement = model.engagement
    clamp = ClampModel(scene, model=engagement, command=engagement.hybrid.u["pressure_command"]) \
        .clamp_pressure(DEFAULT_MARGIN)
    tables = {"A": tcu_model.A, "B": tcu_model.B, "H": tcu_model.H, "G_sub": tcu_model.G_sub, "u_sub": tcu_model.u_sub,
              "held_sub": tcu_model.held_sub, "C": tcu_model.C, "M": M, "K": K,
              "y_ref": tcu_model.y_ref, "slip_row": tcu_model.slip_row, "dt": tcu_model.durations,
              "u_ff": np.interp(starts + D, times, values), "t_ref": tcu_model.t_ref, "rate_ref": tcu_model.rate_ref}
    feedback = TCUFeedback(Ts, tcu_model.names, tcu_model.measured, tables, (times, values), D, p_lo, p_hi,
                           (p_hi - p_lo) / spec.rate_limit_time, spec.anti_windup, lock_slip, spec.lock["samples"],
                           clamp, scene.value("driveline.input_torque"))
    return TCUDesign(feedback, nominal, t_lock, tcu_model, K, M, P_prior, P_post, builder)


def _pressure_reference(sensors, t, p):
    """The noise-free pressure reading along the nominal valve pressure p(t): the sensor's lag integrated exactly."""
    readings = first_order_lag(t, p, sensors.pressure.lag, float(p[0]))
    return lambda time: float(np.interp(time, t, readings))


def _tcu_lqr(w, model, w_rel0, t_lock, p_range):
    """LQR gains (N, n + 1) on [xi; z] (Bryson's rule on slip, slip rate, integral and correction, as the
    difference design's :func:`~clutchocp.shiftcontrol.design._slip_lqr`).

    With ``correction_rate_tolerance`` the input is the change of the correction, v = du - du_prev (du_prev is
    a state of the TCU): the weight on v smooths the correction from sample to sample, and
    ``correction_tolerance`` weighs du itself; the gains returned act on the correction, du = -K [xi; z].

    The weight at the nominal lock-up is ``terminal_weight`` times the running one, or, with
    ``terminal_slip_tolerance`` and ``terminal_slip_rate_tolerance``, Bryson's rule on the slip and the slip
    rate there on their own (the integral keeps its running weight): the torque jump at lock-up is the
    inertia times the slip rate there, so the rate can be weighed harder than the slip, whose tight weight
    makes a slower clutch lock on time.
    """
    N, n = model.A.shape[0], model.A.shape[1]
    e_s, r_s, xi_s = abs(w_rel0), abs(w_rel0) / t_lock, abs(w_rel0) * t_lock
    j = model.names.index("du_prev")
    rate = w.get("correction_rate_tolerance")

    def weight(slip_row, rate_row, slip_tolerance=w["slip_tolerance"], rate_tolerance=w["slip_rate_tolerance"]):
        Q = np.zeros((n + 1, n + 1))
        Q[:n, :n] = (np.outer(slip_row, slip_row) / (slip_tolerance * e_s) ** 2
                     + np.outer(rate_row, rate_row) / (rate_tolerance * r_s) ** 2)
        Q[n, n] = 1.0 / (w["integral_tolerance"] * xi_s) ** 2
        if rate:
            Q[j, j] = 1.0 / (w["correction_tolerance"] * p_range) ** 2
        return Q

    A, B, Q = [], [], []
    for k in range(N):
        Ak = np.eye(n + 1)
        Ak[:n, :n] = model.A[k]
        Ak[n, :n] = model.durations[k] * model.slip_row[k]
        Bk = np.append(model.B[k], 0.0)[:, None]
        if rate:                      # du = du_prev + v
            Ak[:, j] += Bk[:, 0]
        A.append(Ak)
        B.append(Bk)
        Q.append(weight(model.slip_row[k], model.slip_rate_row[k]))
    tolerance = rate if rate else w["correction_tolerance"]
    R = [np.array([[1.0 / (tolerance * p_range) ** 2]])] * N
    if w.get("terminal_slip_tolerance") is not None:
        terminal = weight(model.slip_row_end, model.slip_rate_end, w["terminal_slip_tolerance"],
                          w["terminal_slip_rate_tolerance"])
    else:
        terminal = w["terminal_weight"] * weight(model.slip_row_end, model.slip_rate_end)
    K, _ = tvlqr(A, B, Q, R, terminal)
    K = K[:, 0, :]
    if rate:                          # v = -K_v [xi; z]: du = du_prev + v = -(K_v - e_du_prev) [xi; z]
        K[:, j] -= 1.0
    return K
