"""A CasADi SX Function evaluated on many samples at once with numpy.

CasADi evaluates an SX Function instruction by instruction in its virtual machine, one sample
at a time: about 3 ns per instruction and sample. For the outputs and event functions of a
mode on a long output grid (a locked phase of 1 700 samples) numpy does better: the same
instruction list, translated once into Python source with one numpy operation per instruction
on arrays of all samples, costs about 1 us per instruction plus under 1 ns per instruction and
sample. :func:`numpy_function` makes that translation; :class:`~clutchocp.simulation.compiled.ColumnFunction`
uses it above :data:`MIN_SAMPLES` samples (:data:`MIN_SAMPLES_PLAIN` for a function that calls no
table).

Operations are the IEEE double operations of CasADi's C code (numpy's transcendental functions
agree to within an ulp or two); ``if_else`` keeps CasADi's semantics (``if_else_zero(c, x)`` is
0 where c is 0 even if x is NaN or inf). Calls of scalar functions (the interpolants of tables
and of log F_5/2) are evaluated by CasADi on all samples at once. A function with an instruction
outside :data:`_UNARY`, :data:`_BINARY` and these special cases is not translated (``erfinv``
among them: CasADi's own approximation differs from scipy's by ~1e-7).
"""

import math

import numpy as np
from scipy.special import erf

import casadi as ca

from clutchocp.physics.backend import declared_tables

MIN_SAMPLES = 600      # measured break-even with CasADi's map: ~500 samples (2.4 k and 0.6 k instructions)
MIN_SAMPLES_PLAIN = 128  # the same for a function without calls of tables: ~50-150 samples (measured on the
                         # seed scenes' outputs and event functions, 3 to 2.6 k instructions); the calls are
                         # what the numpy form pays per sample

_UNARY = {
    "OP_EXP": "np.exp({0})", "OP_LOG": "np.log({0})", "OP_SQRT": "np.sqrt({0})", "OP_SIN": "np.sin({0})",
    "OP_COS": "np.cos({0})", "OP_TAN": "np.tan({0})", "OP_ASIN": "np.arcsin({0})", "OP_ACOS": "np.arccos({0})",
    "OP_ATAN": "np.arctan({0})", "OP_SINH": "np.sinh({0})", "OP_COSH": "np.cosh({0})", "OP_TANH": "np.tanh({0})",
    "OP_ASINH": "np.arcsinh({0})", "OP_ACOSH": "np.arccosh({0})", "OP_ATANH": "np.arctanh({0})",
    "OP_FABS": "np.fabs({0})", "OP_FLOOR": "np.floor({0})", "OP_CEIL": "np.ceil({0})", "OP_SIGN": "np.sign({0})",
    "OP_LOG1P": "np.log1p({0})", "OP_EXPM1": "np.expm1({0})", "OP_ERF": "erf({0})",
    "OP_NEG": "-{0}", "OP_SQ": "{0} * {0}", "OP_TWICE": "2.0 * {0}", "OP_INV": "1.0 / {0}", "OP_ASSIGN": "{0}",
    "OP_NOT": "np.equal({0}, 0.0) * 1.0",
}
_BINARY = {
    "OP_ADD": "{0} + {1}", "OP_SUB": "{0} - {1}", "OP_MUL": "{0} * {1}", "OP_DIV": "{0} / {1}",
    "OP_POW": "np.power({0}, {1})", "OP_CONSTPOW": "np.power({0}, {1})", "OP_LT": "np.less({0}, {1}) * 1.0",
    "OP_LE": "np.less_equal({0}, {1}) * 1.0", "OP_EQ": "np.equal({0}, {1}) * 1.0",
    "OP_NE": "np.not_equal({0}, {1}) * 1.0", "OP_AND": "np.logical_and({0}, {1}) * 1.0",
    "OP_OR": "np.logical_or({0}, {1}) * 1.0", "OP_FMIN": "np.fmin({0}, {1})", "OP_FMAX": "np.fmax({0}, {1})",
    "OP_ATAN2": "np.arctan2({0}, {1})", "OP_HYPOT": "np.hypot({0}, {1})", "OP_FMOD": "np.fmod({0}, {1})",
    "OP_COPYSIGN": "np.copysign({0}, {1})", "OP_IF_ELSE_ZERO": "np.where(np.not_equal({0}, 0.0), {1}, 0.0)",
}
_NAMES = {getattr(ca, name): name for name in dir(ca) if name.startswith("OP_")}


def _constant(value):
    if math.isnan(value):
        return "np.nan"
    if math.isinf(value):
        return "np.inf" if value > 0 else "-np.inf"
    return repr(float(value))


def _scalar_call(callee, ins, outs):
    """A call that :func:`_call` evaluates: scalar inputs (those without nonzeros, e.g. the unused
    nominal output of a derivative, take no instruction input), one scalar output."""
    used = [i for i in range(callee.n_in()) if callee.nnz_in(i)]
    return (len(outs) == 1 and callee.n_out() == 1 and callee.numel_out(0) == 1 and len(used) == len(ins)
            and all(callee.numel_in(i) == 1 for i in range(callee.n_in())))


