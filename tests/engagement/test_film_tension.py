"""Film tension limit in the engagement model: closed-form separation of two discs, the energy balance of
a cavitating pack, and the reported film pressures.

Two discs (Zhang's annulus, one film, no contact, no lining permeability, phi_r = 1) are pulled apart by
a constant force F < 0 on the pack face (a negative pressure command). The film load is
W = g(K (-dh/dt)), K = K_g eta / h^3, K_g = (3 pi / 2) G (squeeze_film.film_load), g the tension limit
with L = p_cav A (physics/cavitation.py).

* Massless pack: the force balance F = g(K c) gives the closing speed c = x / K with x = g^-1(F) a
  constant, so d(1/h^2)/dt = 2 x / (K_g eta): 1/h^2 = 1/h0^2 + 2 x t / (K_g eta). Above the limit
  (|F| < |L|) x = F to the limit's offset (2.5e-3 |L|) and this is the uncavitated squeeze law
  1/h^2 = 1/h0^2 - 2 |F| t / (K_g eta);
  beyond it x = L + (F - L) / eps: a cavitated film opens 1 / eps times faster than the excess alone
  would squeeze it.
* A disc of mass m: m dc/dt = F - g(K c); once cavitated (K c well below L) the film holds L and the disc
  accelerates at (F - L) / m = -(|F| - |p_cav| A) / m (to eps), less the residual resistance eps K |c|.
"""

import math

import casadi as ca
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from clutchocp.engagement.measures import energy_balance
from clutchocp.engagement.model import EngagementModel
from clutchocp.physics.cavitation import RESIDUAL_SLOPE, WIDTH, tension_limited_load_inverse
from clutchocp.physics.squeeze_film import squeeze_geometry
from clutchocp.scene import load_scene
from clutchocp.simulation import SimulationOptions, simulate

P_CAV = -1e5                     # Pa, the default
DISCS = {"contact.model": "none", "contact.E_equiv": None, "film.flow_factor": "none", "plates.lining_permeability": "0 m^2",
         "film.cavitation_pressure": P_CAV, "simulation.rtol": 1e-10, "simulation.atol": 1e-10}


def _discs(**overrides):
    """Two discs of zhang2021 with a pressure command input."""
    scene = load_scene("zhang2021").with_overrides({**DISCS, **overrides})
    return EngagementModel(scene, pressure_command=ca.SX.sym("pressure_command"))


def _pull(pressure, t_end, points=201, model=None, **overrides):
    """Run two discs under a constant (negative) face pressure [Pa]."""
    model = model or _discs(**overrides)
    x0 = dict(zip(model.state_names, model.initial_state))
    grid = np.linspace(0.0, t_end, points)
    options = SimulationOptions(rtol=1e-10, atol=1e-10)
    result = simulate(model.hybrid, x0, grid, mode=model.initial_mode(), u={"pressure_command": pressure},
                      options=options)
    return model, result


def _squeeze_constant(model):
    """K_g eta [N s m^2]: K = K_g eta / h^3 for phi_r = 1, no lining flow, H >> 1."""
    film = model.film
    return 1.5 * math.pi * squeeze_geometry(film.r1, film.r2) * film.eta


@pytest.mark.parametrize("fraction", [0.5, 2.0])
def test_massless_discs_separate_by_the_closed_form(fraction):
    """|F| = 0.5 |L|: the uncavitated squeeze law; |F| = 2 |L|: the cavitated film's opening law."""
    pressure = fraction * P_CAV
    model = _discs()
    film = model.film
    F, L = pressure * film.area, P_CAV * film.area
    x = float(tension_limited_load_inverse(F, L, WIDTH * abs(L)))
    h0 = model.H0
    c = _squeeze_constant(model)
    t_inf = c / (2 * abs(x) * h0**2)                       # the film would open without bound at t_inf
    model, result = _pull(pressure, 0.5 * t_inf, model=model)
    h = result["h_1_m"]
    expected = (1 / h0**2 + 2 * x * result.t / c) ** -0.5
    np.testing.assert_allclose(h, expected, rtol=1e-7)
    if fraction < 1:     # uncavitated: the film's own law, to the limit's offset (1 - eps) w^2 / (4 |L|)
        assert abs(x - F) <= 1.01 * (1 - RESIDUAL_SLOPE) * WIDTH**2 * abs(L) / 4
    else:
        assert x == pytest.approx(L + (F - L) / RESIDUAL_SLOPE, rel=1e-3)   # cavitated: 1/eps faster
    # a massless pack's film carries the whole pull (its force balance), beyond the limit by the residual
    # resistance of a film that opens 1 / eps times faster
    p_mean = result["film_1_mean_pressure_Pa"][1:]
    assert np.all(np.abs(p_mean - pressure) < 1e-9 * abs(pressure))
    assert energy_balance(model, result)["rel_error"] < 1e-6


