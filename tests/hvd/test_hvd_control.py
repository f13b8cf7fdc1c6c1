"""Controller specs, design (LQI, PI), margins and the discrete controller law."""

import math

import control
import numpy as np
import pytest
from scipy.linalg import solve_discrete_are

from clutchocp import errors
from clutchocp.hvd import HvdModel, ScheduledController, design, load_controller, loop_margins, parse_controller
from clutchocp.control.lqr import lqi, lqr_gain
from clutchocp.hvd.design import _first_order_model
from clutchocp.scene import load_scene

GOOD = {"controller": {"type": "lqi", "sample_time": "10 ms", "schedule": [0.4, 0.9]},
        "lqi": {"speed_weight": 1.0}}


def spec_with(table, key, value):
    raw = {k: dict(v) for k, v in GOOD.items()}
    raw.setdefault(table, {})[key] = value
    return raw


# ---------------------------------------------------------------------------------- design maths
@pytest.mark.parametrize("a,b,q,r", [(0.9, 0.5, 1.0, 1.0), (1.2, 0.1, 3.0, 0.01), (0.5, -2.0, 0.1, 5.0)])
def test_scalar_lqr_gain_is_the_closed_form(a, b, q, r):
    """x+ = a x + b u: P solves b^2 P^2 + (r(1 - a^2) - q b^2) P - q r = 0, K = a b P / (r + b^2 P)."""
    c1 = r * (1 - a**2) - q * b**2
    P = (-c1 + math.sqrt(c1**2 + 4 * b**2 * q * r)) / (2 * b**2)
    assert lqr_gain(a, b, q, r)[0, 0] == pytest.approx(a * b * P / (r + b**2 * P), rel=1e-10)


def test_scalar_lqr_gain_tends_to_the_continuous_closed_form():
    """dx/dt = alpha x + beta u: K -> (alpha + sqrt(alpha^2 + beta^2 q / r)) / beta as Ts -> 0."""
    alpha, beta, q, r, Ts = -0.5, 2.0, 4.0, 1.0, 1e-5
    a = math.exp(alpha * Ts)
    b = (a - 1) / alpha * beta
    K = lqr_gain(a, b, q * Ts, r * Ts)[0, 0]                  # Riemann sum of the continuous cost
    assert K == pytest.approx((alpha + math.sqrt(alpha**2 + beta**2 * q / r)) / beta, rel=1e-4)


def test_lqi_augmentation_against_the_riccati_equation():
    Ad, Bd, Ts = np.array([[0.97]]), np.array([[0.02]]), 0.01
    Q, R = np.diag([2.0, 50.0]), np.array([[0.1]])
    K_x, k_i, _ = lqi(Ad, Bd, Ts, Q, R)
    A = np.array([[0.97, 0.0], [-Ts, 1.0]])
    B = np.array([[0.02], [0.0]])
    P = solve_discrete_are(A, B, Q, R)
    K = np.linalg.solve(R + B.T @ P @ B, B.T @ P @ A).ravel()
    assert K_x[0] == pytest.approx(K[0], rel=1e-9) and k_i == pytest.approx(-K[1], rel=1e-9)
    assert np.all(np.abs(np.linalg.eigvals(A - B @ K.reshape(1, -1))) < 1)


def test_margins_of_a_discrete_integrator_loop():
    """L = g/(z - 1): unstable for g > 2 (GM = 2/g); |L| = 1 at theta = 2 asin(g/2), PM = 90 - asin(g/2) deg."""
    g = 0.5
    m = loop_margins(control.tf([g], [1, -1], dt=0.01))
    assert m["gain_margin_dB"] == pytest.approx(20 * math.log10(2 / g), abs=1e-6)
    assert m["phase_margin_deg"] == pytest.approx(90 - math.degrees(math.asin(g / 2)), abs=1e-3)
    assert m["sensitivity_peak"] == pytest.approx(1 / (1 - g / 2), rel=1e-6)    # at z = -1
    assert m["stable"]


