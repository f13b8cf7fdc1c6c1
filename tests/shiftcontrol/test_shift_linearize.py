"""Linearisation of the slip phase along a trajectory against finite differences of the nonlinear model."""

import casadi as ca
import numpy as np
import pytest

from clutchocp.optimal.guess import SLIP_MODE
from clutchocp.optimal.replay import CommandModel, simulate_command
from clutchocp.scene import default_scene
from clutchocp.shiftcontrol.linearize import SlipLinearization
from clutchocp.simulation import SimulationOptions, simulate

T0, TS, SUB = 0.08, 0.01, 8


@pytest.fixture(scope="module")
def setup():
    scene = default_scene().without_uncertainty()
    model = CommandModel(scene, "linear")
    times, values = np.array([0.0, 0.3]), np.array([0.3e6, 1.2e6])       # a ramp command
    mids = T0 + TS * (np.arange(SUB) + 0.5) / SUB
    run = simulate_command(scene, times, values, T0 + TS, model=model, control="linear", points=11,
                           extra_times=np.concatenate([[T0], mids]), rtol=1e-10, atol=1e-10)
    lin = SlipLinearization(model.engagement)
    res = run.result

    def state_at(t):
        i = int(np.argmin(np.abs(res.t - t)))
        assert res.mode[i] == SLIP_MODE and abs(res.t[i] - t) < 1e-12
        return np.array([res[n][i] for n in lin.all_states])

    return scene, model, lin, times, values, state_at, mids


def _rhs(lin, mode):
    x = ca.vertcat(*mode.x.values())
    u = lin.engagement.hybrid.u["pressure_command"]
    rows = [list(mode.x).index(n) for n in lin.state_names]
    return ca.Function("f", [x, u], [ca.vertcat(*mode.ode)[rows]])


def test_continuous_jacobians_match_central_differences(setup):
    _, model, lin, times, values, state_at, _ = setup
    f = _rhs(lin, model.engagement.modes[SLIP_MODE])
    x0, u0 = state_at(T0), float(np.interp(T0, times, values))
    A, B, _, _ = lin.continuous(x0, u0)
    cols = [list(lin.all_states).index(n) for n in lin.state_names]
    for j, col in enumerate(cols):
        h = 1e-6 * lin.nominal[j]
        xp, xm = x0.copy(), x0.copy()
        xp[col] += h
        xm[col] -= h
        fd = (np.array(f(xp, u0)).ravel() - np.array(f(xm, u0)).ravel()) / (2 * h)
        scale = np.max(np.abs(A[:, j])) + 1e-300
        np.testing.assert_allclose(A[:, j], fd, rtol=1e-5, atol=1e-6 * scale)
    h = 1.0
    fd_u = (np.array(f(x0, u0 + h)).ravel() - np.array(f(x0, u0 - h)).ravel()) / (2 * h)
    np.testing.assert_allclose(B[:, 0], fd_u, rtol=1e-6, atol=1e-12)


def test_sample_map_matches_finite_differences_of_the_idas_sample(setup):
    _, model, lin, times, values, state_at, mids = setup
    points = np.array([state_at(t) for t in mids])
    Phi, Gamma = lin.sample_map(points, np.interp(mids, times, values), TS / SUB)
    x0 = dict(zip(lin.all_states, state_at(T0)))
    options = SimulationOptions(rtol=1e-11, atol=1e-11)

    def sample(x, du):
        r = simulate(model.hybrid, x, [T0, T0 + TS], mode=SLIP_MODE, u=model.inputs(times, values + du),
                     options=options)
        return np.array([r.final(n) for n in lin.state_names])

    du = 2e3
    gamma_fd = (sample(x0, du) - sample(x0, -du)) / (2 * du)
    np.testing.assert_allclose(Gamma[:, 0], gamma_fd, rtol=5e-3, atol=1e-3 * np.max(np.abs(gamma_fd)))
    # columns of Phi: the valve pressure, the input speed and the films together (they stay equal)
    for names, step in ((["p_valve"], 2e3), (["w_in"], 1e-2), (["h_1", "h_2", "h_3", "h_4"], 2e-8)):
        xp, xm = dict(x0), dict(x0)
        for n in names:
            xp[n] += step
            xm[n] -= step
        fd = (sample(xp, 0.0) - sample(xm, 0.0)) / (2 * step)
        lin_col = sum(Phi[:, lin.state_names.index(n)] for n in names)
        rows = [i for i, n in enumerate(lin.state_names) if n != "p_valve" or names == ["p_valve"]]
        np.testing.assert_allclose(lin_col[rows], fd[rows], rtol=5e-3, atol=1e-3 * np.max(np.abs(fd[rows])))


def test_parameter_columns_exact_against_differences_and_closed_form(setup):
    """Relative-change columns of the slip dynamics: the exact ones (fields as CasADi symbols) against central
    differences of two models; the engine torque (a field the model cannot take as a symbol) against Newton's
    law for the input rotor, theta d(dw_in/dt)/d theta = T_in / J_in, and the same in the slip rate."""
    from clutchocp.shiftcontrol.linearize import _Difference, parametric_linearization

    scene, model, lin, times, values, state_at, _ = setup
    names = ("friction.mu", "load.torque", "driveline.input_torque", "actuation.time_constant")
    plin = parametric_linearization(scene, names)
    assert plin.parameter_names == names
    x0, u0 = state_at(T0), float(np.interp(T0, times, values))
    F, G = plin.parameter_columns(x0, u0)
    # the state Jacobians are the concrete model's
    np.testing.assert_allclose(plin.continuous(x0, u0)[0], lin.continuous(x0, u0)[0], rtol=1e-12, atol=1e-9)
    for j, name in enumerate(("friction.mu", "load.torque", "actuation.time_constant")):
        f_d, _, c_d = _Difference(scene, name, h=1e-4).blocks(x0, np.zeros(0), u0)
        col = names.index(name)
        np.testing.assert_allclose(F[:, col], f_d, rtol=1e-6, atol=1e-8 * np.max(np.abs(f_d)))
        np.testing.assert_allclose(G[:, col], c_d, rtol=1e-6, atol=1e-8 * np.max(np.abs(c_d)))
    T_in, J_in = scene.value("driveline.input_torque"), scene.value("driveline.input_inertia")
    T_L, J_out = scene.value("load.torque"), scene.value("driveline.output_inertia")
    i_in, i_out = plin.state_names.index("w_in"), plin.state_names.index("w_out")
    col = names.index("driveline.input_torque")
    assert F[i_in, col] == pytest.approx(T_in / J_in, rel=1e-9)
    assert np.delete(F[:, col], i_in) == pytest.approx(0.0, abs=1e-9)
    assert G[plin.signals.index("slip_rate"), col] == pytest.approx(T_in / J_in, rel=1e-9)
    load = names.index("load.torque")
    assert F[i_out, load] == pytest.approx(-T_L / J_out, rel=1e-12)
    assert G[plin.signals.index("slip_rate"), load] == pytest.approx(T_L / J_out, rel=1e-12)
    # the valve lag: d(dp/dt) = -(u - p) / tau x d (relative change of tau)
    i_p = plin.state_names.index("p_valve")
    p = x0[plin.all_states.index("p_valve")]
    tau = scene.value("actuation.time_constant")
    assert F[i_p, names.index("actuation.time_constant")] == pytest.approx(-(u0 - p) / tau, rel=1e-12)
