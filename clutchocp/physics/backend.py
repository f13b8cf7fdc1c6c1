"""Elementary functions that work on floats, numpy arrays and CasADi SX/MX/DM alike.

Physics components call these instead of ``numpy`` or ``casadi`` directly, so one
formula serves the numeric analyses, the DAE and the optimal-control problem.
"""

import casadi as ca
import numpy as np
from scipy import special

_CASADI_TYPES = (ca.SX, ca.MX, ca.DM)


def is_symbolic(*args):
    """True if any argument is a CasADi SX, MX or DM (then CasADi operators are used)."""
    return any(isinstance(a, _CASADI_TYPES) for a in args)


def exp(x):
    return ca.exp(x) if is_symbolic(x) else np.exp(x)


def log(x):
    return ca.log(x) if is_symbolic(x) else np.log(x)


def sqrt(x):
    return ca.sqrt(x) if is_symbolic(x) else np.sqrt(x)


def tanh(x):
    return ca.tanh(x) if is_symbolic(x) else np.tanh(x)


def cos(x):
    return ca.cos(x) if is_symbolic(x) else np.cos(x)


def erf(x):
    return ca.erf(x) if is_symbolic(x) else special.erf(x)


def erfc(x):
    """Complementary error function: scipy's (accurate in the tail) for numbers, ``1 - erf``
    for CasADi (which has no erfc; tails below ~1e-15 are rounding noise there)."""
    return 1 - ca.erf(x) if is_symbolic(x) else special.erfc(x)


def fabs(x):
    return ca.fabs(x) if is_symbolic(x) else np.abs(x)


def fmax(a, b):
    return ca.fmax(a, b) if is_symbolic(a, b) else np.maximum(a, b)


def fmin(a, b):
    return ca.fmin(a, b) if is_symbolic(a, b) else np.minimum(a, b)


def if_else(cond, if_true, if_false):
    """Elementwise choice; with CasADi both branches are evaluated (keep them finite)."""
    if is_symbolic(cond, if_true, if_false):
        return ca.if_else(cond, if_true, if_false)
    return np.where(cond, if_true, if_false)


def softplus(x, width):
    """Smooth ``max(x, 0)``: ``width * log(1 + exp(x / width))``, overflow-safe.

    The error against ``max(x, 0)`` is at most ``width * ln 2`` (at x = 0).
    """
    z = x / width
    return width * (fmax(z, 0) + log(1 + exp(-fabs(z))))


def smooth_step(x, width):
    """Smooth Heaviside step: 0.5 (1 + tanh(x / width)); equals 0.5 at x = 0."""
    return 0.5 * (1 + tanh(x / width))


def apply_elementwise(function, x):
    """Evaluate a scalar-in, scalar-out CasADi Function (e.g. an interpolant) elementwise.

    Parameters
    ----------
    function : casadi.Function
        One scalar input, one scalar output.
    x : float, array or CasADi SX/MX/DM
        Argument.

    Returns
    -------
    Same shape as x: a CasADi matrix for CasADi input, else a numpy array (0-d for a float).
    """
    if is_symbolic(x):
        if x.is_scalar():
            return function(x)
        n = x.numel()
        row = function.map(n)(ca.reshape(x, 1, n))
        return ca.reshape(row, x.size1(), x.size2())
    arr = np.asarray(x, dtype=float)
    if arr.size == 0:
        return np.empty(arr.shape)
    return np.array(function(arr.reshape(1, -1)), dtype=float).reshape(arr.shape)


_DECLARED_TABLES = []   # (function, grid) of 1-D tables the engine may evaluate with numpy


def declare_table(function, grid):
    """Declare a 1-D table: a scalar CasADi interpolant whose knots all lie on ``grid``.

    A numpy-translated model (``clutchocp.simulation.vectorized``) then evaluates its calls with
    numpy instead of CasADi, per sample. Declaring changes no result.

    Parameters
    ----------
    function : casadi.Function
        One scalar input, one scalar output, a cubic on each interval of ``grid``.
    grid : array of float
        Strictly increasing knots of the table.
    """
    _DECLARED_TABLES.append((function, np.asarray(grid, dtype=float)))


def declared_tables():
    """The tables declared so far, as (function, grid) pairs, oldest first."""
    return tuple(_DECLARED_TABLES)
