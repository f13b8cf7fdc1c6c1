"""IDAS runs of a given pressure command on the exact (non-smoothed) engagement model.

Used to verify an optimum (the collocation prediction against an independent integration with
event detection), to find the fastest lock-up the pressure limit allows and for baselines.
"""

import time
from dataclasses import replace

import casadi as ca
import numpy as np

from ..engagement.model import EngagementModel
from ..engagement.run import EngagementResult, summarize
from ..errors import ModelError
from .quiet import native_output_caught
from ..simulation import (
    HybridModel,
    Mode,
    PiecewiseConstant,
    SimulationOptions,
    simulate,
)

COMMAND = "pressure_command"


class CommandModel:
    """The exact engagement model of a scene driven by a pressure command input.

    Parameters
    ----------
    scene : clutchocp.scene.Scene
    control : {"constant", "linear"}
        Piecewise-constant command (the input itself) or piecewise-linear (the command is
        ``offset + slope * t`` with both piecewise constant, so the run restarts at every node).
    engagement, command : EngagementModel, casadi.SX, optional
        The exact model of ``scene`` already built with ``pressure_command=command`` (default: built here).
    """

    def __init__(self, scene, control="constant", engagement=None, command=None):
        self.scene = scene
        self.control = control
        if engagement is None:
            command = ca.SX.sym(COMMAND)
            engagement = EngagementModel(scene, smooth=False, pressure_command=command)
        u = command
        self.engagement = engagement
        if control == "constant":
            self.hybrid = self.engagement.hybrid
        elif control == "linear":
            self.hybrid = _linear_command(self.engagement, u)
        else:
            raise ModelError(f"control '{control}': allowed values are constant, linear")

    def inputs(self, times, values, hold=None):
        """Input schedules of a command given by its values at ``times``.

        Piecewise constant: ``values[k]`` from ``times[k]`` on. Piecewise linear: through the points
        (times, values). After the last time the command is ``hold = (t_hold, value)`` from t_hold on
        (default: the last value).
        """
        times, values = np.asarray(times, float), np.asarray(values, float)
        if times.size != values.size or times.size == 0:
            raise ModelError("a pressure command needs one value per time")
        if self.control == "constant":
            breaks, levels = list(times[1:]), list(values)
            if hold is not None:
                breaks.append(hold[0])
                levels.append(hold[1])
            if not breaks:
                return {COMMAND: float(levels[0])}
            return {COMMAND: PiecewiseConstant(breaks, levels)}
        slope = np.diff(values) / np.diff(times)
        offset = values[:-1] - slope * times[:-1]
        last = values[-1] if hold is None else hold[1]
        breaks = list(times[1:-1]) + [times[-1] if hold is None else hold[0]]
        return {"command_offset": PiecewiseConstant(breaks, np.concatenate([offset, [last]])),
                "command_slope": PiecewiseConstant(breaks, np.concatenate([slope, [0.0]]))}


def _linear_command(model, u):
    """The modes with the command replaced by offset + slope * t (jerk gets the d/du term)."""
    offset, slope = ca.SX.sym("command_offset"), ca.SX.sym("command_slope")
    command = offset + slope * model.t

    def sub(expr):
        return ca.substitute(ca.SX(expr), u, command)

    modes = []
    for mode in model.modes.values():
        outputs = {name: sub(expr) for name, expr in mode.outputs.items()}
        a_out = mode.outputs["output_acceleration_rad_s2"]
        outputs["output_jerk_rad_s3"] = sub(mode.outputs["output_jerk_rad_s3"] + ca.jacobian(a_out, u) * slope)
        # every field carried over: an edge (a film gap reaching zero) stays an edge, not a switch into
        # the same mode (which chattered when a held command pressed a locked pack beyond the contact)
        events = [replace(e, function=sub(e.function), reset={k: sub(v) for k, v in e.reset.items()} if e.reset else None,
                          guard=sub(e.guard) if e.guard is not None else None) for e in mode.events]
        modes.append(Mode(mode.name, mode.x, [sub(e) for e in mode.ode], outputs=outputs, events=events,
                          x_nominal=dict(zip(mode.x, mode.x_nominal))))
    return HybridModel(modes, u={"command_offset": offset, "command_slope": slope}, t=model.t)


def simulate_command(scene, times, values, t_end, *, hold=None, model=None, control="constant", points=2001,
                     extra_times=(), rtol=None, atol=None):
    """Simulate the exact model of ``scene`` under a pressure command with IDAS.

    Parameters
    ----------
    scene : clutchocp.scene.Scene
    times, values : sequence of float
        The command: values [Pa] from each time [s] on (constant) or at each node (linear); the
        last value holds afterwards ...
    t_end : float
        End of the run [s].
    hold : (float, float), optional
        ... unless ``hold = (t, value)``: the command is ``value`` from t on.
    model : CommandModel, optional
        A model already built for this scene and control kind.
    control : {"constant", "linear"}
    points : int
        Output points spread over [0, t_end] (the command times are added).
    extra_times : sequence of float
        More output times (e.g. a dense grid over the slip phase).
    rtol, atol : float, optional
        Tolerances (default: the scene's).

    Returns
    -------
    clutchocp.engagement.run.EngagementResult
    """
    model = model or CommandModel(scene, control)
    eng = model.engagement
    options = SimulationOptions(rtol=rtol or scene.value("simulation.rtol"),
                                atol=atol or scene.value("simulation.atol"), chunk=32, chunk_growth=2.0)
    grid = np.concatenate([np.linspace(0.0, t_end, points), np.asarray(times, float), np.asarray(extra_times, float),
                           [hold[0]] if hold is not None else []])
    grid = np.unique(grid[(grid >= 0) & (grid <= t_end)])
    x0 = dict(zip(eng.state_names, eng.initial_state))
    start = time.perf_counter()
    with native_output_caught():         # SUNDIALS' own warning lines: the run's result or error speaks for it
        result = simulate(model.hybrid, x0, grid, mode=eng.initial_mode(), u=model.inputs(times, values, hold),
                          options=options)
    wall = time.perf_counter() - start
    return EngagementResult(eng, result, summarize(eng, result, wall, options, "idas"))
