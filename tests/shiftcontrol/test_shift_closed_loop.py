"""Slip feedback on the nonlinear engagement model: idle on the nominal clutch, acting on another; limits."""

import numpy as np
import pytest

from clutchocp.optimal.problem import EngagementOCP
from clutchocp.optimal.verify import run_numbers
from clutchocp.scene import default_scene
from clutchocp.shiftcontrol.closed_loop import post_lock_command, run_closed_loop, run_open_loop
from clutchocp.shiftcontrol.controller import SlipFeedback
from clutchocp.shiftcontrol.design import design_slip_feedback
from clutchocp.shiftcontrol.spec import load_slip_spec


@pytest.fixture(scope="module")
def designed():
    scene = default_scene().without_uncertainty()
    opt = EngagementOCP(scene, intervals=40).solve()
    design = design_slip_feedback(scene, opt.command_times, opt.command, load_slip_spec())
    times, values = post_lock_command(scene, opt.command_times, opt.command, opt.t_f, design.feedback.rate_limit)
    return scene, opt, design, times, values


def _jump_pct(numbers):
    return 100 * abs(numbers["lockup_torque_jump_Nm"]) / numbers["locked_torque_Nm"]


def test_closed_loop_on_the_nominal_clutch_reproduces_the_open_loop_optimum(designed):
    scene, opt, design, times, values = designed
    t_end = 1.3 * opt.t_f
    closed, tcu = run_closed_loop(scene, design.feedback, t_end)
    open_ = run_open_loop(scene, times, values, t_end)
    a, b = run_numbers(open_), run_numbers(closed)
    assert b["engagement_time_s"] == pytest.approx(a["engagement_time_s"], rel=0.01)
    assert abs(_jump_pct(b) - _jump_pct(a)) < 0.5
    assert b["jerk_integral"] == pytest.approx(a["jerk_integral"], rel=0.02)
    assert b["dissipated_energy_J"] == pytest.approx(a["dissipated_energy_J"], rel=1e-3)
    # the feedback stays idle: corrections of a few pascals against a 1.5 MPa range
    assert np.max(np.abs(tcu["correction_Pa"])) < 100.0
    # the spec's feedforward adaptation is on, and on the nominal clutch it estimates the nominal clutch
    assert design.feedback.adaptation is not None
    assert np.max(np.abs(tcu["scale"] - 1.0)) < 1e-4 and np.max(np.abs(tcu["shift_Pa"])) < 1.0
    assert tcu["handover_s"] is not None


def test_feedback_cuts_the_jump_on_a_clutch_with_less_friction(designed):
    """On the default scene's 0.3 s budget. (At the lock-up time of its own step, 0.135 s, the optimum rides the
    pressure limits and this feedback pushed the weaker clutch into a faster, harder lock: 40.5 % against the
    open loop's 16.1 %.)"""
    scene, opt, design, times, values = designed
    other = scene.with_overrides({"friction.mu": 0.9 * scene.value("friction.mu")})
    t_end = 2.5 * opt.t_f          # the open loop locks late (measured: 1.78 t_f)
    closed, tcu = run_closed_loop(other, design.feedback, t_end, nominal_scene=scene)
    a, b = run_numbers(run_open_loop(other, times, values, t_end)), run_numbers(closed)
    assert a["engagement_time_s"] is not None and b["engagement_time_s"] is not None
    assert _jump_pct(b) < 0.5 * _jump_pct(a)
    assert np.max(tcu["correction_Pa"]) > 1e4           # it pushed harder on the weaker clutch


def _toy_feedback(**kw):
    N = 4
    args = dict(sample_time=0.01, gains=np.full((N, 3), [0.0, -1e6, 1e6]), integral_gains=np.full(N, -1e7),
                reference=np.zeros((N + 1, 3)), slip_reference=np.zeros(N + 1),
                measured=("slip_rate", "w_in", "w_out"), feedforward=([0.0, 1.0], [5e5, 5e5]),
                p_min=0.0, p_max=1e6, rate_limit=2e7)
    args.update(kw)
    return SlipFeedback(**args)


def test_limits_rate_limit_and_clamping_anti_windup():
    fb = _toy_feedback()
    signals = {"w_in": 10.0, "w_out": 0.0}                 # 10 rad/s of slip error: a huge correction
    du, u, u_unsat = fb.step(0, signals)
    assert u_unsat > 1e6 and u == pytest.approx(1e6)      # clipped to the pressure limit
    assert fb.integral == 0.0                             # saturated, and integrating would push further
    du, u, _ = fb.step(1, {"w_in": -10.0, "w_out": 0.0})
    assert u == pytest.approx(1e6 - 2e7 * 0.01)           # the command falls no faster than the rate limit
    free = _toy_feedback(anti_windup="none")
    free.step(0, signals)
    assert free.integral == pytest.approx(0.01 * 10.0)


def test_two_designs_blend_table_by_table():
    """Blending two feedbacks (a TCU interpolating its calibration): every table and the feedforward are
    the weighted mean of the two; weight 0 gives the first back; unlike designs do not blend."""
    a = _toy_feedback(feedforward=([0.0, 0.1, 1.0], [2e5, 6e5, 6e5]))
    b = _toy_feedback(gains=np.full((4, 3), [0.0, -3e6, 2e6]), integral_gains=np.full(4, -2e7),
                      slip_reference=np.linspace(5.0, 0.0, 5), feedforward=([0.0, 0.05, 0.3, 1.0], [0.0, 8e5, 4e5, 4e5]))
    mid = a.blended(b, 0.25)
    assert mid.gains == pytest.approx(0.75 * a.gains + 0.25 * b.gains)
    assert mid.integral_gains == pytest.approx(np.full(4, -1.25e7))
    assert mid.slip_reference == pytest.approx(0.25 * b.slip_reference)
    for t in np.linspace(0.0, 1.2, 37):         # piecewise linear on the union grid: exact everywhere
        assert mid.feedforward(t) == pytest.approx(0.75 * a.feedforward(t) + 0.25 * b.feedforward(t))
    same = a.blended(b, 0.0)
    assert same.gains == pytest.approx(a.gains) and same.feedforward(0.07) == pytest.approx(a.feedforward(0.07))
    assert a.blended(_toy_feedback(integral_gains=np.full(5, -1e7), gains=np.zeros((5, 3)),
                                   reference=np.zeros((6, 3)), slip_reference=np.zeros(6)), 0.5) is None
    assert a.blended(_toy_feedback(p_max=2e6), 0.5) is None


def test_schedule_blends_between_grid_values_and_holds_outside():
    from clutchocp.shiftcontrol.schedule import FeedbackSchedule

    scene = default_scene().without_uncertainty()
    eta = scene.value("oil.viscosity")
    designs = [_toy_feedback(integral_gains=np.full(4, k)) for k in (-1e7, -2e7, -4e7)]
    schedule = FeedbackSchedule("oil.viscosity", np.array([0.8, 1.0, 1.2]) * eta, designs,
                                [{"oil.viscosity": f * eta} for f in (0.8, 1.0, 1.2)], [0.28] * 3)
    at = lambda f: schedule.select(scene.with_overrides({"oil.viscosity": f * eta}))   # noqa: E731
    assert at(1.0)[0] is designs[1] and at(0.7)[0] is designs[0] and at(1.3)[0] is designs[2]
    feedback, overrides = at(1.15)
    assert feedback.integral_gains == pytest.approx(np.full(4, -3.5e7))       # 3/4 of the way to the third
    assert overrides == {"oil.viscosity": pytest.approx(1.15 * eta)}
