"""Tests of clutchocp.physics.spline (Chen 2021 spline friction through the pack)."""

import math

import casadi as ca
import numpy as np
import pytest

from clutchocp.errors import ModelError
from clutchocp.physics.spline import (attenuation_coefficient, equivalent_cof, interface_pressures,
                                      pack_torque, pack_torque_uniform)

# Chen 2021 Table 1
R1, R2 = 0.06, 0.073                   # m
R_SEP, A_SEP = 0.076, math.radians(27)  # separator plate: pitch radius, pressure angle
R_FRI, A_FRI = 0.057, math.radians(30)  # friction disc
# Chen 2021 Table 2 (two-pair mu*) and Table 3 (calculated six-pair torque)
PRESSURES = [0.2e6, 0.4e6, 0.6e6, 0.8e6, 1.6e6]
MU2 = [0.07444, 0.07271, 0.07143, 0.07091, 0.06696]
TABLE3 = {0.1: [30.747, 60.136, 88.694, 117.44, 222.4],
          0.15: [29.977, 58.664, 86.56, 114.64, 217.37]}


def chen_torque(p0, mu, mu_s, n=6):
    z_sep = attenuation_coefficient(mu, mu_s, R1, R2, R_SEP, A_SEP)
    z_fri = attenuation_coefficient(mu, mu_s, R1, R2, R_FRI, A_FRI)
    return pack_torque(interface_pressures(p0, z_sep, z_fri, n), mu, R1, R2)


@pytest.mark.parametrize("mu_s", [0.1, 0.15])
@pytest.mark.parametrize("k", range(5))
def test_chen_table3_within_0p1_percent(mu_s, k):
    torque = chen_torque(PRESSURES[k], MU2[k], mu_s)
    assert torque == pytest.approx(TABLE3[mu_s][k], rel=1e-3)


def test_attenuation_coefficient_value():
    # Chen Eq. 8 by hand for the separator, mu = 0.07444, mu_s = 0.1
    expected = 2 * 0.07444 * 0.1 * (R2**3 - R1**3) / (3 * R_SEP * (R2**2 - R1**2) * math.cos(A_SEP))
    assert attenuation_coefficient(0.07444, 0.1, R1, R2, R_SEP, A_SEP) == pytest.approx(expected, rel=1e-14)
    assert expected == pytest.approx(7.3336e-3, rel=1e-4)


@pytest.mark.parametrize("zeta", [1e-4, 0.01, 0.2, 0.7])
@pytest.mark.parametrize("n", [1, 2, 7, 16])
def test_uniform_zeta_closed_form(zeta, n):
    """Equal zeta: p_k = p0 q^(k-1) / (1 + zeta), q = (1 - zeta)/(1 + zeta); sum = p0 (1 - q^n) / (2 zeta)."""
    p0 = 1.3e6
    p = interface_pressures(p0, zeta, zeta, n)
    q = (1 - zeta) / (1 + zeta)
    k = np.arange(1, n + 1)
    np.testing.assert_allclose(p, p0 * q ** (k - 1) / (1 + zeta), rtol=1e-13)
    assert p.sum() == pytest.approx(p0 * (1 - q**n) / (2 * zeta), rel=1e-12)


def test_force_balance_of_every_plate():
    """Second method (Chen Eq. 3, 4, 6): p_k A - F_s = p_{k+1} A with F_s = mu_s T / (R_p cos alpha)."""
    mu, mu_s, p0, n = 0.07, 0.15, 0.9e6, 9
    zs = attenuation_coefficient(mu, mu_s, R1, R2, R_SEP, A_SEP)
    zf = attenuation_coefficient(mu, mu_s, R1, R2, R_FRI, A_FRI)
    p = interface_pressures(p0, zs, zf, n)
    area = math.pi * (R2**2 - R1**2)
    c = 2 * math.pi / 3 * mu * (R2**3 - R1**3)
    # plate next to the piston: one rubbing face
    f_s = mu_s * c * p[0] / (R_SEP * math.cos(A_SEP))
    assert p0 * area - f_s == pytest.approx(p[0] * area, rel=1e-13)
    for k in range(n - 1):
        radius, angle = (R_FRI, A_FRI) if k % 2 == 0 else (R_SEP, A_SEP)
        f_s = mu_s * c * (p[k] + p[k + 1]) / (radius * math.cos(angle))
        assert p[k] * area - f_s == pytest.approx(p[k + 1] * area, rel=1e-13)


