"""The clamp pressure after lock-up and the whole usable curve (clutchocp.optimal.clamp)."""

import math

import numpy as np
import pytest

from clutchocp.errors import ModelError
from clutchocp.optimal.clamp import ClampModel, extend_to_clamp
from clutchocp.optimal.replay import simulate_command
from clutchocp.scene import default_scene


@pytest.fixture(scope="module")
def scene():
    return default_scene()


@pytest.fixture(scope="module")
def clamp(scene):
    return ClampModel(scene)


def closed_form_capacity_per_pa(scene):
    """Settled pack without a piston: every film carries the face force p A on its asperities
    (no static fluid load without an inlet pressure), so capacity = n mu r_eff A p (Bao Eq. 25-26)."""
    r1, r2 = scene.value("plates.r_inner"), scene.value("plates.r_outer")
    area = math.pi * (r2**2 - r1**2)
    r_eff = 2.0 / 3.0 * (r2**3 - r1**3) / (r2**2 - r1**2)
    return scene.value("plates.n_interfaces") * scene.value("friction.mu") * r_eff * area


def test_locked_torque_is_the_two_inertia_closed_form(scene, clamp):
    T_in, T_load = scene.value("driveline.input_torque"), scene.value("load.torque")
    I_in, I_out = scene.value("driveline.input_inertia"), scene.value("driveline.output_inertia")
    # Locked: both inertias accelerate together, (T_in - T_load) / (I_in + I_out); the clutch
    # carries what the output side needs.
    assert clamp.locked_torque() == pytest.approx(T_load + I_out * (T_in - T_load) / (I_in + I_out), rel=1e-12)


@pytest.mark.parametrize("pressure", [2e5, 8e5])
def test_settled_capacity_is_the_closed_form(scene, clamp, pressure):
    assert clamp.capacity(pressure) == pytest.approx(closed_form_capacity_per_pa(scene) * pressure, rel=1e-9)


@pytest.mark.parametrize("margin", [1.0, 1.3, 2.0])
def test_clamp_pressure_gives_the_margin(scene, clamp, margin):
    p_c = clamp.clamp_pressure(margin)
    assert p_c == pytest.approx(margin * clamp.locked_torque() / closed_form_capacity_per_pa(scene), rel=1e-9)


def test_curve_ramps_at_the_rate_limit_and_holds(scene):
    times, command = np.array([0.0, 0.1, 0.2, 0.3]), np.array([1e5, 3e5, 4e5, 6e5])
    curve = extend_to_clamp(scene, times, command, 0.25, margin=1.3, rate_limit=2e7)
    t, p = curve
    assert np.all(np.diff(t) > 0)
    np.testing.assert_allclose(t[:3], [0.0, 0.1, 0.2])
    assert t[3] == 0.25 and p[3] == pytest.approx(5e5)            # the command at lock-up, 0.3 s dropped
    assert p[-1] == pytest.approx(curve.clamp_pressure_Pa)
    assert (p[-1] - p[-2]) / (t[-1] - t[-2]) == pytest.approx(2e7 * np.sign(p[-1] - p[-2]))
    assert curve.ramp_end_s == t[-1] and curve.margin == 1.3


def test_whole_curve_replayed_holds_the_lock_with_the_margin(scene):
    """IDAS replay: a step to the set pressure locks, the ramp to the clamp follows, the lock holds
    (no unlock) and the capacity settles at margin x the locked torque."""
    run0 = simulate_command(scene, [0.0], [scene.value("actuation.pressure")], 0.5)
    t_lock = run0.summary["engagement_time_s"]
    curve = extend_to_clamp(scene, [0.0, t_lock], [scene.value("actuation.pressure")] * 2, t_lock, margin=1.3)
    t, p = curve
    run = simulate_command(scene, t, p, 1.0, control="linear")
    names = [e.name for e in run.result.events]
    assert "lockup" in names and "unlock" not in names
    capacity = run.result["static_capacity_Nm"][-1]
    torque = run.result["total_torque_Nm"][-1]
    assert torque == pytest.approx(curve.locked_torque_Nm, rel=1e-6)
    assert capacity / torque == pytest.approx(1.3, rel=2e-3)


@pytest.mark.parametrize("margin", [0.9, "x", float("nan"), 100.0])
def test_bad_margins_are_one_clear_line(scene, margin):
    with pytest.raises(ModelError, match="margin"):
        extend_to_clamp(scene, [0.0, 0.1], [1e5, 2e5], 0.1, margin=margin)


def test_clamp_with_a_piston_presses_the_pack_with_the_same_face_force():
    """default_fill is default_driveline with a pressure-applied piston: at its clamp pressure the
    piston force minus the return spring (at the settled stroke, travel + film closure) equals the
    face force p A_pack of default_driveline's clamp, and the settled films are the same."""
    from clutchocp.scene import load_scene
    fill = ClampModel(load_scene("default_fill"))
    plain = ClampModel(default_scene())
    p_fill, p_plain = fill.clamp_pressure(), plain.clamp_pressure()
    h = fill.settled_films(p_fill)
    scene, model = fill.model.scene, fill.model
    k = scene.value("piston.spring_stiffness") * scene.value("piston.spring_count")
    stroke = model.travel + sum(model.H0 - hi for hi in h)
    face = p_fill * scene.value("piston.area") - k * (scene.value("piston.spring_preload") + stroke)
    assert face == pytest.approx(p_plain * plain.model._pack_area(), rel=1e-9)
    assert np.allclose(h, plain.settled_films(p_plain), rtol=1e-9)


def test_a_given_clamp_pressure_needs_no_capacity():
    """A lock that carries no torque: the curve ramps to the pressure given, margin None."""
    curve = extend_to_clamp(default_scene(), [0.0, 0.1], [0.0, 4e5], 0.1, clamp_pressure=6e5, rate_limit=1e8)
    assert curve.margin is None and curve.clamp_pressure_Pa == 6e5
    assert curve.ramp_end_s == pytest.approx(0.1 + 2e5 / 1e8, rel=1e-12)
    assert list(curve.pressures) == [0.0, 4e5, 6e5]
