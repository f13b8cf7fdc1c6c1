"""Driveline parts of the engagement model: compliant output shaft (a true DAE) and tabulated load."""

import numpy as np
import pytest

from clutchocp.engagement import EngagementModel
from clutchocp.engagement.run import simulate_engagement
from clutchocp.errors import ModelError
from clutchocp.scene import load_scene


def run(scene, **overrides):
    return simulate_engagement(load_scene(scene, overrides=overrides))


@pytest.fixture(scope="module")
def rigid():
    return run("default_driveline")


def test_compliant_shaft_adds_a_twist_state_and_a_hub_speed_algebraic_variable():
    model = EngagementModel(load_scene("default_driveline", overrides={
        "driveline.shaft_stiffness": "1e4 N m", "driveline.shaft_damping": 5.0}))
    assert "theta_shaft" in model.state_names
    assert list(model.modes["pressing_slip_forward"].z) == ["w_hub"]
    assert not model.modes["pressing_locked"].z       # the hub is locked to the input


def test_very_stiff_shaft_behaves_like_a_rigid_one(rigid):
    stiff = run("default_driveline", **{"driveline.shaft_stiffness": "1e7 N m", "driveline.shaft_damping": 50.0})
    # The twist under ~300 N m is 3e-5 rad: lock time and final speed move by far less than 1e-3.
    assert stiff.summary["engagement_time_s"] == pytest.approx(rigid.summary["engagement_time_s"], rel=1e-3)
    assert stiff.result.final("w_out") == pytest.approx(rigid.result.final("w_out"), rel=1e-4)
    assert stiff.summary["energy_balance_rel_error"] <= 1e-6


def test_compliant_shaft_keeps_the_clutch_torque_continuous_at_lockup(rigid):
    soft = run("default_driveline", **{"driveline.shaft_stiffness": "1e4 N m", "driveline.shaft_damping": 5.0})
    # The massless hub passes the shaft torque through the clutch on both sides of the lock,
    # so the jump that a rigid driveline shows (about -139 N m) moves into the shaft.
    assert abs(rigid.summary["lockup_torque_jump_Nm"]) > 100
    assert abs(soft.summary["lockup_torque_jump_Nm"]) < 1e-3
    assert soft.summary["energy_balance_rel_error"] <= 1e-6
    assert np.all(np.isfinite(soft.result["output_jerk_rad_s3"]))


def test_shaft_without_damping_is_refused_with_a_clear_message():
    with pytest.raises(ModelError, match="driveline.shaft_damping"):
        EngagementModel(load_scene("default_driveline", overrides={"driveline.shaft_stiffness": 1e4}))


def _load_file(tmp_path, speeds, torques):
    path = tmp_path / "load.csv"
    path.write_text("speed_rad_s,torque_Nm\n" + "".join(f"{w},{T}\n" for w, T in zip(speeds, torques)))
    return str(path)


def test_flat_load_table_equals_the_constant_load(tmp_path):
    """The same load through a table and as a constant: the lock time agrees to 1e-9 when the
    integration is tighter than that (at the scene's rtol 1e-8 the rounding differences of the two
    forms may move CVODES's steps, and the lock time, by up to the tolerance: 4e-9 measured)."""
    file = _load_file(tmp_path, [0, 100, 400], [100, 100, 100])
    tight = {"rtol": 1e-11, "atol": 1e-13}
    constant = simulate_engagement(load_scene("default_driveline"), **tight)
    table = simulate_engagement(load_scene("default_driveline", overrides={
        "load.model": "table", "load.file": file, "load.torque": None}), **tight)
    assert table.summary["engagement_time_s"] == pytest.approx(constant.summary["engagement_time_s"], rel=1e-9)


def test_load_table_from_a_quadratic_matches_the_quadratic_load(tmp_path):
    speeds = np.linspace(0, 400, 4001)
    rated_torque, rated_speed = 100.0, 200.0
    file = _load_file(tmp_path, speeds, rated_torque * (speeds / rated_speed) ** 2)
    quad = run("default_driveline", **{"load.model": "quadratic", "load.torque": None,
                                       "load.rated_torque": rated_torque, "load.rated_speed": rated_speed})
    table = run("default_driveline", **{"load.model": "table", "load.file": file, "load.torque": None})
    # Linear interpolation of w^2 on a 0.1 rad/s grid errs by (0.1)^2/8 * 100/200^2 = 3e-6 N m.
    assert table.summary["engagement_time_s"] == pytest.approx(quad.summary["engagement_time_s"], rel=1e-6)
