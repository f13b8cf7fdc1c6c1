"""Tests of clutchocp.physics.shear (Patir–Cheng shear factors, viscous torque)."""

import casadi as ca
import mpmath
import numpy as np
import pytest
from scipy.integrate import dblquad, quad

from clutchocp.physics.roughness import average_gap
from clutchocp.physics.shear import (grooved_viscous_torque, shear_factor_phi_f, shear_factor_phi_fs,
                                     viscous_torque)

R1, R2 = 0.0725, 0.0975          # m
ETA = 0.03                       # Pa s
W_REL = 150.0                    # rad/s
S1, S2 = 1.2e-6, 0.5e-6          # m


def phi_f_mp(H, eps=mpmath.mpf(1) / 300):
    """Cui 2019 Eq. 6 as printed, in 60-digit arithmetic (no cancellation problem)."""
    with mpmath.workdps(60):
        z = mpmath.mpf(H) / 3
        if z <= 1:
            poly = -55 + z * (132 + z * (345 + z * (-160 + z * (-405 + z * (60 + 147 * z)))))
            value = mpmath.mpf(35) / 32 * z * ((1 - z**2) ** 3 * mpmath.log((z + 1) / eps) + poly / 60)
        else:
            value = mpmath.mpf(35) / 32 * z * ((1 - z**2) ** 3 * mpmath.log((z + 1) / (z - 1))
                                               + z / 15 * (66 + z**2 * (30 * z**2 - 80)))
        return float(value)


def Phi_fs_reference(H):
    """Cui Eq. 8 written out (A3 = 11.1, a4 = 2.31, a5 = 2.38, a6 = 0.11)."""
    return 11.1 * H**2.31 * np.exp(-2.38 * H + 0.11 * H**2) if 0 <= H <= 7 else 0.0


# ---------------------------------------------------------------- phi_f

H_GRID = [1e-3, 0.1, 0.5, 1.0, 2.0, 2.999, 3.0, 3.001, 4.0, 5.5, 5.999, 6.0, 6.001, 8.0,
          15.0, 60.0, 400.0, 3000.0]


@pytest.mark.parametrize("H", H_GRID)
def test_phi_f_matches_cui_eq6_in_high_precision(H):
    assert shear_factor_phi_f(H) == pytest.approx(phi_f_mp(H), rel=5e-14)


def test_phi_f_tends_to_one_like_gaussian_mean():
    # phi_f = 1 + 1/H^2 + O(H^-4) (E[h / h_T] of a Gaussian gap); tends to 1
    for H in (1e3, 1e4):
        assert (shear_factor_phi_f(H) - 1) * H**2 == pytest.approx(1.0, rel=3e-6)
    assert shear_factor_phi_f(1e6) == pytest.approx(1 + 1e-12, rel=1e-15)
    assert shear_factor_phi_f(1e12) == 1.0


def test_phi_f_zero_at_zero_and_below():
    assert shear_factor_phi_f(0.0) == 0.0
    np.testing.assert_array_equal(shear_factor_phi_f(np.array([-10.0, -3.0, -1.0, 0.0])), 0.0)
    # near zero phi_f ~ (35/32) (H/3) (ln(1/eps*) - 55/60)
    H = 1e-6
    assert shear_factor_phi_f(H) == pytest.approx(35 / 32 * H / 3 * (np.log(300) - 55 / 60), rel=1e-5)


def _ad_function(expr_builder):
    x = ca.SX.sym("x")
    e = expr_builder(x)
    d1 = ca.gradient(e, x)
    d2 = ca.gradient(d1, x)
    return ca.Function("f", [x], [e, d1, d2])


def test_phi_f_c2_at_three():
    f = _ad_function(shear_factor_phi_f)
    left, right = f(3 - 1e-7), f(3 + 1e-7)
    assert float(left[0]) == pytest.approx(7 / 6, rel=1e-7)
    assert float(right[0]) == pytest.approx(7 / 6, rel=1e-7)
    # from the polynomials of Cui Eq. 6 at z = 1 (the log terms have a triple zero there):
    # d/dz = (35/32)(-8/15) = -7/12, d2/dz2 = (35/32)(24/5) = 21/4; per unit H divide by 3 and 9
    assert float(left[1]) == pytest.approx(-7 / 36, rel=1e-5)
    assert float(right[1]) == pytest.approx(-7 / 36, rel=1e-5)
    assert float(left[2]) == pytest.approx(float(right[2]), rel=1e-4)
    assert float(left[2]) == pytest.approx(21 / 4 / 9, rel=1e-4)


def test_phi_f_series_switch_at_six_is_seamless():
    f = _ad_function(shear_factor_phi_f)
    left, right = f(6 - 1e-9), f(6 + 1e-9)
    for a, b in zip(left, right):
        assert float(a) == pytest.approx(float(b), rel=1e-7)


@pytest.mark.parametrize("smooth", [False, True])
def test_phi_f_symbolic_finite_everywhere(smooth):
    """Both if_else branches are evaluated by CasADi: value and derivatives stay finite."""
    f = _ad_function(lambda x: shear_factor_phi_f(x, smooth=smooth))
    for H in (-50.0, -3.0, -1.0, 0.0, 1e-12, 3.0, 6.0, 1e3, 1e8):
        assert all(np.isfinite(float(v)) for v in f(H))


