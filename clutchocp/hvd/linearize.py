"""Exact linearisation of the HVD DAE at an operating point, as a python-control state space.

The Jacobians are CasADi's, the algebraic variables eliminated (:mod:`clutchocp.control.linearize`):
A = f_x - f_z g_z^-1 g_x, B = f_u - f_z g_z^-1 g_u, C = c_x - c_z g_z^-1 g_x, D = c_u - c_z g_z^-1 g_u.
"""

import casadi as ca
import control
import numpy as np

from ..control.linearize import jacobian_function, linear_model
from ..errors import ModelError

#: Output used for speed control.
SPEED_OUTPUT = "w_out_rad_s"


def _jacobian_function(model, outputs):
    key = tuple(outputs)
    cache = model.__dict__.setdefault("_jacobian_functions", {})
    if key not in cache:
        xv, zv, uv = model.vector("x"), model.vector("z"), model.vector("u")
        c = ca.vertcat(*[model.outputs[n] for n in outputs])
        cache[key] = jacobian_function("hvd_jacobians", [xv, zv, uv], xv, zv, uv, model.ode, model.alg, c)
    return cache[key]


def linearize(model, point, outputs=(SPEED_OUTPUT,)):
    """Linear model of the HVD at a steady state, algebraic variables eliminated.

    Parameters
    ----------
    model : HvdModel
    point : OperatingPoint
        From :func:`clutchocp.hvd.steady.operating_point` (any state/input pair works: the
        linearisation is about (x, z(x, u), u), steady or not).
    outputs : sequence of str
        Names of model outputs (default: the output speed ``w_out_rad_s``).

    Returns
    -------
    control.StateSpace
        Continuous-time, inputs ``p_cmd`` [Pa] and ``load_torque`` [N m], states as in the model
        (``w`` [rad/s], ``p`` [Pa], ``h_k`` [m]), the requested outputs; deviations from the point.
    """
    unknown = [n for n in outputs if n not in model.outputs]
    if unknown:
        raise ModelError(f"outputs {unknown} are not outputs of the HVD model; known: {list(model.outputs)}")
    A, B, C, D = linear_model(_jacobian_function(model, outputs), point.x, point.z, point.u)
    return control.ss(A, B, C, D, inputs=list(model.u), outputs=list(outputs), states=list(model.x),
                      name=f"hvd_{model.scene.name}")


def reduced_rhs(model, x, u):
    """dx/dt = f(x, z(x, u), u) with z from the algebraic equations (numeric, SI)."""
    return model.evaluate(x, u)[0]


def finite_difference(model, point, outputs=(SPEED_OUTPUT,), rel_step=1e-5):
    """(A, B, C, D) by central differences of the nonlinear model, steps scaled by the nominals.

    A cross-check of :func:`linearize` that never touches a CasADi Jacobian: z is re-solved at
    every perturbed point.
    """
    x0, u0 = np.asarray(point.x, float), np.asarray(point.u, float)
    x_scale = model.x_nominal
    u_scale = np.array([model.p_max, max(model.rated_torque, 1e-9)])

    def fy(x, u):
        dx, _, y = model.evaluate(x, u)
        return dx, np.array([y[n] for n in outputs])

    def columns(base, scale, perturb):
        cols_f, cols_y = [], []
        for j in range(base.size):
            step = rel_step * scale[j]
            e = np.zeros(base.size)
            e[j] = step
            f1, y1 = perturb(base + e)
            f0, y0 = perturb(base - e)
            cols_f.append((f1 - f0) / (2 * step))
            cols_y.append((y1 - y0) / (2 * step))
        return np.array(cols_f).T, np.array(cols_y).T

    A, C = columns(x0, x_scale, lambda x: fy(x, u0))
    B, D = columns(u0, u_scale, lambda u: fy(x0, u))
    return A, B, C, D


def describe(sys):
    """Poles, zeros and DC gains of a linear HVD model (numbers and names only).

    Returns
    -------
    dict with ``poles`` (list of [re, im]), ``zeros_from_p_cmd`` (list of [re, im]),
    ``dc_gain`` ({"<output>/<input>": value}).
    """
    poles = control.poles(sys)
    siso = sys[0, 0]
    zeros = control.zeros(control.ss(siso.A, siso.B, siso.C, siso.D))
    dc = np.atleast_2d(sys.dcgain())
    gains = {f"{o}/{i}": float(dc[a, b]) for a, o in enumerate(sys.output_labels)
             for b, i in enumerate(sys.input_labels)}
    def pair(values):
        return [[float(np.real(c)), float(np.imag(c))] for c in sorted(values, key=lambda c: (np.real(c), np.imag(c)))]

    return {"poles": pair(poles), "zeros_from_p_cmd": pair(zeros), "dc_gain": gains}
