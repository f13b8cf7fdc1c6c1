"""Engagement runs of a command strategy on the exact model with IDAS: open loop, or slip feedback sampled and held.

The closed loop advances the hybrid engagement model (the simulation engine with its lock-up
events, :func:`clutchocp.simulation.simulate`) one TCU sample at a time: at t_k the feedback reads
the state's speeds (and pressure), returns its correction du[k], and the model is integrated over
[t_k, t_k + Ts] under u_ff(t) + du[k]. At the first sample after lock-up the controller hands over to
the clamp ramp (:func:`post_lock_command`), run in one piece to the end. The pieces are stitched into
one :class:`~clutchocp.simulation.result.SimulationResult`, summarised like any engagement run.
"""

import time

import numpy as np

from ..engagement.run import EngagementResult, summarize
from ..optimal.clamp import extend_to_clamp
from ..optimal.replay import CommandModel, simulate_command
from ..simulation import SimulationOptions, simulate
from ..simulation.result import SimulationResult
from .sensors import PressureSensor, Sensors
from .tcu import clipped_command

POINTS_PER_SAMPLE = 11       # output points per TCU sample (1 ms at 10 ms) for jerk integrals


def post_lock_command(scene, times, values, t_lock, rate_limit):
    """The command continued after lock-up: (times, values) [s], [Pa], piecewise linear.

    The command up to ``t_lock`` followed by a ramp at ``rate_limit`` [Pa/s] to the clamp pressure
    (:func:`clutchocp.optimal.clamp.extend_to_clamp`, as the robust optimisation continues its command).
    """
    times, values = np.asarray(times, float), np.asarray(values, float)
    t_out, p_out = extend_to_clamp(scene, times, values, t_lock, rate_limit=rate_limit)
    return np.asarray(t_out, float), np.asarray(p_out, float)


def _options(scene, rtol=None, atol=None):
    return SimulationOptions(rtol=rtol or scene.value("simulation.rtol"), atol=atol or scene.value("simulation.atol"),
                             chunk=32, chunk_growth=2.0)


def run_open_loop(scene, times, values, t_end, *, model=None, rtol=None, atol=None):
    """IDAS run of a piecewise-linear command (through ``times``, ``values``; last value held) to ``t_end``.

    Output points every 1 ms, as the closed loop's at 10 ms (``POINTS_PER_SAMPLE``), so that jerk integrals
    are taken on the same grid. Returns an EngagementResult.
    """
    points = int(round(t_end / 0.001)) + 1
    return simulate_command(scene, times, values, t_end, model=model, control="linear", points=points,
                            rtol=rtol, atol=atol)


