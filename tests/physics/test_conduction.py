"""Conduction through the friction lining (physics/thermal.py) against closed forms and a second method."""

import math

import casadi as ca
import numpy as np
import pytest

from clutchocp.physics import thermal

PAPER = (0.2, 1000.0, 1500.0)            # k [W/(m K)], rho [kg/m^3], c [J/(kg K)]
AREA = 1e-2                              # m^2
ENGAGEMENT_TIMES = np.array([0.05, 0.1, 0.2, 0.3, 0.5])     # s: the slip of an engagement
SHORT_TIMES = np.array([0.01, 0.02])


def lining_alone(thickness, cells, q=1e5):
    """A lining under a flux q [W/m^2] on its surface, its back insulated, no separator, no convection."""
    chain = thermal.lining_chain(thickness, cells, *PAPER, AREA, surface_capacity=0.0, back_capacity=0.0,
                                 surface_loss=0.0, back_loss=0.0)
    return chain, q * AREA


def surface_error(cells, times, thickness=1e-3, q=1e5):
    """Relative error of the chain's surface temperature rise against the semi-infinite closed form."""
    chain, Q = lining_alone(thickness, cells, q)
    rise = np.array([chain.relax(np.zeros(chain.size), t, 0.0, heat=Q)[0] for t in times])
    exact = thermal.semi_infinite_surface_rise(q, times, *PAPER)
    return rise / exact - 1


def test_semi_infinite_closed_form_values():
    """2 q sqrt(t / (pi k rho c)): 1e5 W/m^2 for 0.3 s into paper (e = 547.7 W s^0.5/(m^2 K)) gives 112.84 K."""
    assert thermal.effusivity(*PAPER) == pytest.approx(math.sqrt(3e5))
    assert thermal.semi_infinite_surface_rise(1e5, 0.3, *PAPER) == pytest.approx(2e5 * math.sqrt(0.3 / math.pi)
                                                                                   / math.sqrt(3e5))
    assert thermal.semi_infinite_surface_rise(1e5, 0.3, *PAPER) == pytest.approx(112.84, abs=0.005)


def test_cells_grow_from_the_surface_and_fill_the_lining():
    dx = thermal.lining_cells(1e-3, 6)
    assert dx.sum() == pytest.approx(1e-3, rel=1e-15)
    np.testing.assert_allclose(dx[1:] / dx[:-1], thermal.GRID_RATIO)
    assert dx[0] == pytest.approx(1e-3 * 0.5 / (1.5**6 - 1))      # geometric series: 48.1 um


def test_a_thick_lining_approaches_the_semi_infinite_surface_temperature():
    """The default 6 cells across a 1 mm paper lining: within 5 % of the semi-infinite surface temperature
    over an engagement (0.05-0.5 s; measured -4.5 % at 0.05 s, -1.8 % at 0.5 s), 8 cells from 0.01 s
    (measured -4.3 % at 0.01 s); the error falls as the cells get finer."""
    six = surface_error(6, ENGAGEMENT_TIMES)
    assert np.all(np.abs(six) < 0.05), six
    eight = surface_error(8, np.concatenate([SHORT_TIMES, ENGAGEMENT_TIMES]))
    assert np.all(np.abs(eight) < 0.05), eight
    errors = [np.max(np.abs(surface_error(n, ENGAGEMENT_TIMES))) for n in (3, 4, 6, 10, 14)]
    assert all(a > b for a, b in zip(errors, errors[1:])), errors
    assert errors[-1] < 0.015
    # too coarse for an engagement: 3 cells are 40 % low at 0.05 s
    assert surface_error(3, ENGAGEMENT_TIMES)[0] < -0.3


def test_a_thicker_lining_changes_nothing_while_the_heat_has_not_reached_its_back():
    """Semi-infinite means the back face is not felt: 1 mm and 3 mm of lining (same surface cells) agree
    at 0.1 s to 1e-3 (sqrt(alpha t) = 0.12 mm)."""
    chain_1, Q = lining_alone(1e-3, 6)
    dx_1 = thermal.lining_cells(1e-3, 6)
    # 3 mm with the same first six cells and one more cell of the rest
    widths = np.concatenate([dx_1, [2e-3]])
    k, rho, c = PAPER
    C = np.zeros(8)
    C[:-1] += rho * c * AREA * widths / 2
    C[1:] += rho * c * AREA * widths / 2
    chain_3 = thermal.ConductionChain(C, k * AREA / widths, 0.0, 0.0)
    a = chain_1.relax(np.zeros(7), 0.1, 0.0, heat=Q)[0]
    b = chain_3.relax(np.zeros(8), 0.1, 0.0, heat=Q)[0]
    assert a == pytest.approx(b, rel=1e-3)


