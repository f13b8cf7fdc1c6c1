"""Tests of clutchocp.physics.roughness: F_n functions, F_{5/2} spline, average gap."""

import math

import casadi as ca
import numpy as np
import pytest
from scipy import integrate, special, stats

from clutchocp.physics import roughness as rg


def quad_Fn(n, H):
    """F_n(H) = int_H^inf (s - H)^n phi(s) ds, by quadrature with s - H = t^2 (no root singularity)."""
    value, _ = integrate.quad(
        lambda t: 2 * t ** (2 * n + 1) * math.exp(-0.5 * (H + t * t) ** 2) / math.sqrt(2 * math.pi),
        0.0, np.inf, epsabs=0.0, epsrel=1e-12, limit=200,
    )
    return value


def parabolic_cylinder_Fn(n, H):
    """Closed form F_n(H) = Gamma(n+1)/sqrt(2 pi) exp(-H^2/4) D_{-n-1}(H) (parabolic cylinder)."""
    H = np.asarray(H, dtype=float)
    return special.gamma(n + 1) / math.sqrt(2 * math.pi) * np.exp(-H**2 / 4) * special.pbdv(-n - 1, H)[0]


def sx_eval(fun, *values):
    """Evaluate ``fun`` on scalar SX symbols through a casadi.Function, at float values."""
    syms = [ca.SX.sym(f"x{i}") for i in range(len(values))]
    f = ca.Function("f", syms, [fun(*syms)])
    return float(f(*values))


def test_combined_sigma_is_root_sum_square():
    assert rg.combined_sigma(3.0, 4.0) == pytest.approx(5.0, rel=1e-15)
    # Cui Table 2: 5.975 and 2.85 um
    assert rg.combined_sigma(5.975e-6, 2.85e-6) == pytest.approx(6.6200e-6, rel=1e-4)


def test_normal_pdf_cdf_match_scipy():
    H = np.linspace(-9, 9, 37)
    np.testing.assert_allclose(rg.normal_pdf(H), stats.norm.pdf(H), rtol=1e-14)
    np.testing.assert_allclose(rg.normal_cdf(H), stats.norm.cdf(H), rtol=1e-13)


@pytest.mark.parametrize("n, fun", [(0, rg.F0), (1, rg.F1), (2, rg.F2)])
def test_closed_form_Fn_match_quadrature(n, fun):
    for H in np.linspace(-4, 8, 25):
        assert fun(H) == pytest.approx(quad_Fn(n, H), rel=1e-9)


def test_F52_reference_values_of_physics_md():
    # PHYSICS.md: 0.61663, 0.080562, 0.005424, 1.71e-4; half a unit of the last printed digit
    assert abs(rg.F52(0.0) - 0.61663) < 5e-6
    assert abs(rg.F52(1.0) - 0.080562) < 5e-7
    assert abs(rg.F52(2.0) - 0.005424) < 5e-7
    assert abs(rg.F52(3.0) - 1.71e-4) < 5e-7


def test_F52_matches_quadrature_between_table_nodes():
    # off-node points (table step 0.05): relative tolerance 1e-6
    H = np.linspace(-5.987, 11.987, 241)
    expected = np.array([quad_Fn(2.5, h) for h in H])
    np.testing.assert_allclose(rg.F52(H), expected, rtol=1e-6)


def test_F52_matches_parabolic_cylinder_form_including_extensions():
    H = np.linspace(-25, 25, 2001)   # table is [-6, 12]; beyond: matched asymptotic series
    np.testing.assert_allclose(rg.F52(H), parabolic_cylinder_Fn(2.5, H), rtol=1e-6)