def run_closed_loop(scene, feedback, t_end, *, nominal_scene=None, model=None, rtol=None, atol=None, sensors=None):
    """The slip feedback on the exact model of ``scene`` (sample and hold), through lock-up, to ``t_end``.

    A :class:`~clutchocp.shiftcontrol.tcu.TCUFeedback` (Kalman filter) runs through :func:`run_tcu_loop`
    with the realised ``sensors``; the difference controller reads the exact states.

    Parameters
    ----------
    scene : clutchocp.scene.Scene
        The clutch the controller meets (e.g. a Monte Carlo sample).
    feedback : clutchocp.shiftcontrol.controller.SlipFeedback
        Designed on the nominal scene; reset here.
    t_end : float
        End of the run [s].
    nominal_scene : clutchocp.scene.Scene, optional
        The scene the TCU knows (for the clamp ramp; default: ``scene``).
    model : CommandModel, optional
        Linear command model of ``scene`` already built.

    Returns
    -------
    (EngagementResult, dict)
        The stitched run and the TCU record: ``t`` [s], ``command_Pa``, ``correction_Pa``,
        ``command_unsat_Pa``, ``integral_rad``, ``scale`` and ``shift_Pa`` (the
        feedforward adaptation's, 1 and 0 without it) per sample, and ``handover_s`` (None if it never locked).
    """
    if getattr(feedback, "kind", None) == "kalman":
        return run_tcu_loop(scene, feedback, t_end, sensors=sensors, model=model, rtol=rtol, atol=atol)
    start = time.perf_counter()
    model = model or CommandModel(scene, "linear")
    eng = model.engagement
    options = _options(scene, rtol, atol)
    Ts = feedback.Ts
    feedback.reset()
    x = dict(zip(eng.state_names, eng.initial_state))
    mode = eng.initial_mode()
    segments, events, record = [], [], {k: [] for k in ("t", "command_Pa", "correction_Pa", "command_unsat_Pa",
                                                       "integral_rad", "scale", "shift_Pa")}
    handover = None
    k = 0
    t = 0.0
    while t < t_end - 1e-12:
        if not mode.endswith("locked"):
            signals = {name: x[name] for name in ("w_in", "w_out", "p_valve") if name in x}
            du, u_k, u_unsat = feedback.step(k, signals)
            record["t"].append(t)
            record["command_Pa"].append(u_k)
            record["correction_Pa"].append(du)
            record["command_unsat_Pa"].append(u_unsat)
            record["integral_rad"].append(feedback.integral)
            record["scale"].append(feedback.scale)
            record["shift_Pa"].append(feedback.shift_Pa)
        if mode.endswith("locked") or feedback.finished:
            # hand over to the clamp ramp, from the command the TCU applies now
            u_now = feedback.feedforward(t - feedback.shift) + (record["correction_Pa"][-1] if record["t"] else 0.0)
            before = np.asarray(record["t"]) < t - 1e-12
            c_times, c_values = post_lock_command(nominal_scene or scene, np.append(np.asarray(record["t"])[before], t),
                                                  np.append(np.asarray(record["command_Pa"])[before], u_now), t,
                                                  feedback.rate_limit)
            handover = t
            grid = np.linspace(t, t_end, max(int(round((t_end - t) / 0.001)), 2) + 1)
            piece = simulate(model.hybrid, x, grid, mode=mode, u=model.inputs(c_times, c_values), options=options)
            segments += piece.segments
            events += piece.events
            break
        t_next = min(t + Ts, t_end)
        u = model.inputs(feedback.ff_times + feedback.shift, feedback.ff_values + du)
        piece = simulate(model.hybrid, x, np.linspace(t, t_next, POINTS_PER_SAMPLE), mode=mode, u=u, options=options)
        segments += piece.segments
        events += piece.events
        mode = piece.final_mode
        x = {name: piece.final(name) for name in eng.state_names}
        k += 1
        t = k * Ts
    result = SimulationResult.from_segments(segments, events, {})
    summary = summarize(eng, result, time.perf_counter() - start, options, "idas")
    tcu = {key: np.asarray(v, float) for key, v in record.items()}
    tcu["handover_s"] = handover
    return EngagementResult(eng, result, summary), tcu


