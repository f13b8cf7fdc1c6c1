"""Tests of clutchocp.physics.friction: constant, Stribeck, Chen 2021 Eq. 5, Cui 2019 Eq. 18."""

import math

import casadi as ca
import numpy as np
import pytest

from clutchocp.errors import PhysicalRangeError
from clutchocp.physics import friction as fr


def sx_eval(fun, *values):
    syms = [ca.SX.sym(f"x{i}") for i in range(len(values))]
    return float(ca.Function("f", syms, [fun(*syms)])(*values))


def test_mu_constant():
    assert fr.mu_constant(0.12) == 0.12
    out = fr.mu_constant(0.12, np.array([0.0, -3.0, 5.0]))
    np.testing.assert_array_equal(out, [0.12, 0.12, 0.12])


STRIBECK = dict(mu_static=0.14, mu_kinetic=0.09, v_stribeck=0.5)


def test_stribeck_limits_and_shape():
    assert fr.mu_stribeck(0.0, **STRIBECK) == pytest.approx(0.14, rel=1e-15)
    assert fr.mu_stribeck(50.0, **STRIBECK) == pytest.approx(0.09, rel=1e-15)
    assert fr.mu_stribeck(0.5, **STRIBECK) == pytest.approx(0.09 + 0.05 * math.exp(-1), rel=1e-15)
    assert fr.mu_stribeck(-0.3, **STRIBECK) == fr.mu_stribeck(0.3, **STRIBECK)   # even in v
    v = np.linspace(0, 5, 200)
    assert np.all(np.diff(fr.mu_stribeck(v, **STRIBECK)) <= 0)
    # viscous rise: mu -> mu_k + c |v| at large slip
    assert fr.mu_stribeck(-20.0, **STRIBECK, viscous=0.002) == pytest.approx(0.09 + 0.04, rel=1e-14)
    assert fr.mu_stribeck(1.0, **STRIBECK, exponent=1.0) == pytest.approx(0.09 + 0.05 * math.exp(-2), rel=1e-15)


def test_stribeck_smooth_form_close_to_exact_and_smooth_at_zero():
    kw = dict(STRIBECK, exponent=1.0, viscous=0.002)
    v = np.concatenate([-np.logspace(-1, 1.3, 40), np.logspace(-1, 1.3, 40)])   # |v| >= 0.1 = v_s / 5
    # |v| is replaced by sqrt(v^2 + eps^2), eps = 5e-4 m/s: speed error <= eps^2/(2|v|) = 1.25e-6 m/s
    np.testing.assert_allclose(fr.mu_stribeck(v, **kw, smooth=True), fr.mu_stribeck(v, **kw), atol=1e-6)
    # smooth form: even, zero slope and finite curvature at v = 0 (exact |v|^1 has a corner there)
    x = ca.SX.sym("v")
    y = fr.mu_stribeck(x, **kw, smooth=True)
    grad, hess = ca.Function("d", [x], [ca.gradient(y, x), ca.hessian(y, x)[0]])(0.0)
    assert float(grad) == 0.0
    assert math.isfinite(float(hess)) and float(hess) < 0


def chen_eq5_literal(v, p_mpa, theta):
    """Chen 2021 Eq. 5 as printed (p in MPa, 'ln ⊖' = ln Theta)."""
    return (23 * math.exp(-2.6 * v / ((math.log(theta) - 3.2) * ((28.3 * p_mpa) ** 0.4 - 0.87)) - 5.16)
            + 0.08 * (math.exp(-0.005 * theta) - 1) * (math.exp(-0.2 * v) - 1)
            + 0.01 * math.log(4 * v + 1) / math.exp(0.005 * theta)
            - 0.005 * math.log(28.3 * p_mpa) + 0.035)


def test_chen_eq5_units_and_literal_form():
    for v, p, theta in ((18.2, 0.2, 100.0), (3.0, 1.1, 60.0), (0.0, 0.5, 40.0)):
        assert fr.mu_chen2021(v, p * 1e6, theta) == pytest.approx(chen_eq5_literal(v, p, theta), rel=1e-14)