def test_disc_with_mass_accelerates_at_the_excess_over_the_suction_limit():
    """A disc of 0.5 kg pulled by |F| = 2 |p_cav| A: once cavitated (K c well below L) the film carries
    L + eps (K c - L), so m dc/dt = F - L - eps (K c - L): from rest the disc accelerates at
    (F - (1 - eps) L) / m = -(|F| - (1 - eps) |p_cav| A) / m, less the residual resistance eps K |c|
    (K = K_g eta / h^3 along the run). IDAS follows that reduced law to 2e-3 over 5-15 us."""
    m = 0.5
    pressure = 2 * P_CAV
    model, result = _pull(pressure, 15e-6, points=301, **{"pack.model": "masses", "pack.plate_masses": [m]})
    film = model.film
    F, L = pressure * film.area, P_CAV * film.area
    t, c, h = result.t, result["film_1_closing_speed_m_s"], result["h_1_m"]
    K_g_eta = _squeeze_constant(model)
    window = t >= 5e-6

    def reduced(tk, ck):
        K = K_g_eta / np.interp(tk, t, h) ** 3
        return [(F - L - RESIDUAL_SLOPE * (K * ck[0] - L)) / m]

    sol = solve_ivp(reduced, (t[window][0], t[-1]), [c[window][0]], t_eval=t[window], rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(c[window], sol.y[0], rtol=2e-3)
    a0 = (F - (1 - RESIDUAL_SLOPE) * L) / m                    # from rest: the excess over the suction limit
    assert a0 == pytest.approx((F - L) / m, rel=2 * RESIDUAL_SLOPE)
    # the film is cavitated over the window: its mean pressure is the limit plus the residual resistance,
    # (L + eps (K c - L)) / A (1.035 -> 1.115 x p_cav as the disc speeds up)
    p_mean = result["film_1_mean_pressure_Pa"][window]
    K_run = K_g_eta / h[window] ** 3
    np.testing.assert_allclose(p_mean, (L + RESIDUAL_SLOPE * (K_run * c[window] - L)) / film.area, rtol=2e-3)
    # the linear film would hold the whole pull and let the disc open at |F| / K at most
    K = K_g_eta / model.H0**3
    assert abs(c[-1]) > 5 * abs(F) / K
    assert energy_balance(model, result)["rel_error"] < 1e-6


def test_cavitation_pressure_sets_the_limit():
    """Half the cavitation pressure, half the suction: the same pull is 4 times the limit and opens the
    massless discs by the cavitated law of the new limit."""
    model = _discs(**{"film.cavitation_pressure": 0.5 * P_CAV})
    film = model.film
    assert film.cavitation_pressure == 0.5 * P_CAV
    F, L = 2 * P_CAV * film.area, 0.5 * P_CAV * film.area
    x = float(tension_limited_load_inverse(F, L, WIDTH * abs(L)))
    assert x == pytest.approx(L + (F - L) / RESIDUAL_SLOPE, rel=1e-3)
    c = _squeeze_constant(model)
    _, result = _pull(2 * P_CAV, 0.25 * c / (abs(x) * model.H0**2), points=51, model=model)
    expected = (1 / model.H0**2 + 2 * x * result.t / c) ** -0.5
    np.testing.assert_allclose(result["h_1_m"], expected, rtol=1e-7)


@pytest.mark.parametrize("sharing", ["reduced", "additive"])
def test_limit_acts_on_the_area_the_oil_acts_on(sharing):
    """L = p_cav x wetted area: (1 - A_c/A_n) A_n with the reduced load sharing, A_n with the additive."""
    scene = load_scene("default_driveline").with_overrides({"film.load_sharing": sharing})
    film = EngagementModel(scene).film
    for H in (0.2, 1.0, 3.0):
        h = H * film.sigma
        load = film.film_load(h, 300.0, 150.0)
        share = 1 - float(film.area_ratio(h)) if sharing == "reduced" else 1.0
        assert float(load.limit) == pytest.approx(-1e5 * share * film.area, rel=1e-14)
        assert float(load.wet_area) == pytest.approx(share * film.area, rel=1e-14)
        assert float(load.mean_pressure(load.limit)) == pytest.approx(-1e5, rel=1e-14)


def test_area_ratio_cap_is_smooth_below_099():
    """The real-area ratio (default_driveline: Greenwood-Tripp with n beta sigma = 0.47 passes 1 near
    H = 0.05) is capped by a smooth minimum at 0.99: equal to the raw ratio far below the cap, below 0.99
    everywhere (reaching it in doubles as H -> -inf), growing as the film closes, and C2 (its first two derivatives continuous where the
    raw ratio crosses the cap)."""
    from clutchocp.physics.contact import greenwood_tripp_area_ratio
    film = EngagementModel(load_scene("default_driveline")).film
    h = ca.SX.sym("h")
    ratio = film.area_ratio(h)
    raw_sx = greenwood_tripp_area_ratio(h / film.sigma, film.n_a, film.beta, film.sigma)     # same erf path
    f = ca.Function("f", [h], [ratio, ca.jacobian(ratio, h), ca.hessian(ratio, h)[0], raw_sx])
    H = np.linspace(-1.0, 4.0, 5001)
    values = np.array([[float(v) for v in f(Hk * film.sigma)] for Hk in H])
    raw = values[:, 3]
    assert np.all(values[:, 0] <= 0.99)
    below = raw < 0.6
    np.testing.assert_allclose(values[below, 0], raw[below], rtol=1e-12, atol=1e-16)
    assert np.all(np.diff(values[:, 0]) <= 0)                    # grows as the film closes
    # C2: the first and second derivatives from either side of the crossing agree (a min() jumps there)
    crossing = H[np.argmin(np.abs(raw - 0.99))]
    assert 0.0 < crossing < 0.15                                   # the raw ratio reaches 0.99 there
    left, right = (np.array([float(v) for v in f((crossing + dH) * film.sigma)]) for dH in (-1e-7, 1e-7))
    assert left[1] == pytest.approx(right[1], rel=1e-4)
    assert left[2] == pytest.approx(right[2], rel=1e-3)
    assert abs(left[1]) > 0.1 * abs(float(f(0.5 * film.sigma)[1]))    # still far from flat there
