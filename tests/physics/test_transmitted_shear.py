"""Tests of the transmitted shear factor (shear.transmitted_shear_factor) and its table."""

import casadi as ca
import numpy as np
import pytest

from clutchocp.physics import transmitted_shear_table as table
from clutchocp.physics.rough_wall_flow import transmitted_shear_ensemble
from clutchocp.physics.roughness import average_gap
from clutchocp.physics.shear import (shear_factor_phi_f, table_shear_factor, transmitted_shear_factor,
                                     viscous_torque)

R1, R2, ETA, W_REL = 0.0725, 0.0975, 0.03, 150.0
SIGMA = 2.0e-6


def Phi_fs_reference(H):
    """Cui Eq. 8 written out (A3 = 11.1, a4 = 2.31, a5 = 2.38, a6 = 0.11), 0 above H = 7."""
    return 11.1 * H**2.31 * np.exp(-2.38 * H + 0.11 * H**2) if 0 <= H <= 7 else 0.0


# ---------------------------------------------------------------- Patir-Cheng, which sign


@pytest.mark.parametrize("H", [0.3, 1.0, 2.5, 4.0, 6.9, 7.1, 20.0])
def test_patir_cheng_transmitted_is_phi_f_plus_Phi_fs(H):
    expected = float(shear_factor_phi_f(H)) + Phi_fs_reference(H)
    assert transmitted_shear_factor(H, 1.0, 0.0) == pytest.approx(expected, rel=1e-13)


def test_the_transmitted_torque_does_not_depend_on_which_surface_is_rough():
    # the torque both plates feel: phi_f + |V_r1 - V_r2| Phi_fs over the nominal film, whichever wall
    # carries the roughness (Zhang's smooth separator as surface 1, or the lining as surface 1)
    h = 2.0 * SIGMA
    expected = (float(shear_factor_phi_f(2.0)) + Phi_fs_reference(2.0)) * np.pi * ETA * W_REL * (R2**4 - R1**4) / (2 * h)
    for s1, s2 in [(0.0, SIGMA), (SIGMA, 0.0)]:
        for method in ("patir_cheng", "table"):
            assert viscous_torque(W_REL, h, ETA, R1, R2, sigma_1=s1, sigma_2=s2, method=method) == pytest.approx(
                viscous_torque(W_REL, h, ETA, R1, R2, sigma_1=s2, sigma_2=s1, method=method), rel=1e-14)
        assert viscous_torque(W_REL, h, ETA, R1, R2, sigma_1=s1, sigma_2=s2, method="patir_cheng") == pytest.approx(
            expected, rel=1e-12)


def test_the_table_torque_is_phi_T_over_the_average_gap():
    # phi_T is defined over h_T (the table's own definition): T = phi_T pi eta w (r2^4 - r1^4) / (2 h_T)
    for H in (0.5, 1.0, 2.0, 4.0):
        h = H * SIGMA
        h_T = float(average_gap(h, SIGMA))
        expected = float(table_shear_factor(H)) * np.pi * ETA * W_REL * (R2**4 - R1**4) / (2 * h_T)
        got = viscous_torque(W_REL, h, ETA, R1, R2, sigma_1=SIGMA, sigma_2=0.0, method="table")
        assert got == pytest.approx(expected, rel=1e-12)
        assert transmitted_shear_factor(H, SIGMA, 0.0, method="table") == pytest.approx(
            float(table_shear_factor(H)) * H / (h_T / SIGMA), rel=1e-12)
    # equal roughness: the excess over phi_f is scaled by |V_r1 - V_r2| = 0 in both methods
    for method in ("patir_cheng", "table"):
        assert transmitted_shear_factor(1.5, SIGMA, SIGMA, method=method) == pytest.approx(
            float(shear_factor_phi_f(1.5)), rel=1e-12)


def test_an_unknown_method_is_refused():
    with pytest.raises(ValueError, match="method"):
        viscous_torque(W_REL, SIGMA, ETA, R1, R2, sigma_1=SIGMA, method="plus")
    with pytest.raises(ValueError, match="method"):
        transmitted_shear_factor(1.0, SIGMA, 0.0, method="minus")