def test_chen_eq5_at_chen_table1_conditions():
    # Chen Table 1: v = 18.2 m/s, Theta = 100 degC; Fig. 5: mu decreases over 0.2 ... 2 MPa
    p = np.linspace(0.2e6, 2e6, 37)
    mu = fr.mu_chen2021(18.2, p, 100.0)
    assert np.all(np.diff(mu) < 0)
    assert 0.083 < mu[0] < 0.084 and 0.071 < mu[-1] < 0.072   # 0.0831 and 0.0716
    # Chen Table 2 two-pair bench mu* (engagements from 2686 rpm): Eq. 5 is 7-12 % above them
    bench = {0.2: 0.07444, 0.4: 0.07271, 0.6: 0.07143, 0.8: 0.07091, 1.6: 0.06696}
    for p_mpa, mu_star in bench.items():
        assert 1.0 < fr.mu_chen2021(18.2, p_mpa * 1e6, 100.0) / mu_star < 1.15


def test_chen_eq5_static_end_and_domain():
    # v = 0: 23 e^-5.16 + 0.035 - 0.005 ln(28.3 p) (the stick term dominates)
    p = 1.0
    assert fr.mu_chen2021(0.0, p * 1e6, 100.0) == pytest.approx(
        23 * math.exp(-5.16) + 0.035 - 0.005 * math.log(28.3 * p), rel=1e-14)
    assert fr.mu_chen2021(-5.0, 1e6, 100.0) == fr.mu_chen2021(5.0, 1e6, 100.0)
    with pytest.raises(PhysicalRangeError, match="pressure"):
        fr.mu_chen2021(1.0, 2e4, 100.0)
    with pytest.raises(PhysicalRangeError, match="temperature"):
        fr.mu_chen2021(1.0, 1e6, 20.0)


def test_chen_smooth_form_close_to_exact():
    v = np.linspace(0.05, 20, 50)
    np.testing.assert_allclose(fr.mu_chen2021(v, 0.8e6, 100.0, smooth=True),
                               fr.mu_chen2021(v, 0.8e6, 100.0), atol=1e-5)


CUI_TABLE1 = {0.1: 0.06, 0.2: 0.05, 0.3: 0.044, 0.4: 0.039, 0.5: 0.036,
              0.6: 0.034, 0.7: 0.033, 0.8: 0.0315, 0.9: 0.03, 1.0: 0.029}


def test_cui_eq18_against_cui_table1():
    # Max deviation found: 7.4e-4 at 0.3 MPa.  Table 1 is given to 0.001 (0.0005 at 0.8 MPa),
    # and even the least-squares quartic through it misses by 4.1e-4, so 1e-3 is the data's
    # own resolution.
    dev = [abs(fr.mu_cui2019(p * 1e6) - f) for p, f in CUI_TABLE1.items()]
    assert max(dev) < 1e-3
    assert max(dev) > 5e-4   # (the tolerance is not slack: the worst point uses 74 % of it)
    p = np.linspace(0.1e6, 1e6, 91)
    assert np.all(np.diff(fr.mu_cui2019(p)) < 0)   # Cui: decreases with pressure


@pytest.mark.parametrize("fun, values", [
    (lambda v: fr.mu_constant(0.1, v), (2.0,)),
    (lambda v: fr.mu_stribeck(v, 0.14, 0.09, 0.5), (0.3,)),
    (lambda v: fr.mu_stribeck(v, 0.14, 0.09, 0.5, exponent=1.3, viscous=0.01), (-0.7,)),
    (lambda v: fr.mu_stribeck(v, 0.14, 0.09, 0.5, exponent=1.0, smooth=True), (0.02,)),
    (fr.mu_chen2021, (7.5, 0.9e6, 80.0)),
    (lambda v, p, t: fr.mu_chen2021(v, p, t, smooth=True), (-2.0, 0.3e6, 120.0)),
    (fr.mu_cui2019, (0.45e6,)),
])
def test_symbolic_equals_numeric(fun, values):
    assert sx_eval(fun, *values) == pytest.approx(fun(*values), rel=1e-13)