_MAPS = {}              # (callee name, m) -> (callee, its map over m samples, the map's buffer, evaluate)
_MAX_MAPS = 256
_DUMMY = np.zeros(1)


def padded_size(n):
    """Sample count of the map that evaluates ``n`` samples: ``n`` up to 8, else ``n`` rounded up to
    a quarter of its octave (at most 25 % more samples, four sizes per octave). A map costs
    0.6-1.5 ms to build and the sample counts of a run's pieces change from run to run with
    their event times; rounded up, a few cached maps serve every count (the padding repeats the
    last sample and is dropped from the result)."""
    if n <= 8:
        return n
    quantum = 1 << ((n - 1).bit_length() - 3)
    return -(-n // quantum) * quantum


class PiecewiseCubic:
    """A one-dimensional table function (a CasADi cubic B-spline or linear interpolant) as the
    cubic polynomial of each of its grid intervals, evaluated with numpy.

    CasADi evaluates a B-spline sample by sample (de Boor, ~0.55 us a sample: 0.9 ms for the
    1 620 samples of a locked phase, once per film and per function that calls it); a polynomial
    per interval costs ~30 ns a sample. Each interval's cubic goes through the table function's
    own values at four points of that interval (the interval's ends and thirds), so within the
    grid it is the same piecewise cubic up to rounding (checked at build time at every
    interval's quarter points; the grid must hold the spline's knots). Samples outside the grid
    (or NaN) are evaluated by CasADi itself, whatever its extrapolation is. On a uniform grid a
    sample's interval is found by division; at a grid point the two neighbouring cubics agree to
    rounding.
    """

    # inverse of the Vandermonde matrix of u = 0, 1/3, 2/3, 1 (rows: coefficients of u^0..u^3)
    _FIT = np.linalg.inv(np.vander(np.array([0.0, 1 / 3, 2 / 3, 1.0]), 4, increasing=True))

    def __init__(self, function, grid, rtol=1e-12):
        grid = np.asarray(grid, float)
        if grid.ndim != 1 or grid.size < 2 or np.any(np.diff(grid) <= 0):
            raise ValueError("a table's grid must be a strictly increasing 1-D array of two or more points")
        self.function, self.grid = function, grid
        step = (grid[-1] - grid[0]) / (grid.size - 1)
        self._inverse_step = 1.0 / step if np.allclose(np.diff(grid), step, rtol=1e-12, atol=0) else None
        u = np.array([0.0, 1 / 3, 2 / 3, 1.0])
        points = grid[:-1, None] + u[None, :] * np.diff(grid)[:, None]
        values = np.array(function(ca.DM(points.ravel()).T), dtype=float).reshape(points.shape)
        self.coefficients = np.ascontiguousarray((values @ self._FIT.T).T)   # (4, intervals): c0 + c1 u + ... c3 u^3
        self._left, self._width = grid[:-1], grid[1:] - grid[:-1]      # each interval's start and width
        check = grid[:-1, None] + np.array([0.25, 0.5, 0.75])[None, :] * np.diff(grid)[:, None]
        exact = np.array(function(ca.DM(check.ravel()).T), dtype=float).ravel()
        scale = max(1.0, float(np.max(np.abs(values))))
        if not np.max(np.abs(self(check.ravel()) - exact)) <= rtol * scale:
            raise ValueError(f"table function {function.name()} is not a cubic on each interval of the grid given")

    def __call__(self, x):
        """Values at the samples ``x`` (1-D array)."""
        x = np.asarray(x, float)
        grid = self.grid
        if self._inverse_step is not None:      # uniform grid: the interval by division (no search)
            r = (x - grid[0]) * self._inverse_step
            r[~np.isfinite(r)] = 0.0            # NaN and +-inf: interval 0 (evaluated by CasADi below)
            i = r.astype(np.intp)
        else:
            i = np.searchsorted(grid, x, side="right") - 1
        np.minimum(np.maximum(i, 0, out=i), grid.size - 2, out=i)     # clipped to the intervals
        u = (x - self._left[i]) / self._width[i]
        c0, c1, c2, c3 = self.coefficients.take(i, axis=1)
        y = c0 + u * (c1 + u * (c2 + u * c3))
        outside = ~((x >= grid[0]) & (x <= grid[-1]))
        if outside.any():
            y[outside] = _casadi_call(self.function, x[outside])
        return y


_TABLES = {}            # hash of a CasADi table function -> its PiecewiseCubic
_TAKEN = [0]            # how many of the physics floor's declared tables are registered here


def register_table(function, grid):
    """Evaluate the 1-D table ``function`` (a CasADi interpolant whose knots are all on ``grid``)
    with numpy wherever a numpy-translated function calls it (:class:`PiecewiseCubic`); a table
    that is not a cubic on each interval of ``grid`` is left to CasADi (ValueError)."""
    _TABLES[hash(function)] = PiecewiseCubic(function, grid)


def _take_declared():
    """Register the tables the physics floor declared since the last look (``backend.declare_table``)."""
    declared = declared_tables()
    for function, grid in declared[_TAKEN[0]:]:
        register_table(function, grid)
    _TAKEN[0] = len(declared)


def calls_unregistered(function):
    """Whether the SX ``function`` calls a function that is not a registered table (a call that
    the numpy form pays per sample, through CasADi)."""
    if not function.is_a("SXFunction"):
        return False
    calls = [k for k in range(function.n_instructions()) if function.instruction_id(k) == ca.OP_CALL]
    if not calls:
        return False
    instructions = function.instructions_sx()
    _take_declared()
    return any(hash(instructions[k].which_function()) not in _TABLES for k in calls)


def _call(callee, *args):
    """``callee`` (scalar in, scalar out, e.g. an interpolant or its derivative) on every sample:
    a registered table (:func:`register_table`) with numpy, anything else through a map over the
    samples called with the buffer interface (numpy in and out)."""
    shape = np.broadcast(*args).shape
    n = math.prod(shape)
    if n == 0:
        return np.zeros(shape)
    _take_declared()
    table = _TABLES.get(hash(callee))
    if table is not None and len(args) == 1:
        x = args[0]
        result = table(np.ravel(x) if isinstance(x, np.ndarray) and x.shape == shape else
                       np.ravel(np.broadcast_to(x, shape)))
    else:
        result = _casadi_call(callee, *(np.ravel(np.broadcast_to(a, shape)) for a in args))
    return result.reshape(shape) if shape else float(result[0])


def _casadi_call(callee, *args):
    """``callee`` on the ``n`` samples of the flat arrays ``args`` through a cached map: (n,) array."""
    n = args[0].size
    m = padded_size(n)
    key = (callee.name(), m)
    entry = _MAPS.get(key)
    if entry is None or entry[0] is not callee:
        if len(_MAPS) >= _MAX_MAPS:
            _MAPS.pop(next(iter(_MAPS)))
        mapped = callee.map(m)
        entry = _MAPS[key] = (callee, mapped, *mapped.buffer())
    _, _, buffer, evaluate = entry
    values = iter([_pad(a, n, m) for a in args])
    for i in range(callee.n_in()):
        buffer.set_arg(i, memoryview(next(values) if callee.nnz_in(i) else _DUMMY))
    result = np.empty(m)
    buffer.set_res(0, memoryview(result))
    evaluate()
    return result[:n]


def _pad(a, n, m):
    """The ``n`` values of ``a`` as a flat float array of length ``m >= n``, the last value repeated."""
    out = np.empty(m)
    out[:n] = np.ravel(a)
    out[n:] = out[n - 1]
    return out


def _source(function):
    """Python source of :func:`numpy_function` (its lines and the functions it calls), or None when
    the function holds an instruction that has no numpy counterpart here."""
    if not function.is_a("SXFunction"):
        return None
    lines, calls = ["def evaluate(args, outs):"], []
    for k in range(function.n_instructions()):
        op = _NAMES.get(function.instruction_id(k))
        ins, outs = function.instruction_input(k), function.instruction_output(k)
        if op == "OP_INPUT":
            lines.append(f"    w{outs[0]} = args[{ins[0]}][{ins[1]}]")
        elif op == "OP_OUTPUT":
            lines.append(f"    outs[{outs[0]}][{outs[1]}] = w{ins[0]}")
        elif op == "OP_CONST":
            lines.append(f"    w{outs[0]} = {_constant(function.instruction_constant(k))}")
        elif op in _UNARY:
            lines.append(f"    w{outs[0]} = " + _UNARY[op].format(f"w{ins[0]}"))
        elif op in _BINARY:
            lines.append(f"    w{outs[0]} = " + _BINARY[op].format(f"w{ins[0]}", f"w{ins[1]}"))
        elif op == "OP_CALL" and _scalar_call(callee := function.instructions_sx()[k].which_function(), ins, outs):
            calls.append(callee)
            lines.append(f"    w{outs[0]} = call(calls[{len(calls) - 1}], " + ", ".join(f"w{i}" for i in ins) + ")")
        else:
            return None
    if len(lines) == 1:
        lines.append("    pass")
    return lines, calls


def translatable(function):
    """Whether :func:`numpy_function` translates ``function`` (without compiling the translation)."""
    return _source(function) is not None


def numpy_function(function):
    """``function`` (an SX Function with dense inputs and outputs) as a Python function of numpy arrays.

    Returns
    -------
    callable or None
        ``g(args, outs)``: ``args[i]`` indexable by nonzero (rows of an array of samples, or
        scalars); ``outs[i][k]`` receives nonzero ``k`` of output ``i`` (a row, broadcast from a
        scalar where the output does not depend on the sampled inputs). None when the function
        holds an instruction that has no numpy counterpart here.
    """
    source = _source(function)
    if source is None:
        return None
    lines, calls = source
    namespace = {"np": np, "erf": erf, "call": _call, "calls": calls}
    exec(compile("\n".join(lines), f"<numpy {function.name()}>", "exec"), namespace)   # noqa: S102 (own source)
    return namespace["evaluate"]