def run_tcu_loop(scene, feedback, t_end, *, sensors=None, model=None, rtol=None, atol=None):
    """The Kalman-filter controller (:class:`~clutchocp.shiftcontrol.tcu.TCUFeedback`) on the exact model of
    ``scene`` with its sensors and valve dead time, through lock-up, to ``t_end``.

    The plant's valve receives the TCU's output the dead time D_p later, so the plant is integrated in
    pieces [t_k + D_p, t_k+1 + D_p] under u_ff(t - D_p + D) + du_k (D the dead time the TCU assumes), clipped
    to the TCU's pressure limits (the valve's range);
    the sensors are fed the plant's speeds and pressure as they come and read at t_k. The TCU hands
    over to the clamp ramp once it has seen the measured slip within its lock-up threshold for its
    number of samples (or its design's horizon has run out); the ramp reaches the plant D_p later too.

    Parameters
    ----------
    scene : clutchocp.scene.Scene
        The clutch the controller meets.
    feedback : TCUFeedback
    t_end : float
    sensors : clutchocp.shiftcontrol.sensors.SensorSet, optional
        The realised sensors of this clutch (default: exact readings, no dead time).
    model : CommandModel, optional

    Returns
    -------
    (EngagementResult, dict)
        The stitched run and the TCU record: ``t`` [s], ``command_Pa``, ``correction_Pa``, ``command_unsat_Pa``,
        ``integral_rad``, ``slip_reading_rad_s`` per sample, ``estimates`` (the parameter estimates per
        sample, by field), ``handover_s`` (None if it never handed over) and ``locked_at_handover``.
    """
    start = time.perf_counter()
    model = model or CommandModel(scene, "linear")
    eng = model.engagement
    options = _options(scene, rtol, atol)
    Ts = feedback.Ts
    feedback.reset()
    x = dict(zip(eng.state_names, eng.initial_state))
    mode = eng.initial_mode()
    initial = {name: x[name] for name in ("w_in", "w_out", "p_valve") if name in x}
    if sensors is None:
        sensors = Sensors(pressure=PressureSensor() if "p_valve" in x else None).realize(
            np.random.default_rng(0), initial, Ts)
    D_p = sensors.sensors.valve.dead_time
    torque_signal = sensors.sensors.engine_torque
    plant_torque = scene.get("driveline.input_torque", 0.0)
    params = [name for name in feedback.names if name.startswith("d:")]
    record = {key: [] for key in ("t", "command_Pa", "correction_Pa", "command_unsat_Pa", "integral_rad",
                                  "slip_reading_rad_s")}
    estimates = {name[2:]: [] for name in params}
    segments, events = [], []

    def run_piece(t0, t1, inputs, mode, x, extra=()):
        grid = np.unique(np.concatenate([np.linspace(t0, t1, POINTS_PER_SAMPLE), list(extra)]))
        piece = simulate(model.hybrid, x, grid, mode=mode, u=inputs, options=options)
        segments.extend(piece.segments)
        events.extend(piece.events)
        sensors.advance(piece.t, piece["w_in"], piece["w_out"], piece["p_valve"] if "p_valve" in x else None)
        return piece.final_mode, {name: piece.final(name) for name in eng.state_names}

    if D_p > 0:          # before the first command arrives the valve keeps its initial command
        p0 = initial.get("p_valve", 0.0)
        mode, x = run_piece(0.0, D_p, model.inputs([0.0, 1.0], [p0, p0]), mode, x)
    handover, k = None, 0
    while k * Ts < t_end - 1e-12:
        t = k * Ts
        if feedback.locked or k >= feedback.horizon:
            handover = t
            break
        readings = sensors.read(t)
        readings["engine_torque"] = torque_signal.read(t, lambda _t: plant_torque, feedback.nominal_torque,
                                                       sensors.torque_error)
        du, u_k, u_unsat = feedback.step(k, readings)
        for key, value in zip(record, (t, u_k, du, u_unsat, feedback.integral, readings["w_in"] - readings["w_out"])):
            record[key].append(value)
        for name in params:
            estimates[name[2:]].append(feedback.estimate(name))
        t1 = min((k + 1) * Ts + D_p, t_end)
        inputs = model.inputs(*clipped_command(feedback.ff_times - feedback.advance + D_p, feedback.ff_values + du,
                                               feedback.p_min, feedback.p_max))
        mode, x = run_piece(t + D_p, t1, inputs, mode, x, extra=[(k + 1) * Ts] if (k + 1) * Ts < t1 else ())
        k += 1
    t_plant = k * Ts + D_p if handover is not None else None
    if handover is not None and t_plant < t_end:
        # the clamp ramp from the command the TCU sends now, reaching the valve D_p later
        u_now = feedback.feedforward(handover) + (record["correction_Pa"][-1] if record["t"] else 0.0)
        c_times, c_values = extend_to_clamp(scene, np.append(record["t"], handover)
                                            if not record["t"] or record["t"][-1] < handover else record["t"],
                                            np.append(record["command_Pa"], u_now)
                                            if not record["t"] or record["t"][-1] < handover else record["command_Pa"],
                                            handover, rate_limit=feedback.rate_limit,
                                            clamp_pressure=feedback.clamp_pressure)
        grid = np.linspace(t_plant, t_end, max(int(round((t_end - t_plant) / 0.001)), 2) + 1)
        piece = simulate(model.hybrid, x, grid, mode=mode, u=model.inputs(np.asarray(c_times) + D_p, c_values),
                         options=options)
        segments += piece.segments
        events += piece.events
        mode = piece.final_mode
    result = SimulationResult.from_segments(segments, events, {})
    summary = summarize(eng, result, time.perf_counter() - start, options, "idas")
    tcu = {key: np.asarray(v, float) for key, v in record.items()}
    tcu["estimates"] = {key: np.asarray(v, float) for key, v in estimates.items()}
    tcu["handover_s"] = handover
    return EngagementResult(eng, result, summary), tcu
