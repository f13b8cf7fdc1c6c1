"""Tests of clutchocp.physics.squeeze_film (averaged Reynolds squeeze film of an annulus)."""

import casadi as ca
import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp

from clutchocp.errors import PhysicalRangeError
from clutchocp.physics.squeeze_film import (film_load, pressure_flow_factor, squeeze_geometry,
                                            squeeze_pressure)

# A wet-clutch-like film (Bao Table 1 magnitudes)
R1, R2 = 0.0725, 0.0975          # m
ETA = 0.03                       # Pa s
H = 40e-6                        # m
DH = -2e-4                       # m/s, squeezing
RHO = 870.0                      # kg/m^3
W1, W2 = 600.0, 250.0            # rad/s
P0 = 2.0e5                       # Pa
PERM, D_LINING = 1e-13, 0.5e-3   # m^2, m

CASES = {
    "plain": {},
    "rough": {"phi_r": 0.8},
    "inlet": {"inlet_pressure": P0},
    "centrifugal": {"rho": RHO, "w1": W1, "w2": W2},
    "permeable": {"permeability": PERM, "lining_thickness": D_LINING},
    "all": {"phi_r": 0.7, "permeability": PERM, "lining_thickness": D_LINING,
            "inlet_pressure": P0, "rho": RHO, "w1": W1, "w2": W2},
}


def geometry_reference(r1, r2):
    """G written out independently of the module."""
    return r2**4 - r1**4 - (r2**2 - r1**2) ** 2 / np.log(r2 / r1)


# ---------------------------------------------------------------- pressure profile

@pytest.mark.parametrize("name", CASES)
def test_pressure_boundary_values(name):
    kw = CASES[name]
    p = lambda r: squeeze_pressure(r, H, DH, ETA, R1, R2, **kw)
    scale = abs(p(0.5 * (R1 + R2)))
    assert scale > 1e3
    assert abs(p(R2)) <= 1e-12 * scale
    assert p(R1) == pytest.approx(kw.get("inlet_pressure", 0.0), abs=1e-12 * scale)


def test_squeezing_gives_positive_pressure_and_load():
    r = np.linspace(R1, R2, 51)[1:-1]
    assert np.all(squeeze_pressure(r, H, DH, ETA, R1, R2) > 0)
    assert film_load(H, DH, ETA, R1, R2) > 0
    # separating plates suck: negative load
    assert film_load(H, -DH, ETA, R1, R2) < 0
    # centrifugal pumping lowers the load (Liao subtracts F2)
    assert film_load(H, DH, ETA, R1, R2, rho=RHO, w1=W1, w2=W2) < film_load(H, DH, ETA, R1, R2)


def _laplacian_and_rhs(kw):
    """(1/r) d/dr(r D p') / 12 eta from AD of the closed form, and the seed PDE right-hand side."""
    r = ca.SX.sym("r")
    p = squeeze_pressure(r, H, DH, ETA, R1, R2, **kw)
    dp = ca.gradient(p, r)
    phi_r = kw.get("phi_r", 1.0)
    D = phi_r * (H**3 + 12 * kw.get("permeability", 0.0) * kw.get("lining_thickness", 0.0))
    lhs = ca.gradient(r * D / (12 * ETA) * dp, r) / r        # Zhang 2021 Eq. 1 left side / (12 eta r)
    # Bao 2020 Eq. 7 right side (with h uniform), divided by 12 as the left side. With a
    # permeable lining the module's documented assumption is that the lining oil is pumped like
    # the film oil, i.e. h^3 -> h^3 + 12 Phi_p d in the centrifugal term too.
    rho, w1, w2 = kw.get("rho", 0.0), kw.get("w1", 1.0), kw.get("w2", 0.0)
    bracket = 0.3 * (1 - w2 / w1) ** 2 + w2 / w1
    conductance = D / phi_r                                      # h^3 + 12 Phi_p d
    centrifugal = rho * w1**2 / r * bracket * ca.gradient(r**2 * conductance / ETA, r) / 12
    rhs = DH + centrifugal
    return ca.Function("f", [r], [lhs, rhs, p])


