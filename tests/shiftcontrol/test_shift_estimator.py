"""The TCU's torque estimator and the feedforward adaptation built on it."""

import numpy as np
import pytest

from clutchocp.errors import ModelError
from clutchocp.optimal.verify import run_numbers
from clutchocp.scene import default_scene, load_scene
from clutchocp.shiftcontrol.closed_loop import run_open_loop
from clutchocp.shiftcontrol.estimator import FeedforwardAdaptation, TorqueEstimator

TS = 0.01


@pytest.fixture(scope="module")
def nominal_run():
    scene = default_scene().without_uncertainty()
    times, command = np.array([0.0, 0.05, 0.4]), np.array([6e5, 9e5, 9e5])
    return scene, run_open_loop(scene, times, command, 0.4)


def _sampled(run, name, t):
    res = run.result
    unique, order = np.unique(res.t, return_index=True)
    return np.interp(t, unique, res[name][order])


def test_estimates_follow_newton_on_a_run(nominal_run):
    """Over each 10 ms sample of a slipping run: the load estimate is the scene's constant load (exact:
    both rotors are rigid), the clutch torque estimate is the mean of the model's clutch torque, and the
    locked torque of the estimated load is the model's own locked torque."""
    scene, run = nominal_run
    est = TorqueEstimator.from_scene(scene, TS)
    t_lock = run_numbers(run)["engagement_time_s"]
    t = np.arange(0.0, t_lock - TS, TS)
    clutch, load, p_mean = est.along(_sampled(run, "w_in_rad_s", t), _sampled(run, "w_out_rad_s", t),
                                     _sampled(run, "pressure_Pa", t))
    assert load == pytest.approx(np.full(t.size - 1, scene.value("load.torque")), rel=1e-6)
    dense = np.linspace(0.0, t[-1], 200 * (t.size - 1) + 1)
    torque = _sampled(run, "total_torque_Nm", dense).reshape(-1)
    means = [np.trapezoid(torque[200 * k:200 * k + 201], dense[200 * k:200 * k + 201]) / TS for k in range(t.size - 1)]
    assert clutch == pytest.approx(means, rel=2e-3, abs=0.2)
    assert p_mean[-1] == pytest.approx(0.5 * (_sampled(run, "pressure_Pa", t[-1]) + _sampled(run, "pressure_Pa", t[-2])))
    assert est.locked_torque(load[-1]) == pytest.approx(run_numbers(run)["locked_torque_Nm"], rel=1e-6)
    one = est.estimate({"w_in": 300.0, "w_out": 150.0, "p_valve": 4e5}, {"w_in": 301.0, "w_out": 150.5, "p_valve": 6e5})
    J_in, J_out, T_in = est.input_inertia, est.output_inertia, est.input_torque
    assert one == pytest.approx((T_in - J_in * 100.0, T_in - J_in * 100.0 - J_out * 50.0, 5e5))


def _samples_for(est, clutch, load, p_mean):
    """Two sample dicts whose estimates are (clutch, load, p_mean)."""
    dw_in = (est.input_torque - clutch) * TS / est.input_inertia
    dw_out = (clutch - load) * TS / est.output_inertia
    return ({"w_in": 300.0, "w_out": 150.0, "p_valve": p_mean - 1e4},
            {"w_in": 300.0 + dw_in, "w_out": 150.0 + dw_out, "p_valve": p_mean + 1e4})


def test_adaptation_gives_the_clutch_met_the_nominal_slip_rate():
    """A clutch with 0.9 x the nominal torque gain and 20 N m more load: the scaled and shifted pressure
    gives it the nominal clutch's slip acceleration (closed form: dw_rel/dt = T_in/J_in + T_L/J_out -
    T_c (1/J_in + 1/J_out))."""
    est = TorqueEstimator(0.25, 2.0, 150.0, TS)
    nominal = np.array([[300.0, 100.0, 8e5]] * 3)
    adapt = FeedforwardAdaptation(est, nominal, activation=50.0, gain_limit=1.5)
    g_nom, g = 300.0 / 8e5, 0.9 * 300.0 / 8e5
    p_nom = 8e5
    # the clutch met, at some pressure p: torque g p, load 120 N m
    p = 7e5
    scale, shift = adapt.correction(nominal[1], *_samples_for(est, g * p, 120.0, p))
    assert scale == pytest.approx(g_nom / g)
    p_given = scale * p_nom + shift              # the nominal command, adapted (a static valve: p = u)
    rate = lambda T_c, T_L: est.input_torque / 0.25 + T_L / 2.0 - T_c * (1 / 0.25 + 1 / 2.0)   # noqa: E731
    assert rate(g * p_given, 120.0) == pytest.approx(rate(g_nom * p_nom, 100.0), abs=1e-9)
    # the nominal clutch itself: nothing changes
    assert adapt.correction(nominal[1], *_samples_for(est, 300.0, 100.0, 8e5)) == pytest.approx((1.0, 0.0))
    # before the activation torque, and without a previous sample: no adaptation
    early = FeedforwardAdaptation(est, nominal, activation=400.0, gain_limit=1.5)
    assert early.correction(nominal[1], *_samples_for(est, g * p, 120.0, p)) == (1.0, 0.0)
    assert adapt.correction(nominal[1], None, {"w_in": 1.0, "w_out": 0.0, "p_valve": 1e5}) == (1.0, 0.0)
    # the ratio is limited
    weak = adapt.correction(nominal[1], *_samples_for(est, 0.25 * g_nom * p, 100.0, p))
    assert weak[0] == pytest.approx(1.5)


def test_estimator_needs_two_rigid_rotors_and_a_valve_state():
    from clutchocp.shiftcontrol.design import _adaptation_unavailable

    with pytest.raises(ModelError, match=r"driveline\.input = \"inertia\""):
        TorqueEstimator.from_scene(load_scene("zhang2021"), TS)
    bao = load_scene("bao2020")                 # prescribed input speed, step actuation
    assert "driveline.input" in TorqueEstimator.unavailable(bao)
    assert "no p_valve state" in _adaptation_unavailable(bao, ("w_in", "w_out", "h_1"))
    default = default_scene()
    assert TorqueEstimator.unavailable(default) is None
    assert _adaptation_unavailable(default, ("w_in", "w_out", "p_valve")) is None
