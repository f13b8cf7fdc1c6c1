"""Tests of clutchocp.physics.fractal: Cui 2019 Eq. 10-17 (Majumdar-Bhushan asperity load)."""

import math

import casadi as ca
import numpy as np
import pytest
from scipy import integrate

from clutchocp.errors import PhysicalRangeError
from clutchocp.physics import fractal as fc

# Cui 2019 Table 2 (yield strength: the "compressive strength" 110 MPa; hardness 50 N/mm^2)
A_A = fc.cui_nominal_area(0.043, 0.0615, 0.78)
CUI = dict(D=1.54, G=1.584e-11, E_equiv=2.176e9, hardness=50e6, yield_strength=110e6, nominal_area=A_A)


def load_by_quadrature(area_ratio, D, G, E_equiv, hardness, yield_strength, nominal_area):
    """W_a / A_a integrated from the spot-size distribution itself (independent of Eq. 10)."""
    psi = fc.domain_extension_factor(D)
    a_l = fc.largest_contact_area(area_ratio * nominal_area, D)
    a_c = fc.critical_contact_area(D, G, E_equiv, yield_strength)

    # spots per unit size (Wang-Komvopoulos / M-B): n(a) = c_n a^{-(D+2)/2}
    log_cn = math.log(D / 2 * psi ** ((2 - D) / 2) * a_l ** (D / 2))
    # loads per spot: elastic (4 sqrt(pi)/3) E G^{D-1} a^{(3-D)/2}, plastic H a
    log_ce = math.log(4 * math.sqrt(math.pi) / 3 * E_equiv * G ** (D - 1))

    def in_log(log_c, power):   # f(a) n(a) da in x = ln a, computed in logs (no overflow)
        return lambda x: math.exp(log_c + log_cn + (power - (D + 2) / 2 + 1) * x)

    a_m = min(a_c, a_l)
    # plastic integrand ~ a^{(2-D)/2} in x = ln a: start 40 e-folds below its top
    plastic, _ = integrate.quad(in_log(math.log(hardness), 1.0), math.log(a_m) - 80 / (2 - D), math.log(a_m),
                                epsabs=0.0, epsrel=1e-12, limit=200)
    el = 0.0
    if a_l > a_c:
        el, _ = integrate.quad(in_log(log_ce, (3 - D) / 2), math.log(a_c), math.log(a_l), epsabs=0.0, epsrel=1e-12,
                               limit=200)
    return (plastic + el) / nominal_area


def test_domain_extension_factor_solves_eq17_and_has_known_limits():
    for D in (1.05, 1.3, 1.5, 1.54, 1.8, 1.95):
        psi = fc.domain_extension_factor(D)
        e = (2 - D) / D
        assert (psi ** ((2 - D) / 2) - (1 + psi ** (-D / 2)) ** (-e)) / e == pytest.approx(1.0, abs=1e-13)
        assert psi > 1
    # D -> 1: Psi/(sqrt(Psi) + 1) = 1, Psi = golden ratio squared;  D -> 2: ln(1 + Psi) = 1
    assert fc.domain_extension_factor(1.0001) == pytest.approx((1 + math.sqrt(5)) ** 2 / 4, rel=1e-3)
    assert fc.domain_extension_factor(1.9999) == pytest.approx(math.e - 1, rel=1e-3)


def test_g1_g2_identity_and_real_area_integral():
    for D in (1.2, 1.54, 1.8):
        # g1 (3 - 2D) / (2 - D) = (D/(2-D))^{1 - D/2} = g2
        assert fc.fractal_g1(D) * (3 - 2 * D) / (2 - D) == pytest.approx(fc.fractal_g2(D), rel=1e-14)
        # Eq. 12: the spot-size distribution integrates to A_r
        psi, A_r = fc.domain_extension_factor(D), 2.5e-5
        a_l = fc.largest_contact_area(A_r, D)
        total, _ = integrate.quad(
            lambda x: D / 2 * psi ** ((2 - D) / 2) * a_l ** (D / 2) * math.exp(x) ** ((2 - D) / 2),
            math.log(a_l) - 200, math.log(a_l), epsabs=0.0, epsrel=1e-12, limit=200)
        assert total == pytest.approx(A_r, rel=1e-10)


def test_cui_nominal_area_and_critical_area():
    assert A_A == pytest.approx(0.78 * math.pi * (0.0615**2 - 0.043**2), rel=1e-15)
    assert A_A == pytest.approx(4.7373e-3, rel=1e-4)
    a_c = fc.critical_contact_area(1.54, 1.584e-11, 2.176e9, 110e6)
    assert a_c == pytest.approx(1.584e-11**2 * (math.pi * 2.176e9**2 / (225 * 110e6**2)) ** (1 / 0.54), rel=1e-14)