@pytest.mark.parametrize("name", CASES)
def test_pressure_solves_reynolds_equation(name):
    f = _laplacian_and_rhs(CASES[name])
    values = []
    for r in np.linspace(R1, R2, 7):
        lhs, rhs, _ = f(r)
        values.append(float(lhs))
        assert float(lhs) == pytest.approx(float(rhs), rel=1e-9)
    # (1/r)(r p')' is constant over the annulus
    assert np.ptp(values) <= 1e-9 * abs(np.mean(values))


def test_zhang_eq4_factor_two_erratum():
    """Zhang Eq. 4 printed with (b^2 - a^2)/(2 ln(a/b)) misses p(r1) = 0; without the 2 it is ours."""
    a, b = R1, R2
    coef = 3 * ETA * DH / H**3

    def zhang(r, factor):
        return coef * (r**2 + (b**2 - a**2) / (factor * np.log(a / b)) * np.log(r / b) - b**2)

    assert abs(zhang(a, 2.0)) > 0.1 * abs(zhang(0.5 * (a + b), 2.0))       # printed: wrong
    r = np.linspace(a, b, 9)
    np.testing.assert_allclose(zhang(r, 1.0), squeeze_pressure(r, H, DH, ETA, a, b),
                               rtol=1e-12, atol=1e-9)


# ---------------------------------------------------------------- load

@pytest.mark.parametrize("name", CASES)
def test_load_equals_quadrature_of_pressure(name):
    kw = CASES[name]
    integral, err = quad(lambda r: 2 * np.pi * r * squeeze_pressure(r, H, DH, ETA, R1, R2, **kw),
                         R1, R2, epsabs=0, epsrel=1e-13)
    W = film_load(H, DH, ETA, R1, R2, **kw)
    assert W == pytest.approx(integral, rel=1e-10)


def test_centrifugal_load_equals_quadrature_without_squeeze():
    kw = CASES["centrifugal"]
    integral, _ = quad(lambda r: 2 * np.pi * r * squeeze_pressure(r, H, 0.0, ETA, R1, R2, **kw),
                       R1, R2, epsabs=0, epsrel=1e-13)
    assert film_load(H, 0.0, ETA, R1, R2, **kw) == pytest.approx(integral, rel=1e-10)
    assert integral < 0


def test_constant_load_closed_form():
    """W = K eta (-h')/h^3 integrates to 1/h^2 = 1/h0^2 + 2 W t / (K eta)."""
    W, h0 = 500.0, 100e-6
    K = 1.5 * np.pi * geometry_reference(R1, R2)
    stiffness = lambda h: film_load(h, -1.0, ETA, R1, R2)      # W per unit squeeze speed (linear)

    sol = solve_ivp(lambda t, y: [-W / stiffness(y[0])], (0.0, 0.2), [h0],
                    method="LSODA", rtol=1e-11, atol=1e-16, dense_output=True)
    assert sol.success
    t = np.linspace(0.0, 0.2, 11)
    h_exact = (1 / h0**2 + 2 * W * t / (K * ETA)) ** -0.5
    np.testing.assert_allclose(sol.sol(t)[0], h_exact, rtol=1e-8)
    assert h_exact[-1] < 0.4 * h0                                # the film really thinned


def test_liao_eq5_F1_is_inlet_term():
    F1 = np.pi * P0 / (2 * np.log(R2 / R1)) * (R2**2 - R1**2 - 2 * R1**2 * np.log(R2 / R1))
    assert film_load(H, 0.0, ETA, R1, R2, inlet_pressure=P0) == pytest.approx(F1, rel=1e-13)
    assert F1 > 0


