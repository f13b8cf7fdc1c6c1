"""Tests of clutchocp.physics.contact: Greenwood-Tripp, Zhang's GW variant, plasticity, radius."""

import math

import casadi as ca
import numpy as np
import pytest
from scipy import integrate, special

from clutchocp.errors import UnknownVariantError
from clutchocp.physics import contact as ct
from clutchocp.physics.roughness import F52, combined_sigma

# Bao 2020 Table 1 (n_a is the "rough peak density", 1/m^2) and text below Eq. 17
BAO = dict(n_a=7e7, beta=9e-4, sigma=8.4e-6, E=3e9, hardness=280e6, r1=0.12, r2=0.16)
# Cui 2019 Table 2
CUI = dict(n_a=8.49e7, beta=8e-4, sigma=combined_sigma(5.975e-6, 2.85e-6), r1=0.043, r2=0.0615)


def sx_eval(fun, *values):
    syms = [ca.SX.sym(f"x{i}") for i in range(len(values))]
    return float(ca.Function("f", syms, [fun(*syms)])(*values))


def test_greenwood_tripp_coefficient_value_and_scaling():
    k = ct.greenwood_tripp_coefficient(BAO["n_a"], BAO["beta"], BAO["sigma"])
    assert k == pytest.approx(0.128219, rel=1e-5)   # hand value for Bao Table 1
    # K' ~ n_a^2 beta^{3/2} sigma^{5/2}
    assert ct.greenwood_tripp_coefficient(2e7, 1e-3, 1e-6) / ct.greenwood_tripp_coefficient(1e7, 1e-3, 1e-6) \
        == pytest.approx(4.0, rel=1e-14)
    assert ct.greenwood_tripp_coefficient(1e7, 4e-3, 1e-6) / ct.greenwood_tripp_coefficient(1e7, 1e-3, 1e-6) \
        == pytest.approx(8.0, rel=1e-14)
    assert ct.greenwood_tripp_coefficient(1e7, 1e-3, 4e-6) / ct.greenwood_tripp_coefficient(1e7, 1e-3, 1e-6) \
        == pytest.approx(32.0, rel=1e-14)


def test_area_ratio_equals_cui_eq3_written_out():
    n, R, s = CUI["n_a"], CUI["beta"], CUI["sigma"]
    for lam in np.linspace(-1, 4, 11):
        cui_eq3 = math.pi**2 * (n * R * s) ** 2 / 2 * (
            (1 + lam**2) * special.erfc(lam / math.sqrt(2))
            - math.sqrt(2 / math.pi) * lam * math.exp(-lam**2 / 2))
        assert ct.greenwood_tripp_area_ratio(lam, n, R, s) == pytest.approx(cui_eq3, rel=1e-12)


def test_area_ratio_equals_bao_eq18_written_out_with_n0():
    n, b, s, n0 = BAO["n_a"], BAO["beta"], BAO["sigma"], 1.5
    for H in (0.0, 0.5, 1.5, 2.5):
        bao_eq18 = n0 * math.pi**2 * (n * b * s) ** 2 * (
            -H / math.sqrt(2 * math.pi) * math.exp(-H**2 / 2)
            - 0.5 * (H**2 + 1) * (math.erf(H / math.sqrt(2)) - 1))
        assert ct.greenwood_tripp_area_ratio(H, n, b, s, n0=n0) == pytest.approx(bao_eq18, rel=1e-12)


def test_pressure_fits():
    args = (BAO["E"], BAO["n_a"], BAO["beta"], BAO["sigma"])
    k_e = ct.greenwood_tripp_coefficient(BAO["n_a"], BAO["beta"], BAO["sigma"]) * BAO["E"]
    for H in (0.0, 1.0, 2.5):
        assert ct.greenwood_tripp_pressure(H, *args) == pytest.approx(k_e * F52(H), rel=1e-14)
        bao_eq19 = 4.4086e-5 * k_e * (4 - H) ** 6.804   # Bao Eq. 19 literally
        assert ct.greenwood_tripp_pressure(H, *args, fit="patir") == pytest.approx(bao_eq19, rel=1e-14)
    assert ct.greenwood_tripp_pressure(4.2, *args, fit="patir") == 0.0
    # the fit under-predicts: exact/fit = 0.61663/0.550 at H = 0
    ratio = ct.greenwood_tripp_pressure(0.0, *args) / ct.greenwood_tripp_pressure(0.0, *args, fit="patir")
    assert ratio == pytest.approx(0.61663 / 0.550, rel=1e-3)
    with pytest.raises(UnknownVariantError, match="exact, patir"):
        ct.greenwood_tripp_pressure(1.0, *args, fit="bao")