def test_F52_derivatives_from_casadi_are_finite_and_correct():
    # dF_n/dH = -n F_{n-1}:  F52' = -(5/2) F_{3/2},  F52'' = (15/4) F_{1/2}
    x = ca.SX.sym("H")
    y = rg.F52(x)
    f = ca.Function("d", [x], [ca.gradient(y, x), ca.hessian(y, x)[0]])
    H = np.concatenate([np.linspace(-5.99, 11.99, 719), [-6.0, 0.0, 0.05, 12.0]])   # incl. nodes
    grad, hess = (np.array(v).ravel() for v in f.map(H.size)(H.reshape(1, -1)))
    assert np.all(np.isfinite(hess))
    np.testing.assert_allclose(grad, -2.5 * parabolic_cylinder_Fn(1.5, H), rtol=1e-6)
    # cubic-spline second derivative: O(step^2) error, measured 1.4e-4 at the table's end
    np.testing.assert_allclose(hess, 3.75 * parabolic_cylinder_Fn(0.5, H), rtol=2e-4)
    # extensions stay finite and close too
    H_out = np.array([-30.0, -10.0, 15.0, 30.0])
    grad, hess = (np.array(v).ravel() for v in f.map(H_out.size)(H_out.reshape(1, -1)))
    np.testing.assert_allclose(grad, -2.5 * parabolic_cylinder_Fn(1.5, H_out), rtol=1e-6)
    np.testing.assert_allclose(hess, 3.75 * parabolic_cylinder_Fn(0.5, H_out), rtol=1e-6)


def test_F52_keeps_array_shape_and_scalar_type():
    H = np.array([[0.0, 1.0], [2.0, 3.0]])
    assert rg.F52(H).shape == (2, 2)
    assert np.ndim(rg.F52(1.0)) == 0
    X = ca.SX.sym("X", 2, 2)
    f = ca.Function("f", [X], [rg.F52(X)])
    np.testing.assert_allclose(np.array(f(H)), rg.F52(H), rtol=1e-15)


def test_F52_on_MX_equals_numeric():
    x = ca.MX.sym("H")
    f = ca.Function("f", [x], [rg.F52(x)])
    for H in (-8.0, -1.3, 0.7, 4.2, 13.0):
        assert float(f(H)) == pytest.approx(rg.F52(H), rel=1e-14)


def test_bao_fit_values_and_cutoff():
    assert abs(rg.F52_bao_fit(0.0) - 0.550) < 5e-4   # PHYSICS.md: 0.550 at H = 0
    assert abs(rg.F52_bao_fit(3.0) - 4.4e-5) < 5e-7  # and 4.4e-5 at H = 3
    assert rg.F52_bao_fit(4.0) == 0.0
    assert np.all(rg.F52_bao_fit(np.array([4.5, 10.0])) == 0.0)


def test_bao_fit_smooth_form_close_to_exact_away_from_cutoff():
    H = np.linspace(-2, 3, 51)
    np.testing.assert_allclose(rg.F52_bao_fit(H, smooth=True), rg.F52_bao_fit(H), rtol=1e-8)
    assert rg.F52_bao_fit(5.0, smooth=True) < 1e-50   # and negligible beyond it


def test_bao_fit_exact_and_smooth_have_finite_hessians_at_cutoff():
    x = ca.SX.sym("H")
    for smooth in (False, True):
        y = rg.F52_bao_fit(x, smooth=smooth)
        f = ca.Function("h", [x], [ca.hessian(y, x)[0]])
        for H in (3.99, 4.0, 4.01):
            assert math.isfinite(float(f(H)))


def test_average_gap_matches_quadrature_of_its_definition():
    # h_T = int_{-h}^inf (h + delta) f(delta) d delta, delta ~ N(0, sigma^2); delta = sigma u
    sigma = 2.0e-6
    for H in (-2.0, -0.5, 0.0, 0.8, 2.5):
        h = H * sigma
        value, _ = integrate.quad(lambda u: sigma * (H + u) * stats.norm.pdf(u), -H, np.inf,
                                  epsabs=0.0, epsrel=1e-12)
        assert rg.average_gap(h, sigma) == pytest.approx(value, rel=1e-10)


def test_average_gap_derivative_matches_finite_differences():
    sigma = 3.0e-6
    for H in (-1.5, 0.0, 1.0, 3.0):
        h, dh = H * sigma, 1e-6 * sigma
        fd = (rg.average_gap(h + dh, sigma) - rg.average_gap(h - dh, sigma)) / (2 * dh)
        assert rg.average_gap_derivative(h, sigma) == pytest.approx(fd, rel=1e-8)