def test_first_order_model_by_the_half_rule():
    """K/((2s + 1)(0.5s + 1)(0.03s + 1)): tau = 2 + 0.25, theta = 0.25 + 0.03 + Ts/2 (Skogestad)."""
    plant = control.ss(control.tf([3.0], np.polymul(np.polymul([2, 1], [0.5, 1]), [0.03, 1])))
    tau, theta = _first_order_model(plant, 0.01)
    assert tau == pytest.approx(2.25, rel=1e-9) and theta == pytest.approx(0.285, rel=1e-9)


# ---------------------------------------------------------------------------------- specs
def test_builtin_specs_load():
    lqi_spec, pi_spec = load_controller("lqi"), load_controller("pi")
    assert lqi_spec.type == "lqi" and pi_spec.type == "pi"
    assert lqi_spec.sample_time == pytest.approx(0.01) and pi_spec.pi["phase_margin"] == pytest.approx(math.pi / 4)


@pytest.mark.parametrize("raw,cls,text", [
    (spec_with("controller", "type", "pid"), errors.UnknownVariantError, "controller.type"),
    (spec_with("lqi", "speed_weight", -1.0), errors.PhysicalRangeError, "lqi.speed_weight"),
    (spec_with("lqi", "input_weight", 0.0), errors.PhysicalRangeError, "lqi.input_weight"),
    (spec_with("lqi", "sped_weight", 1.0), errors.UnknownKeyError, "did you mean 'speed_weight'"),
    (spec_with("controller", "sample_time", "10 m"), errors.UnitError, "controller.sample_time"),
    (spec_with("controller", "schedule", [0.4, 1.2]), errors.PhysicalRangeError, "controller.schedule[1]"),
    (spec_with("controller", "schedule", 0.4), errors.ParameterTypeError, "controller.schedule"),
    (spec_with("pi", "phase_margin", "45 deg"), errors.UnknownKeyError, "[pi]"),
    (spec_with("anti_windup", "method", "reset"), errors.UnknownVariantError, "anti_windup.method"),
    ({"lqi": {}}, errors.MissingParameterError, "[controller]"),
    ({"controller": {"type": "pi", "schedule": [0.5]}}, errors.MissingParameterError, "controller.sample_time"),
    ({"controler": {}}, errors.UnknownKeyError, "did you mean 'controller'"),
])
def test_bad_spec_gives_one_clean_line_naming_the_field(raw, cls, text):
    with pytest.raises(cls) as info:
        parse_controller(raw)
    message = str(info.value)
    assert text in message and "\n" not in message
    assert isinstance(info.value, errors.SceneError)


def test_bad_spec_file_names_the_file(tmp_path):
    path = tmp_path / "mine.toml"
    path.write_text('[controller]\ntype = "lqr"\nsample_time = 0.01\nschedule = [0.5]\n')
    with pytest.raises(errors.UnknownVariantError, match="mine.toml: controller.type = 'lqr'"):
        load_controller(path)
    with pytest.raises(errors.SceneNotFoundError, match="controller spec 'lqx'"):
        load_controller("lqx")


# ---------------------------------------------------------------------------------- designs
@pytest.fixture(scope="module")
def designs():
    out = {}
    for scene in ("liao2021_hvd", "cui2019_hvd"):
        model = HvdModel(load_scene(scene))
        for name in ("lqi", "pi"):
            out[scene, name] = design(model, load_controller(name))
    return out


@pytest.mark.parametrize("scene", ["liao2021_hvd", "cui2019_hvd"])
@pytest.mark.parametrize("name", ["lqi", "pi"])
def test_margins_at_every_scheduled_point(designs, scene, name):
    sched = designs[scene, name]
    assert [p.fraction for p in sched.points] == [0.4, 0.5, 0.6, 0.7, 0.8, 0.9]
    for p in sched.points:
        assert p.margins["stable"]
        assert p.margins["gain_margin_dB"] >= 6.0
        assert p.margins["phase_margin_deg"] >= 45.0


def test_pi_loop_is_the_product_of_controller_and_plant(designs):
    """The discrete PI loop (python-control series) equals C(z) P(z) evaluated directly."""
    p = designs["cui2019_hvd", "pi"].points[2]
    Ts = 0.01
    A, B, C = p.plant_d.A, p.plant_d.B[:, :1], p.plant_d.C[:1, :]
    for z in np.exp(1j * np.array([0.01, 0.1, 1.0])):
        plant = (C @ np.linalg.solve(z * np.eye(3) - A, B))[0, 0]
        np.testing.assert_allclose(p.loop(z), (p.k_p + p.k_i * Ts / (z - 1)) * plant, rtol=1e-9)