def test_patir_pressure_smooth_within_1e8_of_exact_below_H3():
    args = (BAO["E"], BAO["n_a"], BAO["beta"], BAO["sigma"])
    H = np.linspace(-1, 3, 41)
    np.testing.assert_allclose(ct.greenwood_tripp_pressure(H, *args, fit="patir", smooth=True),
                               ct.greenwood_tripp_pressure(H, *args, fit="patir"), rtol=1e-8)


def test_zhang_area_ratio_is_greenwood_williamson_integral():
    # GW: A_c/A_n = pi n_a beta int_h^inf (z - h) phi_sigma(z) dz (z: asperity height)
    n, b, s = 6e7, 1e-4, 1.2e-6   # n_a beta sigma = 0.0072: small, as GW assumes
    for H in (-0.5, 0.0, 1.0, 2.0, 3.0):
        h = H * s
        integral, _ = integrate.quad(lambda u: s * (u - H) * math.exp(-u * u / 2) / math.sqrt(2 * math.pi),
                                     H, np.inf, epsabs=0.0, epsrel=1e-12)
        assert ct.zhang_area_ratio(H, n, b, s) == pytest.approx(math.pi * n * b * integral, rel=1e-9)
        # Zhang Eq. 5 with the exponent corrected to -H^2/2 and g(h) = Phi(H)
        eq5 = math.pi * n * b * s * (math.exp(-H**2 / 2) / math.sqrt(2 * math.pi)
                                     + h / s * (0.5 * (1 + math.erf(H / math.sqrt(2))) - 1))
        assert ct.zhang_area_ratio(H, n, b, s) == pytest.approx(eq5, rel=1e-12)


def test_zhang_contact_pressure_is_modulus_times_area_ratio():
    n, b, s, E = 6e7, 1e-4, 1.2e-6, 2.5e8
    for H in (0.0, 1.3):
        assert ct.zhang_contact_pressure(H, E, n, b, s) == pytest.approx(E * ct.zhang_area_ratio(H, n, b, s),
                                                                          rel=1e-15)


def test_plasticity_index_of_bao_table1_is_1_04():
    omega = ct.plasticity_index(BAO["E"], BAO["hardness"], BAO["sigma"], BAO["beta"])
    assert round(omega, 2) == 1.04   # Bao text below Eq. 17


def test_effective_radius_rules():
    r1, r2 = BAO["r1"], BAO["r2"]
    # uniform pressure: r_eff = int r * r dr / int r dr over the annulus
    moment, _ = integrate.quad(lambda r: r * r, r1, r2)
    force, _ = integrate.quad(lambda r: r, r1, r2)
    assert ct.effective_radius(r1, r2) == pytest.approx(moment / force, rel=1e-13)
    assert ct.effective_radius(r1, r2, rule="cui") == pytest.approx(0.14, rel=1e-15)
    # thin ring: both -> r
    assert ct.effective_radius(0.1, 0.1 + 1e-7) == pytest.approx(0.1, rel=1e-6)
    with pytest.raises(UnknownVariantError, match="bao, cui"):
        ct.effective_radius(r1, r2, rule="mean")


@pytest.mark.parametrize("fun, values", [
    (ct.greenwood_tripp_coefficient, (7e7, 9e-4, 8.4e-6)),
    (ct.greenwood_tripp_area_ratio, (1.3, 7e7, 9e-4, 8.4e-6)),
    (lambda H, n, b, s: ct.greenwood_tripp_area_ratio(H, n, b, s, n0=1.7), (0.4, 7e7, 9e-4, 8.4e-6)),
    (ct.greenwood_tripp_pressure, (1.3, 3e9, 7e7, 9e-4, 8.4e-6)),
    (ct.greenwood_tripp_pressure, (-7.0, 3e9, 7e7, 9e-4, 8.4e-6)),
    (lambda *a: ct.greenwood_tripp_pressure(*a, fit="patir"), (1.3, 3e9, 7e7, 9e-4, 8.4e-6)),
    (lambda *a: ct.greenwood_tripp_pressure(*a, fit="patir", smooth=True), (1.3, 3e9, 7e7, 9e-4, 8.4e-6)),
    (ct.zhang_area_ratio, (0.8, 6e7, 1e-4, 1.2e-6)),
    (ct.zhang_contact_pressure, (0.8, 2.5e8, 6e7, 1e-4, 1.2e-6)),
    (ct.plasticity_index, (3e9, 280e6, 8.4e-6, 9e-4)),
    (ct.effective_radius, (0.12, 0.16)),
    (lambda r1, r2: ct.effective_radius(r1, r2, rule="cui"), (0.12, 0.16)),
])
def test_symbolic_equals_numeric(fun, values):
    assert sx_eval(fun, *values) == pytest.approx(fun(*values), rel=1e-12)