def test_no_spline_friction_gives_eq9_and_eq11_inverts_it():
    p = interface_pressures(0.5e6, 0.0, 0.0, 6)
    np.testing.assert_array_equal(p, 0.5e6)
    t = pack_torque(p, 0.08, R1, R2)
    assert t == pytest.approx(pack_torque_uniform(0.5e6, 0.08, R1, R2, 6), rel=1e-14)
    assert equivalent_cof(t, 0.5e6, R1, R2, 6) == pytest.approx(0.08, rel=1e-14)


def test_chen_eq10_odd_sum_erratum():
    """Chen Eq. 10 summed over i = 1, 3, 5 only gives about half of Chen's own Table 3."""
    mu, p0 = MU2[0], PRESSURES[0]
    zs = attenuation_coefficient(mu, 0.1, R1, R2, R_SEP, A_SEP)
    zf = attenuation_coefficient(mu, 0.1, R1, R2, R_FRI, A_FRI)
    p = interface_pressures(p0, zs, zf, 6)
    odd_only = pack_torque(p[0::2], mu, R1, R2)
    assert odd_only / TABLE3[0.1][0] == pytest.approx(0.5, abs=0.02)
    assert pack_torque(p, mu, R1, R2) == pytest.approx(TABLE3[0.1][0], rel=1e-3)


def test_mu_forms_agree():
    p = interface_pressures(0.8e6, 0.01, 0.02, 5)
    t_scalar = pack_torque(p, 0.07, R1, R2)
    assert pack_torque(p, [0.07] * 5, R1, R2) == pytest.approx(t_scalar, rel=1e-15)
    assert pack_torque(p, lambda pk: 0.07 + 0 * pk, R1, R2) == pytest.approx(t_scalar, rel=1e-15)
    mus = [0.06, 0.07, 0.08, 0.09, 0.1]
    expected = 2 * math.pi / 3 * (R2**3 - R1**3) * sum(m * pk for m, pk in zip(mus, p))
    assert pack_torque(p, mus, R1, R2) == pytest.approx(expected, rel=1e-14)
    with pytest.raises(ModelError):
        pack_torque(p, [0.07] * 4, R1, R2)


def test_array_pressures_broadcast():
    p0 = np.array(PRESSURES)
    mu = np.array(MU2)
    torque = chen_torque(p0, mu, 0.1)
    np.testing.assert_allclose(torque, [chen_torque(a, b, 0.1) for a, b in zip(PRESSURES, MU2)], rtol=1e-14)
    assert interface_pressures(p0, 0.01, 0.02, 6).shape == (6, 5)


def test_symbolic_equals_numeric():
    p0, mu, mu_s, angle = ca.SX.sym("p0"), ca.SX.sym("mu"), ca.SX.sym("mu_s"), ca.SX.sym("alpha")
    zs = attenuation_coefficient(mu, mu_s, R1, R2, R_SEP, angle)
    zf = attenuation_coefficient(mu, mu_s, R1, R2, R_FRI, A_FRI)
    pressures = interface_pressures(p0, zs, zf, 6)
    f = ca.Function("f", [p0, mu, mu_s, angle], [pack_torque(pressures, mu, R1, R2), ca.vertcat(*pressures)])
    t_sym, p_sym = f(PRESSURES[2], MU2[2], 0.15, A_SEP)
    zs_n = attenuation_coefficient(MU2[2], 0.15, R1, R2, R_SEP, A_SEP)
    zf_n = attenuation_coefficient(MU2[2], 0.15, R1, R2, R_FRI, A_FRI)
    p_num = interface_pressures(PRESSURES[2], zs_n, zf_n, 6)
    np.testing.assert_allclose(np.array(p_sym).ravel(), p_num, rtol=1e-14)
    assert float(t_sym) == pytest.approx(chen_torque(PRESSURES[2], MU2[2], 0.15), rel=1e-14)


@pytest.mark.parametrize("bad", [dict(zeta_first=1.0), dict(zeta_second=-0.1), dict(n_interfaces=0),
                                 dict(n_interfaces=2.5)])
def test_invalid_input(bad):
    kw = dict(p0=1e6, zeta_first=0.01, zeta_second=0.02, n_interfaces=4)
    kw.update(bad)
    with pytest.raises(ModelError):
        interface_pressures(**kw)
