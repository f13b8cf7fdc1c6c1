"""Exact linearisation of the HVD DAE: finite differences, a second method for the DC gain, and a step."""

import numpy as np
import pytest

from clutchocp.hvd import HvdModel, finite_difference, linearize, operating_point
from clutchocp.hvd.linearize import describe
from clutchocp.scene import load_scene
from clutchocp.simulation import PiecewiseConstant, SimulationOptions, simulate

LIAO_FILMS = {"hvc.friction_ratio": "0.1 1/mm^2", "hvc.first_film": "0.1 mm", "hvd.spline_friction": 0.1}


@pytest.fixture(scope="module")
def models():
    return {"liao": HvdModel(load_scene("liao2021_hvd")), "cui": HvdModel(load_scene("cui2019_hvd")),
            "liao_films": HvdModel(load_scene("liao2021_hvd", overrides=LIAO_FILMS))}


def _scaled_error(model, exact, approx, rows, cols):
    """max |S_r (approx - exact) S_c^-1| / max |S_r exact S_c^-1| on nominal-scaled variables."""
    R, C = np.diag(1 / rows), np.diag(cols)
    return np.max(np.abs(R @ (approx - exact) @ C)) / np.max(np.abs(R @ exact @ C))


@pytest.mark.parametrize("name,fraction", [("liao", 0.4), ("liao", 0.6), ("liao", 0.9), ("cui", 0.6),
                                           ("cui", 0.9), ("liao_films", 0.6)])
def test_linearisation_matches_finite_differences(models, name, fraction):
    model = models[name]
    op = operating_point(model, fraction * model.rated_speed)
    sys = linearize(model, op)
    A, B, C, D = finite_difference(model, op)
    u_scale = np.array([model.p_max, model.rated_torque])
    assert _scaled_error(model, sys.A, A, model.x_nominal, model.x_nominal) <= 1e-6
    assert _scaled_error(model, sys.B, B, model.x_nominal, u_scale) <= 1e-6
    np.testing.assert_allclose(sys.C, C, rtol=1e-6, atol=1e-12)
    np.testing.assert_allclose(sys.D, D, atol=1e-12)


def test_algebraic_elimination_matters(models):
    """f_z g_z^-1 g_x is not negligible: A differs from f_x alone (the films move through z)."""
    import casadi as ca
    model = models["liao"]
    op = operating_point(model, 0.6 * model.rated_speed)
    fx = np.array(ca.Function("fx", [model.vector("x"), model.vector("z"), model.vector("u")],
                              [ca.jacobian(model.ode, model.vector("x"))])(op.x, op.z, op.u))
    A = linearize(model, op).A
    S = np.diag(1 / model.x_nominal)
    scaled = lambda M: S @ M @ np.linalg.inv(S)
    assert np.max(np.abs(scaled(A) - scaled(fx))) > 0.1 * np.max(np.abs(scaled(A)))


def test_named_signals_and_description(models):
    model = models["cui"]
    sys = linearize(model, operating_point(model, 0.6 * model.rated_speed))
    assert sys.input_labels == ["p_cmd", "load_torque"]
    assert sys.state_labels == ["w", "p", "h_1"]
    assert sys.output_labels == ["w_out_rad_s"]
    info = describe(sys)
    assert len(info["poles"]) == 3 and all(re < 0 for re, _ in info["poles"])
    assert info["poles"][0][0] == pytest.approx(-1 / model.valve_time_constant, rel=1e-9)   # the valve lag


@pytest.mark.parametrize("name", ["liao", "cui"])
def test_dc_gain_equals_slope_of_the_operating_points(models, name):
    """Second method: d(speed)/d(pressure) from two neighbouring steady states (central difference)."""
    model = models[name]
    op = operating_point(model, 0.7 * model.rated_speed)
    gain = linearize(model, op).dcgain()[0, 0]
    dw = 1e-4 * op.speed
    hi = operating_point(model, op.speed + dw, guess=op)
    lo = operating_point(model, op.speed - dw, guess=op)
    assert gain == pytest.approx(2 * dw / (hi.pressure - lo.pressure), rel=1e-6)


@pytest.mark.parametrize("name,fraction", [("liao", 0.6), ("cui", 0.9)])
def test_linear_and_nonlinear_responses_to_a_one_percent_step_agree(models, name, fraction):
    """Pressure step that moves the steady speed by 1 %: IDAS (simulation engine) vs the linear model."""
    model = models[name]
    op = operating_point(model, fraction * model.rated_speed)
    sys = linearize(model, op)
    gain = sys.dcgain()[0, 0]
    dp = 0.01 * op.speed / gain
    slowest = 1 / min(abs(np.real(sys.poles())))
    t = np.linspace(0.0, 6 * slowest, 201)
    res = simulate(model.hybrid, dict(zip(model.state_names, op.x)), t,
                   u={"p_cmd": PiecewiseConstant([1e-9], [op.pressure, op.pressure + dp]), "load_torque": 0.0},
                   options=SimulationOptions(rtol=1e-9, atol=1e-9))
    w_nl = np.interp(t, res.t, res["w"]) - op.speed
    from control import forced_response
    _, y = forced_response(sys[0, 0], T=t, U=np.full_like(t, dp))
    assert np.max(np.abs(w_nl - y)) <= 0.02 * np.max(np.abs(y))
    assert w_nl[-1] == pytest.approx(0.01 * op.speed, rel=0.02)         # it did reach ~1 %