@pytest.mark.parametrize("D", [1.3, 1.5, 1.54, 1.8])
@pytest.mark.parametrize("area_ratio", [1e-19, 1e-6, 1e-3, 0.2])
def test_eq10_11_match_quadrature_of_size_distribution(D, area_ratio):
    params = dict(CUI, D=D)
    expected = load_by_quadrature(area_ratio, **params)
    assert fc.fractal_contact_pressure(area_ratio, **params) == pytest.approx(expected, rel=1e-9)


def test_all_plastic_branch_is_hardness_times_area():
    # a_l < a_c (tiny real area with Cui's data, a_c = 5.8e-21 m^2): Cui Eq. 11
    for ratio in (1e-22, 1e-20, 1e-19):
        assert fc.fractal_contact_pressure(ratio, **CUI) == pytest.approx(CUI["hardness"] * ratio, rel=1e-12)


def test_continuous_where_largest_spot_equals_critical_area():
    for D in (1.3, 1.5, 1.54):
        params = dict(CUI, D=D)
        a_c = fc.critical_contact_area(D, params["G"], params["E_equiv"], params["yield_strength"])
        ratio_at_switch = a_c / fc.largest_contact_area(A_A, D)   # A_r* with a_l = a_c
        for factor in (1 - 1e-9, 1 + 1e-9):
            ratio = ratio_at_switch * factor
            assert fc.fractal_contact_pressure(ratio, **params) == pytest.approx(
                params["hardness"] * ratio, rel=1e-8)


def test_general_branch_tends_to_D_equal_1p5_branch():
    for ratio in (1e-6, 1e-3, 0.3):
        at = fc.fractal_contact_pressure(ratio, **dict(CUI, D=1.5))
        for d in (1e-5, 1e-6):
            lo = fc.fractal_contact_pressure(ratio, **dict(CUI, D=1.5 - d))
            hi = fc.fractal_contact_pressure(ratio, **dict(CUI, D=1.5 + d))
            assert abs(hi / at - 1) < 5 * d and abs(lo / at - 1) < 5 * d   # O(d): ~3 d measured
            assert (lo + hi) / 2 == pytest.approx(at, rel=1e-8)           # O(d^2): 3.4e-9 at d = 1e-5


@pytest.mark.parametrize("D", [1.2, 1.5, 1.54, 1.9])
def test_load_increases_with_area_ratio(D):
    ratio = np.logspace(-24, 0, 241)
    load = fc.fractal_contact_pressure(ratio, **dict(CUI, D=D))
    assert np.all(np.diff(load) > 0)


def test_smooth_switch_close_to_exact_away_from_switch():
    ratio = np.logspace(-24, 0, 241)
    D = CUI["D"]
    a_c = fc.critical_contact_area(D, CUI["G"], CUI["E_equiv"], CUI["yield_strength"])
    distance = np.abs(np.log(fc.largest_contact_area(ratio * A_A, D) / a_c))
    far = distance >= 1
    exact = fc.fractal_contact_pressure(ratio, **CUI)
    smooth = fc.fractal_contact_pressure(ratio, **CUI, smooth=True)
    np.testing.assert_allclose(smooth[far], exact[far], rtol=1e-6)
    assert np.all(np.diff(smooth) > 0)   # still increasing through the switch


def test_load_is_pressure_times_nominal_area():
    assert fc.fractal_contact_load(1e-3, **CUI) == pytest.approx(A_A * fc.fractal_contact_pressure(1e-3, **CUI),
                                                                 rel=1e-15)


@pytest.mark.parametrize("D", [1.3, 1.5, 1.54])
@pytest.mark.parametrize("smooth", [False, True])
def test_symbolic_equals_numeric(D, smooth):
    x, e, h = ca.SX.sym("x"), ca.SX.sym("E"), ca.SX.sym("H")
    params = dict(CUI, D=D)
    expr = fc.fractal_contact_pressure(x, D, params["G"], e, h, params["yield_strength"], A_A, smooth=smooth)
    f = ca.Function("w", [x, e, h], [expr, ca.hessian(expr, x)[0]])
    for ratio in (1e-20, 1e-4, 0.1):
        value, hess = f(ratio, params["E_equiv"], params["hardness"])
        assert float(value) == pytest.approx(fc.fractal_contact_pressure(ratio, **params, smooth=smooth), rel=1e-12)
        assert math.isfinite(float(hess))


def test_bad_dimension_rejected():
    for D in (1.0, 2.0, 2.5):
        with pytest.raises(PhysicalRangeError, match="fractal dimension"):
            fc.fractal_contact_pressure(1e-3, **dict(CUI, D=D))
    with pytest.raises(PhysicalRangeError, match="number"):
        fc.fractal_contact_pressure(1e-3, **dict(CUI, D=ca.SX.sym("D")))