# ---------------------------------------------------------------- the table's interpolant


def test_table_interpolant_passes_through_the_table():
    values = table_shear_factor(np.array(table.H))
    np.testing.assert_allclose(values, table.PHI_T, rtol=1e-12)


def test_table_interpolant_is_c2():
    # first and second derivatives continuous across every table point (and the spline's knots)
    Hs = ca.SX.sym("H")
    phi = table_shear_factor(Hs)
    d1 = ca.Function("d1", [Hs], [ca.jacobian(phi, Hs)])
    d2 = ca.Function("d2", [Hs], [ca.hessian(phi, Hs)[0]])
    for H in table.H[1:]:
        left, right = H - 1e-7, H + 1e-7
        assert float(d1(left)) == pytest.approx(float(d1(right)), rel=1e-5, abs=1e-6)
        assert float(d2(left)) == pytest.approx(float(d2(right)), rel=1e-4, abs=1e-5)


def test_table_interpolant_far_field():
    # phi_T -> 1 + 2.5 / H^2 (Couette 1/H^2 + half the isotropic form drag 3/H^2)
    for H in (1e3, 1e4):
        assert (table_shear_factor(H) - 1) * H**2 == pytest.approx(2.5, rel=10 / H)
    H = np.linspace(table.H[-1], 200.0, 400)
    phi = table_shear_factor(H)
    assert np.all(np.diff(phi) < 0) and np.all(phi > 1)


def test_table_interpolant_numeric_equals_symbolic():
    H = np.array([-0.5, 0.0, 0.1, 0.9, 1.3, 2.2, 3.3, 5.5, 9.0, 15.0, 1e3])
    numeric = table_shear_factor(H)
    for sym in (ca.SX, ca.MX):
        x = sym.sym("H", H.size)
        f = ca.Function("f", [x], [table_shear_factor(x)])
        np.testing.assert_allclose(np.array(f(H)).ravel(), numeric, rtol=1e-14)
    np.testing.assert_allclose(np.array(table_shear_factor(ca.DM(H))).ravel(), numeric,
                               rtol=1e-14)
    assert table_shear_factor(-1.0) == table_shear_factor(0.0)
    smooth = table_shear_factor(H, smooth=True)
    assert np.all(np.abs(smooth - numeric)[H >= 0.5] < 1e-6 * numeric[H >= 0.5])


def solver_with_table_walls(H, cells_per_length):
    """The solver on the table's own walls (seeds, box, cut-off), at other film ratios."""
    return transmitted_shear_ensemble(H, 24, length=8.0, cells_per_length=cells_per_length, seed=0)


def test_table_matches_the_solver_between_table_points():
    # the same 24 walls as the table (common random numbers: the solver's curve is smooth in H and
    # the table samples it), 8 cells per lambda (without contact 0.05 % from 16): the interpolant
    # between table points is within 0.2 %
    H = np.array([4.5, 7.0])
    run = solver_with_table_walls(H, 8)
    assert np.all(run.contact_fraction == 0)
    np.testing.assert_allclose(table_shear_factor(H), run.transmitted, rtol=2e-3)


@pytest.mark.slow
def test_table_matches_the_solver_in_the_mixed_range():
    # with contact lines, at the table's resolution (32 cells per lambda): within 2 %, well inside
    # the ensemble's standard error
    H = np.array([0.875, 1.625, 2.75])
    run = solver_with_table_walls(H, 32)
    assert np.all(run.contact_fraction > 0)
    np.testing.assert_allclose(table_shear_factor(H), run.transmitted, rtol=0.02)


def test_table_is_registered_for_the_numpy_form():
    # the numpy translation of a model calling the table gives CasADi's values to rounding
    from clutchocp.simulation import vectorized

    h = ca.SX.sym("h")
    f = ca.Function("f", [h], [table_shear_factor(h)])
    assert not vectorized.calls_unregistered(f)
    x = np.linspace(-1.0, 30.0, 2001)
    out = np.empty(x.size)
    vectorized.numpy_function(f)([x[None, :]], [out[None, :]])
    np.testing.assert_allclose(out, table_shear_factor(x), rtol=1e-12)
