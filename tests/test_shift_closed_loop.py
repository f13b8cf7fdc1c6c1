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