def test_liao_eq7_F3_lacks_one_half():
    F3 = 3 * np.pi * ETA * geometry_reference(R1, R2) / H**3 * DH   # Liao Eq. 7 as printed
    assert film_load(H, DH, ETA, R1, R2) == pytest.approx(-F3 / 2, rel=1e-13)


@pytest.mark.parametrize("w1, w2", [(600.0, 250.0), (300.0, 300.0), (500.0, 0.0), (100.0, -80.0)])
def test_liao_eq6_F2_versus_centrifugal_term(w1, w2):
    """Liao F2 and the Reynolds centrifugal load share the speed factor, not the radial factor.

    Bao Eq. 7 with h uniform gives (1/r)(r p')' = 4 E_c, E_c = rho K / (2 phi_r) with
    K = (3 w1^2 + 3 w2^2 + 4 w1 w2)/10; with p(r1) = p(r2) = 0 its load is
    -(pi/2) E_c G = -(pi/4) rho K G. Liao Eq. 6 (subtracted) is (pi/6) rho K (r2^4 - r1^4): the
    two differ by 2 (r2^4 - r1^4) / (3 G), which tends to 2/3 for r1 -> 0 and is 16.5 for
    r1/r2 = 0.7. They agree in sign and speed dependence only.
    """
    dw = w1 - w2
    K = (3 * w1**2 + 3 * w2**2 + 4 * w1 * w2) / 10
    assert w1**2 - w1 * dw + 0.3 * dw**2 == pytest.approx(K, rel=1e-13)   # Liao's speed factor

    def centrifugal(r1, r2):
        return film_load(H, 0.0, ETA, r1, r2, rho=RHO, w1=w1, w2=w2)

    def F2(r1, r2):
        return RHO * np.pi / 6 * (r2**4 - r1**4) * (w1**2 - w1 * dw + 0.3 * dw**2)

    assert centrifugal(R1, R2) == pytest.approx(-np.pi / 4 * RHO * K * geometry_reference(R1, R2),
                                                rel=1e-12)
    ratio = F2(0.7, 1.0) / -centrifugal(0.7, 1.0)
    assert ratio == pytest.approx(2 * (1 - 0.7**4) / (3 * geometry_reference(0.7, 1.0)), rel=1e-12)
    assert ratio == pytest.approx(16.52, abs=0.01)
    # the disc limit is reached only logarithmically: G = r2^4 (1 - 1/ln(r2/r1)) + O(r1^2)
    assert F2(1e-200, 1.0) / -centrifugal(1e-200, 1.0) == pytest.approx(2 / 3 / (1 - 1 / np.log(1e200)),
                                                                       rel=1e-12)


# ---------------------------------------------------------------- geometry

def test_geometry_limits():
    # r1 -> 0: the hole (p = 0 at r1) matters only logarithmically, G -> r2^4 (1 - 1/ln(r2/r1))
    for r1 in (1e-6, 1e-50, 1e-200):
        assert squeeze_geometry(r1, 0.1) == pytest.approx(0.1**4 * (1 - 1 / np.log(0.1 / r1)), rel=1e-9)
    # narrow annulus: plane strip of length 2 pi r and width b, W = eta (-h') 2 pi r b^3 / h^3
    r, b = 0.1, 1e-3
    G = squeeze_geometry(r - b / 2, r + b / 2)
    assert G == pytest.approx(4 / 3 * r * b**3, rel=1e-4)
    assert squeeze_geometry(R1, R2) == pytest.approx(geometry_reference(R1, R2), rel=1e-15)


@pytest.mark.parametrize("r1, r2", [(0.1, 0.1), (0.1, 0.05), (-0.01, 0.1), (0.0, 0.1)])
def test_bad_radii_raise(r1, r2):
    with pytest.raises(PhysicalRangeError, match="r1"):
        squeeze_geometry(r1, r2)
    with pytest.raises(PhysicalRangeError):
        film_load(H, DH, ETA, r1, r2)


# ---------------------------------------------------------------- pressure flow factor