def test_average_gap_limits():
    sigma = 1.0e-6
    for H in (6.0, 8.0, 20.0):   # h_T - h = sigma F_1(H) -> 0
        assert abs(rg.average_gap(H * sigma, sigma) - H * sigma) < 1e-9 * sigma
    assert rg.average_gap(-10 * sigma, sigma) < 1e-20   # surfaces fully interpenetrated
    assert rg.average_gap(0.0, sigma) == pytest.approx(sigma / math.sqrt(2 * math.pi), rel=1e-15)


def test_patir_polynomial_within_3_percent_of_exact():
    sigma = 1.0
    H = np.linspace(0, 6, 601)
    ratio = rg.average_gap_patir(H * sigma, sigma) / rg.average_gap(H * sigma, sigma)
    assert np.max(np.abs(ratio - 1)) < 0.03
    assert abs(ratio[0] - 1) > 0.02   # the largest difference, 2.8 %, is at H = 0


def test_patir_branches_and_joins():
    sigma = 1.5e-6
    assert rg.average_gap_patir(4 * sigma, sigma) == 4 * sigma
    assert rg.average_gap_patir(-4 * sigma, sigma) == 0.0
    assert rg.average_gap_patir(0.0, sigma) == pytest.approx(105 / 256 * sigma, rel=1e-15)
    # value, slope and curvature continuous at H = +-3 (polynomial side vs outer side)
    x = ca.SX.sym("h")
    y = rg.average_gap_patir(x, 1.0)
    f = ca.Function("f", [x], [y, ca.gradient(y, x), ca.hessian(y, x)[0]])
    for H, outer in ((3.0, (3.0, 1.0, 0.0)), (-3.0, (0.0, 0.0, 0.0))):
        inner = [float(v) for v in f(H - math.copysign(1e-9, H))]
        np.testing.assert_allclose(inner, outer, atol=1e-7)


@pytest.mark.parametrize("fun", [rg.normal_pdf, rg.normal_cdf, rg.F0, rg.F1, rg.F2, rg.F52,
                                 rg.log_F52, rg.F52_bao_fit,
                                 lambda H: rg.F52_bao_fit(H, smooth=True)])
def test_one_argument_functions_symbolic_equals_numeric(fun):
    for H in (-7.0, -2.0, 0.0, 0.37, 2.0, 3.9, 5.5):
        # CasADi has no erfc: symbolic tails differ from numeric by ~1e-16 absolute
        assert sx_eval(fun, H) == pytest.approx(fun(H), rel=1e-12, abs=1e-15)


@pytest.mark.parametrize("fun", [rg.combined_sigma, rg.average_gap, rg.average_gap_derivative,
                                 rg.average_gap_patir])
def test_two_argument_functions_symbolic_equals_numeric(fun):
    sigma = 2.0e-6
    for H in (-4.0, -1.0, 0.0, 1.7, 3.5):
        h = H * sigma if fun is not rg.combined_sigma else abs(H) * 1e-6
        assert sx_eval(fun, h, sigma) == pytest.approx(fun(h, sigma), rel=1e-12, abs=1e-15 * sigma)


def test_F52_on_an_sx_scalar_is_the_same_expression_built_once():
    """The cached SX function (inlined at each call) gives the expression of the direct build:
    the same value, slope and curvature."""
    roughness = rg
    h = ca.SX.sym("h")
    cached = roughness.F52(h)
    direct = roughness.exp(roughness.log_F52(h))
    assert roughness._f52_sx() is roughness._f52_sx()                 # built once
    fns = [ca.Function("f", [h], [e, ca.gradient(e, h), ca.hessian(e, h)[0]]) for e in (cached, direct)]
    for H in (-8.0, -2.0, 0.0, 0.7, 3.0, 11.0, 14.0):
        got, want = ([float(v) for v in f(H)] for f in fns)
        assert got == pytest.approx(want, rel=1e-14, abs=0.0)
        assert got[0] == pytest.approx(float(roughness.F52(H)), rel=1e-14)
