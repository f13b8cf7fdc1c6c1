"""Tests of clutchocp.physics.cavitation (the smooth tension limit of a squeeze film and its inverse)."""

import casadi as ca
import numpy as np
import pytest

from clutchocp.physics.cavitation import RESIDUAL_SLOPE, tension_limited_load, tension_limited_load_inverse

L, W = -1000.0, 20.0            # limit and corner width [N]
EPS = RESIDUAL_SLOPE


def test_a_film_at_rest_carries_nothing_and_follows_the_linear_law_above_the_limit():
    """g(0) = 0 exactly; for x >= 0, x - (1 - eps) D <= g(x) <= x with D = w^2 / (4 |L|), and
    g(x) - x -> -(1 - eps) D (the asymptote x - delta); between the limit and 0 the hyperbola's tail
    (1 - eps) w^2 / (4 d) - delta, d = x - L - D."""
    assert tension_limited_load(0.0, L, W) == 0.0 or abs(tension_limited_load(0.0, L, W)) < 1e-12 * abs(L)
    D = W**2 / (4 * abs(L))
    x = np.array([0.0, 10.0, 1e3, 1e5, 1e8])
    g = tension_limited_load(x, L, W)
    assert np.all(g <= x + 1e-9) and np.all(g >= x - (1 - EPS) * D - 1e-9)
    d = x[-2] - L - D
    assert g[-2] - x[-2] == pytest.approx(-(1 - EPS) * D + (1 - EPS) * W**2 / (4 * d), rel=1e-6)
    x = np.array([-900.0, -500.0, -100.0])
    d = x - L - D
    tail = (1 - EPS) * (np.sqrt(d * d + W * W) - d) / 2 - (1 - EPS) * D
    np.testing.assert_allclose(tension_limited_load(x, L, W) - x, tail, rtol=1e-9)
    assert np.all(np.abs(tension_limited_load(x, L, W) - x) < 2e-3 * abs(L))      # within 0.2 % of the limit


def test_saturates_at_the_limit_with_the_residual_slope():
    """Below the limit g -> L + eps (x - L) + O(w^2 / |x - L|)."""
    x = np.array([-2e4, -1e5, -1e7])
    expected = L + EPS * (x - L)
    assert np.all(np.abs(tension_limited_load(x, L, W) - expected) < W**2 / np.abs(x - L))


def test_strictly_increasing_with_slope_between_eps_and_one():
    x = np.linspace(-1e5, 1e5, 400001)
    g = tension_limited_load(x, L, W)
    slope = np.diff(g) / np.diff(x)
    assert slope.min() > 0.99 * EPS and slope.max() <= 1.0 + 1e-9


@pytest.mark.parametrize("x", [-1e7, -3e3, -1010.0, -1000.0, -990.0, -500.0, 0.0, 2.5e3, 1e8])
def test_inverse_round_trip(x):
    g = tension_limited_load(x, L, W)
    assert tension_limited_load_inverse(g, L, W) == pytest.approx(x, rel=1e-12, abs=1e-9)


def test_inverse_covers_every_load():
    """g maps onto the whole real line: every load has a closing speed (a massless pack stays well posed)."""
    for y in (-1e6, -2e3, L, L + W, 0.0, 1e6):
        x = tension_limited_load_inverse(y, L, W)
        assert np.isfinite(x) and tension_limited_load(x, L, W) == pytest.approx(y, rel=1e-12, abs=1e-9)


def test_symbolic_equals_numeric_and_derivatives_are_smooth():
    """CasADi and numpy give the same values; g' and g'' are continuous through the corner and the inverse's
    two branches (Y < 0, Y >= 0) join with equal first and second derivatives."""
    xs = ca.SX.sym("x")
    g = tension_limited_load(xs, L, W)
    gi = tension_limited_load_inverse(xs, L, W)
    f = ca.Function("f", [xs], [g, ca.jacobian(g, xs), ca.hessian(g, xs)[0], gi, ca.jacobian(gi, xs),
                                ca.hessian(gi, xs)[0]])
    for x in (-3e3, -1005.0, -1000.0, -995.0, 0.0, 500.0):
        g_val = float(f(x)[0])
        assert g_val == pytest.approx(float(tension_limited_load(x, L, W)), rel=1e-15)
        assert float(f(x)[3]) == pytest.approx(float(tension_limited_load_inverse(x, L, W)), rel=1e-14)
    # the inverse at Y = 0 (x = L): one-sided values of g^-1' and g^-1'' agree
    h = 1e-7
    lo, hi = f(L - h), f(L + h)
    assert float(lo[4]) == pytest.approx(float(hi[4]), rel=1e-6)
    assert float(lo[5]) == pytest.approx(float(hi[5]), rel=1e-5)
    # g' = 1 / (g^-1)' at corresponding points
    y = float(f(-1002.0)[0])
    assert float(f(-1002.0)[1]) == pytest.approx(1.0 / float(f(y)[4]), rel=1e-10)
