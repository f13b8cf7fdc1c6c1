"""One collocation problem per worker for an optimize sweep: a point on the reused problem is the
ordinary problem of the overridden scene."""

import numpy as np
import pytest

from clutchocp.optimal.problem import EngagementOCP
from clutchocp.scene import load_scene
from clutchocp.study import parametric_ocp

# The roughness split equally between the surfaces: the optimum of each point is unique there
# (tests/test_study_sweep.py, EQUAL_SPLIT).
EQUAL_SPLIT = {"roughness.sigma_1": 8.41e-6 / 2**0.5, "roughness.sigma_2": 8.41e-6 / 2**0.5}
NAMES = ("load.torque", "oil.viscosity")


@pytest.fixture(scope="module")
def base():
    return load_scene("default_driveline", overrides=EQUAL_SPLIT)


@pytest.fixture(scope="module")
def reused(base):
    ocp = parametric_ocp.build(base.with_overrides({"load.torque": 90.0, "oil.viscosity": 0.05}), NAMES, intervals=12)
    assert isinstance(ocp, parametric_ocp.SweepOCP)
    return ocp


def test_a_point_of_the_reused_problem_is_the_ordinary_problem_of_its_scene(base, reused):
    # another load and viscosity: other references (lock time, energy, jerk, torque) than the first point's
    scene = base.with_overrides({"load.torque": 115.0, "oil.viscosity": 0.08})
    reused.set_point(scene)
    assert reused.point_scales.time_s != pytest.approx(reused.scales.time_s, rel=1e-3)
    assert reused.point_scales.torque_Nm != pytest.approx(reused.scales.torque_Nm, rel=1e-3)
    mine = reused.solve()
    ordinary = EngagementOCP(scene, intervals=12)
    theirs = ordinary.solve()
    # its scales are the ordinary build's (the baseline on the parametric simulate model: 1e-14)
    assert reused.point_scales.jerk_integral == pytest.approx(ordinary.scales.jerk_integral, rel=1e-10)
    assert reused.point_scales.energy_J == pytest.approx(ordinary.scales.energy_J, rel=1e-10)
    # the same objective (weights moved onto the first point's scales), the same optimum to IPOPT's
    # tolerance (measured: 2.4e-9 relative)
    assert mine.objective == pytest.approx(theirs.objective, rel=1e-7)
    assert mine.t_f == pytest.approx(theirs.t_f, rel=1e-7)
    assert np.max(np.abs(mine.command - theirs.command)) <= 1e-6 * theirs.command.max()
    for key in ("jerk_integral", "dissipated_energy_J", "lockup_torque_jump_Nm", "peak_torque_Nm"):
        assert mine.terms[key] == pytest.approx(theirs.terms[key], rel=1e-6), key
    assert mine.weights == theirs.weights                     # the user's weights, not the moved ones
    assert mine.stats["model"] == theirs.stats["model"] == "exact"     # polished on the reused twin too


def test_the_moved_weights_give_each_term_the_points_own_reference(reused):
    sc, pt = reused.scales, reused.point_scales
    values = reused.parameter_values({"jerk": 1.0, "energy": 1.0, "time": 1.0, "jump": 1.0, "smooth": 1.0,
                                      "fill_time": 0.0, "kiss_speed": 0.0})
    p = dict(zip(("jerk", "energy", "time", "jump", "smooth"), values))
    # a term measured on the first point's scale times its moved weight = the term on the point's scale
    jerk, energy, t_f, jump, rate2 = 3.0e5, 4.0e3, 0.21, 2.0, 7.0e12         # int jerk^2 dt, E, t_f, jump, int p'^2 dt
    assert p["jerk"] * jerk / sc.jerk_integral == pytest.approx(jerk / pt.jerk_integral)
    assert p["energy"] * energy / sc.energy_J == pytest.approx(energy / pt.energy_J)
    assert p["time"] * t_f / sc.time_s == pytest.approx(t_f / pt.time_s)
    assert p["jump"] * (jump / sc.torque_Nm) ** 2 == pytest.approx((jump / pt.torque_Nm) ** 2)
    assert p["smooth"] * rate2 * sc.time_s / sc.pressure_Pa**2 == pytest.approx(rate2 * pt.time_s / pt.pressure_Pa**2)
    assert values[7:] == list(reused.theta_value)                        # then the swept values, theta


def test_a_field_the_problem_needs_as_a_number_is_not_reused(base):
    # the input speed sets the initial state and its scale
    assert parametric_ocp.build(base, ("driveline.input_speed",), intervals=12) is None


def test_a_point_that_changes_more_than_the_swept_values_is_refused(base, reused):
    # the pressure limit scales the command and bounds it: not a swept value of this problem
    other = base.with_overrides({"load.torque": 100.0, "oil.viscosity": 0.06, "actuation.max_pressure": 2.0e6})
    with pytest.raises(parametric_ocp.NotReusable):
        reused.set_point(other)
    assert reused.holds_torque