def test_phi_f_smooth_within_tolerance():
    Hs = np.linspace(0.5, 50, 5001)
    exact, smooth = shear_factor_phi_f(Hs), shear_factor_phi_f(Hs, smooth=True)
    assert np.max(np.abs(smooth / exact - 1)) < 1e-5
    assert np.max(np.abs(shear_factor_phi_f(np.linspace(-5, -0.5, 50), smooth=True))) < 1e-5


# ---------------------------------------------------------------- phi_fs

def test_phi_fs_equals_cui_eq8_and_vanishes_above_seven():
    Vd = (S1**2 - S2**2) / (S1**2 + S2**2)
    for H in (0.0, 0.3, 1.0, 2.5, 5.0, 6.99, 7.0):
        assert shear_factor_phi_fs(H, S1, S2) == pytest.approx(Vd * Phi_fs_reference(H), rel=1e-13, abs=0)
    np.testing.assert_array_equal(shear_factor_phi_fs(np.array([7.0001, 8.0, 12.0, 100.0, 1e5]), S1, S2), 0.0)
    assert shear_factor_phi_fs(-1.0, S1, S2) == 0.0
    assert shear_factor_phi_fs(1.0, S1, S2) == pytest.approx(Vd * 11.1 * np.exp(-2.27), rel=1e-14)


def test_phi_fs_roughness_weights():
    assert shear_factor_phi_fs(1.0, S1, S1) == 0.0                 # equal roughness
    assert shear_factor_phi_fs(1.0, 0.0, 0.0) == 0.0               # smooth plates
    assert shear_factor_phi_fs(1.0, S1, S2) == pytest.approx(-shear_factor_phi_fs(1.0, S2, S1), rel=1e-15)
    assert shear_factor_phi_fs(1.0, S1, 0.0) == pytest.approx(Phi_fs_reference(1.0), rel=1e-14)


def test_phi_fs_smooth_within_tolerance():
    below = np.linspace(0.0, 6.5, 651)
    exact, smooth = shear_factor_phi_fs(below, S1, 0.0), shear_factor_phi_fs(below, S1, 0.0, smooth=True)
    assert np.max(np.abs(smooth - exact) / np.maximum(exact, 1e-300)) < 5e-5
    above = np.linspace(7.5, 1e3, 2001)
    assert np.max(np.abs(shear_factor_phi_fs(above, S1, 0.0, smooth=True))) < 1e-6
    # the smooth cut-off passes through half the jump at H = 7
    assert shear_factor_phi_fs(7.0, S1, 0.0, smooth=True) == pytest.approx(0.5 * Phi_fs_reference(7.0), rel=1e-9)


@pytest.mark.parametrize("smooth", [False, True])
def test_phi_fs_symbolic_finite_everywhere(smooth):
    f = _ad_function(lambda x: shear_factor_phi_fs(x, S1, S2, smooth=smooth))
    for H in (-5.0, 0.0, 1.0, 7.0, 20.0, 1e4):
        assert all(np.isfinite(float(v)) for v in f(H))


# ---------------------------------------------------------------- torque

def test_viscous_torque_newtonian_limit():
    plain = np.pi * ETA * W_REL * (R2**4 - R1**4) / (2 * 40e-6)
    assert viscous_torque(W_REL, 40e-6, ETA, R1, R2) == pytest.approx(plain, rel=1e-15)
    # second method: integrate the Newtonian stress eta w r / h times r over the annulus
    T, _ = dblquad(lambda r, th: ETA * W_REL * r / 40e-6 * r * r, 0, 2 * np.pi, R1, R2, epsrel=1e-12)
    assert viscous_torque(W_REL, 40e-6, ETA, R1, R2) == pytest.approx(T, rel=1e-10)
    # rough plates far apart (H = 1000) approach it: phi_f - 1 = 1e-6, h_T = h
    rough = viscous_torque(W_REL, 1e3 * 1.3e-6, ETA, R1, R2, sigma_1=1.2e-6, sigma_2=0.5e-6)
    assert rough == pytest.approx(np.pi * ETA * W_REL * (R2**4 - R1**4) / (2 * 1.3e-3), rel=2e-6)


def test_viscous_torque_equals_quadrature_of_cui_eq5():
    h = 2.0e-6
    sigma = np.hypot(S1, S2)
    H = h / sigma
    tau_factor = (shear_factor_phi_f(H) - shear_factor_phi_fs(H, S1, S2)) / average_gap(h, sigma)
    area_ratio, land = 0.05, 0.8
    # Cui Eq. 5 stress, integrated over the land area not in contact
    T, _ = dblquad(lambda r, th: ETA * W_REL * r * tau_factor * r * r, 0, 2 * np.pi, R1, R2, epsrel=1e-12)
    T *= (1 - area_ratio) * land
    got = viscous_torque(W_REL, h, ETA, R1, R2, sigma_1=S1, sigma_2=S2, area_ratio=area_ratio,
                         land_fraction=land)
    assert got == pytest.approx(T, rel=1e-10)
    assert viscous_torque(-W_REL, h, ETA, R1, R2, sigma_1=S1, sigma_2=S2) < 0