def test_unequal_films_lqi_is_stable_and_pi_pole_placement_refuses():
    """Liao's films add slow (one slightly unstable) distribution modes: state feedback handles them,
    SIMC (which assumes a stable plant) says so in one line."""
    model = HvdModel(load_scene("liao2021_hvd", overrides={"hvc.friction_ratio": "0.1 1/mm^2",
                                                           "hvc.first_film": "0.1 mm", "hvd.spline_friction": 0.1}))
    lqi_spec = parse_controller({"controller": {"type": "lqi", "sample_time": 0.01, "schedule": [0.6]},
                                 "lqi": {"speed_weight": 100.0, "integral_weight": 1000.0}})
    sched = design(model, lqi_spec)
    assert max(np.real(sched.points[0].plant.poles())) > 0            # the open loop has an unstable mode
    assert sched.points[0].margins["stable"] and sched.points[0].margins["gain_margin_dB"] >= 6
    pi_spec = parse_controller({"controller": {"type": "pi", "sample_time": 0.01, "schedule": [0.6]},
                                "pi": {"method": "pole_placement"}})
    with pytest.raises(errors.ModelError, match="at 0.6 x rated speed: pi: pole placement"):
        design(model, pi_spec)


# ---------------------------------------------------------------------------------- controller law
def _controller(**kw):
    args = {"speeds": [10.0, 20.0], "u_op": [1e6, 2e6], "x_op": [[10.0, 1e6], [20.0, 2e6]], "K_x": [[0.0, 0.0]] * 2,
            "k_p": [1e4, 1e4], "k_i": [1e4, 1e4], "sample_time": 0.01, "p_min": 0.0, "p_max": 1.5e6}
    args.update(kw)
    return ScheduledController(**args)


def test_gains_are_interpolated_and_held_outside_the_schedule():
    c = _controller(k_p=[1e4, 3e4])
    c.reset()
    assert c.command(15.0, [15.0, 0.0])[1] == pytest.approx(1.5e6)          # u_op interpolated, e = 0
    assert c.command(14.0, [15.0, 0.0])[1] == pytest.approx(1.4e6 - 1.8e4)   # k_p(14) = 1.8e4
    assert c.command(30.0, [30.0, 0.0])[1] == pytest.approx(2e6)             # held above the schedule


@pytest.mark.parametrize("method,bounded", [("back_calculation", True), ("clamping", True), ("none", False)])
def test_anti_windup_keeps_the_integral_bounded_in_saturation(method, bounded):
    c = _controller(anti_windup=method, tracking_time=0.1)
    c.reset()
    for _ in range(2000):                       # 20 s with a speed error the valve cannot remove
        u = c.step(20.0, [10.0, 1e6])
    assert u == 1.5e6 and c.saturated(u)
    assert (c.integral < 2e5) == bounded         # without anti-windup: 1e4 * 10 rad/s * 20 s = 2e6
    if method == "back_calculation":             # I settles where the tracking term balances k_i e
        assert c.integral == pytest.approx(1.5e6 - 2e6 - 1e4 * 10 + 0.1 * 1e4 * 10, rel=1e-6)


def test_bumpless_start_and_setpoint_filter():
    c = _controller(reference_time_constant=0.5)
    c.reset(setpoint=10.0, x=[12.0, 0.0], pressure=0.8e6)
    assert c.command(10.0, [12.0, 0.0])[0] == pytest.approx(0.8e6)           # first command = pressure
    refs = []
    for _ in range(1000):
        refs.append(c.reference(20.0))
        c.step(20.0, [12.0, 0.0])
    refs = np.array(refs)
    assert np.all(np.diff(refs) >= 0) and refs[-1] == pytest.approx(20.0, rel=1e-6)   # no overshoot
    t = 0.01 * np.arange(1000)
    exact = 20.0 - 10.0 * (1 + t / 0.5) * np.exp(-t / 0.5)                   # two first-order stages
    np.testing.assert_allclose(refs[1:], exact[:-1], atol=0.05)              # sampled: one step of delay