def test_flow_factor_equals_patir_cheng_fit_above_half():
    Hs = np.linspace(0.5, 30, 301)
    np.testing.assert_allclose(pressure_flow_factor(Hs), 1 - 0.90 * np.exp(-0.56 * Hs), rtol=1e-14)
    assert pressure_flow_factor(1e3) == pytest.approx(1.0, rel=1e-14)


def test_flow_factor_extension_positive_monotone_c2():
    Hs = np.linspace(-8, 0.5, 2001)
    phi = pressure_flow_factor(Hs)
    assert np.all(phi > 0) and np.all(np.diff(phi) > 0)
    assert pressure_flow_factor(-30.0) < 1e-100
    assert pressure_flow_factor(0.0) == pytest.approx(0.1358, abs=1e-4)
    # value, slope and curvature continuous at H = 0.5 (AD from both sides)
    x = ca.SX.sym("x")
    phi_x = pressure_flow_factor(x)
    d1 = ca.gradient(phi_x, x)
    d2 = ca.gradient(d1, x)
    f = ca.Function("f", [x], [phi_x, d1, d2])
    left, right = f(0.5 - 1e-9), f(0.5 + 1e-9)
    for a, b in zip(left, right):
        assert float(a) == pytest.approx(float(b), rel=1e-7)
    assert float(right[1]) == pytest.approx(0.90 * 0.56 * np.exp(-0.28), rel=1e-7)
    assert float(right[2]) == pytest.approx(-0.90 * 0.56**2 * np.exp(-0.28), rel=1e-7)


def test_flow_factor_smooth_within_tolerance():
    Hs = np.linspace(-6, 30, 36001)
    exact, smooth = pressure_flow_factor(Hs), pressure_flow_factor(Hs, smooth=True)
    rel = np.abs(smooth - exact) / exact
    assert rel.max() < 3e-3
    assert rel[np.abs(Hs - 0.5) >= 0.5].max() < 3e-6
    assert np.all(smooth > 0)


# ---------------------------------------------------------------- symbolic == numeric

@pytest.mark.parametrize("smooth", [False, True])
def test_flow_factor_symbolic_equals_numeric(smooth):
    x = ca.SX.sym("x")
    f = ca.Function("f", [x], [pressure_flow_factor(x, smooth=smooth)])
    for Hv in (-3.0, 0.0, 0.3, 0.5, 0.9, 4.0, 50.0):
        assert float(f(Hv)) == pytest.approx(float(pressure_flow_factor(Hv, smooth=smooth)), rel=1e-14)


@pytest.mark.parametrize("name", CASES)
def test_pressure_and_load_symbolic_equal_numeric(name):
    kw = CASES[name]
    names = ["r", "h", "dh", "eta", "r1", "r2"] + list(kw)
    syms = [ca.SX.sym(n) for n in names]
    skw = dict(zip(kw, syms[6:]))
    p = squeeze_pressure(*syms[:6], **skw)
    W = film_load(*syms[1:6], **skw)
    G = squeeze_geometry(syms[4], syms[5])
    f = ca.Function("f", syms, [p, W, G])
    values = [0.085, H, DH, ETA, R1, R2] + list(kw.values())
    p_s, W_s, G_s = f(*values)
    assert float(p_s) == pytest.approx(squeeze_pressure(*values[:6], **kw), rel=1e-12)
    assert float(W_s) == pytest.approx(film_load(*values[1:6], **kw), rel=1e-12)
    assert float(G_s) == pytest.approx(squeeze_geometry(R1, R2), rel=1e-12)


def test_arrays_broadcast():
    r = np.linspace(R1, R2, 5)
    hs = np.array([20e-6, 40e-6, 80e-6])
    assert squeeze_pressure(r, H, DH, ETA, R1, R2).shape == (5,)
    W = film_load(hs, DH, ETA, R1, R2)
    np.testing.assert_allclose(W * hs**3, W[0] * hs[0] ** 3, rtol=1e-13)     # W ~ 1/h^3