def test_viscous_torque_smooth_close_to_exact():
    for h in (0.8e-6, 3e-6, 20e-6):
        exact = viscous_torque(W_REL, h, ETA, R1, R2, sigma_1=S1, sigma_2=S2)
        smooth = viscous_torque(W_REL, h, ETA, R1, R2, sigma_1=S1, sigma_2=S2, smooth=True)
        assert smooth == pytest.approx(exact, rel=5e-5)


def test_grooved_torque_without_grooves_is_liao_eq1():
    h, n = 30e-6, 6
    eq1 = 0.5 * n * np.pi * ETA * W_REL * (R2**4 - R1**4) / h        # Liao Eq. 1
    for K2 in (0.5, 1.0, 3.0):
        assert grooved_viscous_torque(W_REL, h, ETA, R1, R2, 0.0, K2, n) == pytest.approx(eq1, rel=1e-14)
    assert grooved_viscous_torque(W_REL, h, ETA, R1, R2, 0.0, 1.0) == pytest.approx(
        viscous_torque(W_REL, h, ETA, R1, R2), rel=1e-14)


def test_grooved_torque_equals_sector_quadrature():
    """Integrate eta w r^3 / gap(theta) over z periods of groove (h + h_a) and land (h)."""
    h, h_a, K2, z = 30e-6, 0.3e-3, 2.5, 12
    period = 2 * np.pi / z
    th1 = period / (1 + K2)                                          # groove angle

    def gap(th):
        return h + h_a if (th % period) < th1 else h

    radial = ETA * W_REL * (R2**4 - R1**4) / 4                       # int r^3 dr times eta w
    breaks = sorted([k * period for k in range(z)] + [k * period + th1 for k in range(z)])
    T, _ = quad(lambda th: radial / gap(th), 0, 2 * np.pi, points=breaks[1:], limit=200, epsrel=1e-12)
    assert grooved_viscous_torque(W_REL, h, ETA, R1, R2, h_a, K2) == pytest.approx(T, rel=1e-9)
    # all land / all groove limits
    plain = viscous_torque(W_REL, h, ETA, R1, R2)
    assert grooved_viscous_torque(W_REL, h, ETA, R1, R2, h_a, 1e12) == pytest.approx(plain, rel=1e-11)
    deep = viscous_torque(W_REL, h + h_a, ETA, R1, R2)
    assert grooved_viscous_torque(W_REL, h, ETA, R1, R2, h_a, 1e-12) == pytest.approx(deep, rel=1e-9)


# ---------------------------------------------------------------- symbolic == numeric

@pytest.mark.parametrize("smooth", [False, True])
def test_shear_factors_symbolic_equal_numeric(smooth):
    x, s1, s2 = ca.SX.sym("x"), ca.SX.sym("s1"), ca.SX.sym("s2")
    f = ca.Function("f", [x, s1, s2], [shear_factor_phi_f(x, smooth=smooth),
                                       shear_factor_phi_fs(x, s1, s2, smooth=smooth)])
    for H in (-1.0, 0.0, 0.2, 1.0, 3.0, 4.5, 6.0, 6.9, 7.0, 7.2, 30.0, 5e3):
        pf, pfs = f(H, S1, S2)
        assert float(pf) == pytest.approx(float(shear_factor_phi_f(H, smooth=smooth)), rel=1e-14, abs=1e-300)
        assert float(pfs) == pytest.approx(float(shear_factor_phi_fs(H, S1, S2, smooth=smooth)),
                                           rel=1e-13, abs=1e-300)


@pytest.mark.parametrize("smooth", [False, True])
def test_torques_symbolic_equal_numeric(smooth):
    names = ["w", "h", "eta", "r1", "r2", "s1", "s2", "ac", "psi", "ha", "K2", "n"]
    w, h, eta, r1, r2, s1, s2, ac, psi, ha, K2, n = syms = [ca.SX.sym(k) for k in names]
    f = ca.Function("f", syms, [
        viscous_torque(w, h, eta, r1, r2, sigma_1=s1, sigma_2=s2, area_ratio=ac, land_fraction=psi,
                       smooth=smooth),
        grooved_viscous_torque(w, h, eta, r1, r2, ha, K2, n)])
    for hv in (0.5e-6, 2e-6, 8e-6, 40e-6):
        vals = [W_REL, hv, ETA, R1, R2, S1, S2, 0.03, 0.85, 0.3e-3, 2.0, 4]
        Tv, Tg = f(*vals)
        assert float(Tv) == pytest.approx(viscous_torque(W_REL, hv, ETA, R1, R2, sigma_1=S1, sigma_2=S2,
                                                         area_ratio=0.03, land_fraction=0.85,
                                                         smooth=smooth), rel=1e-13)
        assert float(Tg) == pytest.approx(grooved_viscous_torque(W_REL, hv, ETA, R1, R2, 0.3e-3, 2.0, 4),
                                          rel=1e-14)
