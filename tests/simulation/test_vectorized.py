"""numpy evaluation of SX Functions on many samples (clutchocp.simulation.vectorized) against
CasADi's own evaluation of the same Function."""

import casadi as ca
import numpy as np
import pytest

from clutchocp.physics.roughness import log_F52
from clutchocp.simulation import compiled
from clutchocp.simulation.compiled import ColumnFunction
from clutchocp.simulation.vectorized import numpy_function


def casadi_columns(function, xs, zs, pu, t):
    return np.hstack([np.array(function(xs[:, k], zs[:, k], pu, t[k]), dtype=float) for k in range(t.size)])


def numpy_columns(function, xs, zs, pu, t):
    out = np.empty((function.size1_out(0), t.size))
    with np.errstate(all="ignore"):
        numpy_function(function)([xs, zs, pu, t[None, :]], [out])
    return out


@pytest.fixture
def symbols():
    return ca.SX.sym("x", 3), ca.SX.sym("z", 1), ca.SX.sym("p", 2), ca.SX.sym("t")


def samples(n=50, seed=1):
    rng = np.random.default_rng(seed)
    return rng.uniform(-2, 2, (3, n)), rng.uniform(0.1, 3, (1, n)), np.array([0.7, -1.3]), np.linspace(0, 2, n)


def test_every_supported_operation_matches_casadi(symbols):
    x, z, p, t = symbols
    a, b, c = x[0], x[1], x[2]
    exprs = [a + b, a - b, a * b, a / z, -a, ca.exp(a), ca.log(z), z ** p[0], ca.constpow(z, 2.5), ca.sqrt(z),
             a ** 2, 2 * a, ca.sin(a), ca.cos(a), ca.tan(a), ca.asin(a / 3), ca.acos(a / 3), ca.atan(a),
             ca.sinh(a), ca.cosh(a), ca.tanh(a), ca.asinh(a), ca.acosh(1 + z), ca.atanh(a / 3), ca.fabs(a),
             ca.floor(a), ca.ceil(a), ca.sign(a), ca.log1p(z), ca.expm1(a), ca.erf(a),
             ca.fmin(a, b), ca.fmax(a, b), ca.atan2(a, b), ca.hypot(a, b), ca.fmod(a, z), ca.copysign(a, b),
             a < b, a <= b, a == b, a != b, ca.logic_and(a > 0, b > 0), ca.logic_or(a > 0, b > 0),
             ca.logic_not(a > 0), ca.if_else(a > b, c, 2 * c), 1 / (1 + a * a), p[1] * t, ca.SX(3.25), p[0]]
    f = ca.Function("f", [x, z, p, t], [ca.vertcat(*exprs)])
    assert numpy_function(f) is not None
    args = samples()
    np.testing.assert_allclose(numpy_columns(f, *args), casadi_columns(f, *args), rtol=1e-14, atol=1e-300)


def test_if_else_takes_no_nan_from_the_branch_not_taken(symbols):
    x, z, p, t = symbols
    f = ca.Function("f", [x, z, p, t], [ca.if_else(x[0] > 0, ca.log(x[0]), -1.0)])
    args = samples()
    got = numpy_columns(f, *args)
    assert np.all(np.isfinite(got))
    np.testing.assert_array_equal(got, casadi_columns(f, *args))


def test_interpolant_calls_and_their_derivatives_match_casadi(symbols):
    """log F_5/2 is a B-spline interpolant; its derivative calls a derivative function whose
    nominal-output input has no nonzeros."""
    x, z, p, t = symbols
    H = 2 * x[0] + 1
    expr = ca.vertcat(log_F52(H), ca.jacobian(log_F52(H), x)[0], ca.jacobian(ca.jacobian(log_F52(H), x)[0], x)[0])
    f = ca.Function("f", [x, z, p, t], [expr])
    assert numpy_function(f) is not None
    args = samples(n=40)
    np.testing.assert_allclose(numpy_columns(f, *args), casadi_columns(f, *args), rtol=1e-13, atol=1e-300)


def test_a_function_with_an_unsupported_instruction_is_not_translated(symbols):
    x, z, p, t = symbols
    table = ca.interpolant("table2d", "linear", [[0.0, 1.0], [0.0, 1.0]], [0.0, 1.0, 2.0, 3.0])   # two inputs
    f = ca.Function("f", [x, z, p, t], [table(ca.vertcat(x[0], x[1])) + 0 * z + 0 * p[0] + 0 * t])
    assert numpy_function(f) is None
    # erfinv: CasADi's approximation is not scipy's, so it stays with CasADi
    assert numpy_function(ca.Function("e", [x, z, p, t], [ca.erfinv(x[0] / 3)])) is None
    column = ColumnFunction(ca.Function("g", [x, z, p, t], [ca.densify(table(ca.vertcat(x[0], x[1])))]))
    xs, zs, pu, ts = samples(n=700)
    np.testing.assert_allclose(column(xs, zs, pu, ts).ravel(),
                               [float(table([xs[0, k], xs[1, k]])) for k in range(ts.size)], rtol=1e-14)


def test_column_function_gives_the_same_outputs_either_way(monkeypatch):
    """A mode's outputs on many samples: numpy above MIN_SAMPLES, CasADi's map below, equal."""
    from clutchocp.engagement.model import EngagementModel
    from clutchocp.scene.loader import load_scene

    model = EngagementModel(load_scene("bao2020"))
    cm = model.hybrid.compiled()["pressing_slip_forward"]
    n = 800
    rng = np.random.default_rng(3)
    xs = (model.initial_state / cm.x_nominal)[:, None] * (1 + 0.1 * rng.random((cm.nx, n)))
    xs[cm.x_names.index("h_1")] = rng.uniform(0.5, 20, n)
    args = (xs, np.zeros((0, n)), np.zeros(cm.pu.numel()), np.linspace(0, 0.4, n))
    monkeypatch.setattr(compiled, "MIN_SAMPLES", 10**9)
    by_casadi = cm.outputs_on(*args)
    monkeypatch.setattr(compiled, "MIN_SAMPLES", 1)
    by_numpy = cm.outputs_on(*args)
    assert cm.outputs_on._numpy is not None
    np.testing.assert_allclose(by_numpy, by_casadi, rtol=1e-12, atol=0)
