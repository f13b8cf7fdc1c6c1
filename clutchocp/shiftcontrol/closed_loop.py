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


def run_closed_loop(scene, feedback, t_end, *, nominal_scene=None, model=None, rtol=None, atol=None):
    """The slip feedback on the exact model of ``scene`` (sample and hold), through lock-up, to ``t_end``.

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
