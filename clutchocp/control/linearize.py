"""Exact linearisation of a semi-explicit DAE by CasADi, algebraic variables eliminated.

With dx/dt = f(x, z, u), 0 = g(x, z, u) (g_z non-singular) and outputs y = c(x, z, u), the
implicit function theorem gives dz = -g_z^-1 (g_x dx + g_u du), so

    A = f_x - f_z g_z^-1 g_x,   B = f_u - f_z g_z^-1 g_u,
    C = c_x - c_z g_z^-1 g_x,   D = c_u - c_z g_z^-1 g_u,

all Jacobians evaluated exactly by CasADi (algorithmic differentiation) at the point.
"""

import casadi as ca
import numpy as np

from ..errors import ModelError


def jacobian_function(name, inputs, x, z, u, ode, alg, outputs):
    """A CasADi function of ``inputs`` giving the nine Jacobian blocks of (f, g, c) by (x, z, u).

    Parameters
    ----------
    name : str
    inputs : list of casadi.SX
        The function's arguments (they may hold more than ``x``, e.g. states nothing depends on).
    x, z, u : casadi.SX
        Column vectors the Jacobians are taken by (``z`` may be empty).
    ode, alg, outputs : casadi.SX
        f, g (may be empty) and c as column vectors.

    Returns
    -------
    casadi.Function
        Outputs f_x, f_z, f_u, g_x, g_z, g_u, c_x, c_z, c_u.
    """
    blocks = []
    for expr in (ode, alg, outputs):
        blocks += [ca.jacobian(expr, x), ca.jacobian(expr, z), ca.jacobian(expr, u)]
    return ca.Function(name, inputs, blocks)


def linear_model(jacobians, *point):
    """(A, B, C, D) at a point from a :func:`jacobian_function`, algebraic variables eliminated."""
    fx, fz, fu, gx, gz, gu, cx, cz, cu = (np.array(m, dtype=float) for m in jacobians(*point))
    (A, B), (C, D) = eliminate_algebraic(gx, gz, gu, (fx, fz, fu), (cx, cz, cu))
    return A, B, C, D


def eliminate_algebraic(gx, gz, gu, *blocks):
    """Jacobians with the algebraic variables eliminated (implicit function theorem).

    With 0 = g(x, z, u) and g_z non-singular, dz = -g_z^-1 (g_x dx + g_u du), so an expression
    h(x, z, u) has the total Jacobians H_x = h_x - h_z g_z^-1 g_x and H_u = h_u - h_z g_z^-1 g_u.

    Parameters
    ----------
    gx, gz, gu : numpy.ndarray
        Jacobians of the algebraic residuals (gz square; empty if there are none).
    *blocks : (hx, hz, hu) tuples of numpy.ndarray
        Jacobians of each expression to reduce (the ODE right-hand side, outputs ...).

    Returns
    -------
    list of (H_x, H_u), one per block.

    Raises
    ------
    ModelError
        g_z is singular (the DAE is not index 1 at this point).
    """
    if not gz.size:
        return [(hx, hu) for hx, _, hu in blocks]
    if np.linalg.cond(gz) > 1e14:
        raise ModelError("linearisation: d alg / d z is singular at this point (the DAE is not index 1 here)")
    solve_x, solve_u = np.linalg.solve(gz, gx), np.linalg.solve(gz, gu)
    return [(hx - hz @ solve_x, hu - hz @ solve_u) for hx, hz, hu in blocks]