def test_rates_integrated_by_cvodes_agree_with_the_matrix_exponential():
    """Two methods on the same chain: the model's equations (rates, as CasADi expressions) integrated by
    CVODES, and the exact linear solution (relax); with a separator, a core and convection at both ends."""
    chain = thermal.lining_chain(1e-3, 6, *PAPER, AREA, surface_capacity=40.0, back_capacity=20.0,
                                 surface_loss=10.0, back_loss=10.0)
    T = ca.SX.sym("T", chain.size)
    E = ca.SX.sym("E")
    Q = ca.SX.sym("Q")
    dT, convected = chain.rates([T[j] for j in range(chain.size)], Q, 40.0)
    dae = {"x": ca.vertcat(T, E), "p": Q, "ode": ca.vertcat(*dT, convected)}
    times = np.array([0.1, 0.5, 2.0])
    sim = ca.integrator("chain", "cvodes", dae, 0.0, times, {"reltol": 1e-12, "abstol": 1e-10})
    start = np.full(chain.size, 60.0)
    out = np.array(sim(x0=np.concatenate([start, [0.0]]), p=5e3)["xf"])
    for k, t in enumerate(times):
        np.testing.assert_allclose(out[:-1, k], chain.relax(start, t, 40.0, heat=5e3), rtol=1e-9)
        # energy: heat in = stored + convected
        stored = chain.stored_heat(out[:-1, k], 60.0)
        assert stored + out[-1, k] == pytest.approx(5e3 * t, rel=1e-9)


def test_steady_state_with_convection_is_the_resistor_chain():
    """Q into the surface, convection G at both ends: through the lining flows f = Q / (1 + G_0 (R + 1/G_N))
    with R = d / (k A) (the continuous slab's resistance, independent of the cells), and the surface
    is f R above the back. The chain run to rest (exact solution after 1e4 s) and the linear solve agree."""
    d, Q, G0, GN = 1e-3, 2e3, 15.0, 25.0
    chain = thermal.lining_chain(d, 6, *PAPER, AREA, surface_capacity=30.0, back_capacity=10.0,
                                 surface_loss=G0, back_loss=GN)
    R = d / (PAPER[0] * AREA)
    assert np.sum(1 / chain.conductance) == pytest.approx(R, rel=1e-12)
    f = Q / (1 + G0 * (R + 1 / GN))
    steady = chain.steady_state(Q, 40.0)
    assert steady[-1] == pytest.approx(40.0 + f / GN, rel=1e-12)
    assert steady[0] - steady[-1] == pytest.approx(f * R, rel=1e-12)
    assert G0 * (steady[0] - 40.0) + GN * (steady[-1] - 40.0) == pytest.approx(Q, rel=1e-12)
    A, b = chain.matrix()
    np.testing.assert_allclose(40.0 + np.linalg.solve(A, -b * Q), steady, rtol=1e-12)
    np.testing.assert_allclose(chain.relax(np.full(chain.size, 40.0), 1e4, 40.0, heat=Q), steady, rtol=1e-9)
    # the lining's linear profile: temperatures fall in proportion to the depth
    depth = np.concatenate([[0.0], np.cumsum(thermal.lining_cells(d, 6))])
    np.testing.assert_allclose(steady[0] - steady, f * depth / (PAPER[0] * AREA), rtol=1e-12, atol=1e-12)


def test_steady_state_limits():
    chain = thermal.lining_chain(1e-3, 4, *PAPER, AREA, surface_capacity=1.0, back_capacity=1.0,
                                 surface_loss=10.0, back_loss=0.0)
    np.testing.assert_allclose(chain.steady_state(100.0, 40.0), 50.0)           # all out at the surface
    insulated = thermal.lining_chain(1e-3, 4, *PAPER, AREA, surface_capacity=1.0, back_capacity=1.0,
                                     surface_loss=0.0, back_loss=0.0)
    assert np.all(np.isinf(insulated.steady_state(100.0, 40.0)))


def test_lumped_closed_form():
    """C dT/dt = Q - G (T - T_oil): the closed form and its G -> 0 limit Q t / C."""
    assert thermal.constant_heat_temperature(2.0, 100.0, 50.0, 0.0, 20.0, 40.0) == pytest.approx(24.0)
    assert thermal.constant_heat_temperature(2.0, 100.0, 50.0, 1e-9, 20.0, 40.0) == pytest.approx(24.0, rel=1e-9)
    one = thermal.ConductionChain(np.array([50.0]), np.zeros(0), 5.0, 0.0)
    assert one.relax([20.0], 3.0, 40.0, heat=100.0)[0] == pytest.approx(
        thermal.constant_heat_temperature(3.0, 100.0, 50.0, 5.0, 20.0, 40.0), rel=1e-12)
