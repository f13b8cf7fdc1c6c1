"""Registered tables (:class:`clutchocp.simulation.vectorized.PiecewiseCubic`) against CasADi's own
evaluation of the same interpolants."""

import casadi as ca
import numpy as np
import pytest

from clutchocp.simulation import vectorized
from clutchocp.simulation.vectorized import PiecewiseCubic


def _casadi(function, x):
    return np.array(function(ca.DM(np.ravel(x)).T), dtype=float).ravel()


@pytest.mark.parametrize("kind", ["bspline", "linear"])
@pytest.mark.parametrize("uniform", [True, False])
def test_piecewise_cubic_equals_the_interpolant_to_rounding(kind, uniform):
    grid = np.linspace(-2.0, 3.0, 41) if uniform else np.cumsum(np.r_[-2.0, np.linspace(0.05, 0.3, 30)])
    values = np.sin(2 * grid) * np.exp(-0.3 * grid) + 0.1 * grid**3
    f = ca.interpolant(f"t_{kind}_{uniform}", kind, [grid.tolist()], values.tolist())
    table = PiecewiseCubic(f, grid)
    rng = np.random.default_rng(1)
    x = np.concatenate([rng.uniform(grid[0] - 1, grid[-1] + 1, 5000), grid, [np.nan, np.inf, -np.inf]])
    exact, got = _casadi(f, x), table(x)
    finite = np.isfinite(exact)
    assert np.max(np.abs(got[finite] - exact[finite]) / np.maximum(1.0, np.abs(exact[finite]))) <= 1e-13
    assert np.array_equal(np.isnan(got), np.isnan(exact))
    outside = ~((x >= grid[0]) & (x <= grid[-1]))                     # CasADi's own extrapolation there
    assert np.array_equal(got[outside & finite], exact[outside & finite])


@pytest.mark.parametrize("uniform", [True, False])
def test_piecewise_cubic_is_its_interval_cubics_sample_by_sample(uniform):
    """Within the grid each value is, bit for bit, its interval's cubic by Horner's rule on Python
    floats (the interval found by bisection, the local variable from that interval's ends)."""
    import bisect

    grid = np.linspace(-2.0, 3.0, 41) if uniform else np.cumsum(np.r_[-2.0, np.linspace(0.05, 0.3, 30)])
    f = ca.interpolant(f"t_scalar_{uniform}", "bspline", [grid.tolist()], (np.cos(grid) + 0.2 * grid**2).tolist())
    table = PiecewiseCubic(f, grid)
    rng = np.random.default_rng(3)
    x = np.concatenate([rng.uniform(grid[0], grid[-1], 3000), grid])
    got = table(x)
    g = grid.tolist()
    for value, xi in zip(got.tolist(), x.tolist()):
        if uniform:
            i = min(max(int((xi - g[0]) * table._inverse_step), 0), len(g) - 2)
        else:
            i = min(max(bisect.bisect_right(g, xi) - 1, 0), len(g) - 2)
        u = (xi - g[i]) / (g[i + 1] - g[i])
        c0, c1, c2, c3 = (float(table.coefficients[k, i]) for k in range(4))
        assert value == c0 + u * (c1 + u * (c2 + u * c3))


def test_a_grid_that_misses_the_knots_is_refused():
    grid = np.linspace(0.0, 1.0, 21)
    f = ca.interpolant("t_knots", "bspline", [grid.tolist()], np.exp(3 * grid).tolist())
    with pytest.raises(ValueError, match="not a cubic"):
        PiecewiseCubic(f, grid[::4])                                 # 5 intervals, knots inside them


def test_the_numpy_form_calls_registered_tables_and_keeps_casadis_values(monkeypatch):
    """log F_5/2 (registered at import by the roughness module): the numpy translation of a
    function calling it gives CasADi's values to rounding, and the table is no longer a call that
    the numpy form pays per sample."""
    from clutchocp.physics.roughness import log_F52

    h = ca.SX.sym("h")
    f = ca.Function("f", [h], [ca.exp(log_F52(h)) * h])
    assert not vectorized.calls_unregistered(f)
    x = np.linspace(-8.0, 14.0, 3001)
    out = np.empty(x.size)
    vectorized.numpy_function(f)([x[None, :]], [out[None, :]])
    exact = np.array([float(f(v)) for v in x])
    assert np.max(np.abs(out - exact) / np.maximum(np.abs(exact), 1e-300)) <= 1e-12
    monkeypatch.setattr(vectorized, "_TABLES", {})
    assert vectorized.calls_unregistered(f)
