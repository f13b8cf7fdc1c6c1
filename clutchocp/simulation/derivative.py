"""Total time derivative of an expression along the flow of a semi-explicit index-1 DAE.

Symbolic (CasADi SX) and free of the model classes, so the model description
(:mod:`clutchocp.simulation.model`) and its compiled functions (:mod:`clutchocp.simulation.compiled`)
both build on it.
"""

from collections.abc import Mapping

import casadi as ca


def time_derivative(expr, x, ode, *, z=None, alg=None, t=None):
    """Total time derivative of an expression along a DAE flow (e.g. jerk from an acceleration).

    ``d expr/dt = e_x x' + e_z z' + e_t`` with ``x' = ode`` and ``z'`` from differentiating
    ``0 = alg``: ``z' = -alg_z^-1 (alg_x x' + alg_t)`` (index 1). Parameters and
    piecewise-constant inputs have zero derivative inside a piece. Usable before the
    :class:`~clutchocp.simulation.model.Mode` is built (so the derivative can be one of its outputs); see also
    :meth:`clutchocp.simulation.model.Mode.time_derivative`.

    Parameters
    ----------
    expr : casadi.SX
        Expression of ``x, z`` (and parameters, inputs, ``t``).
    x : mapping of str to casadi.SX or sequence of casadi.SX
        Differential states.
    ode : mapping of str to casadi.SX or sequence of casadi.SX
        Their derivatives (same keys / order as ``x``).
    z, alg : as for x, ode, optional
        Algebraic variables and residuals.
    t : casadi.SX, optional
        The time symbol, if anything depends on time explicitly.

    Returns
    -------
    casadi.SX
        The derivative, same shape as ``expr`` (unit of ``expr`` per second).
    """
    def column(items, keys=None):
        if isinstance(items, Mapping):
            items = [items[k] for k in keys] if keys is not None else list(items.values())
        return ca.vertcat(*[ca.SX(e) for e in items])

    expr = ca.SX(expr)
    x_col = column(x)
    dx = column(ode, list(x) if isinstance(x, Mapping) and isinstance(ode, Mapping) else None)
    result = ca.jtimes(expr, x_col, dx)
    if z:
        z_col, g = column(z), column(alg)
        rhs = ca.jtimes(g, x_col, dx) + (ca.jacobian(g, t) if t is not None else 0)
        result += ca.jtimes(expr, z_col, -ca.solve(ca.jacobian(g, z_col), rhs))
    if t is not None:
        result += ca.jacobian(expr, t)
    return result
