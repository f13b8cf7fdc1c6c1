"""The HVD model: films, forces, steady states and the static map against closed forms and Liao."""

import math

import casadi as ca
import numpy as np
import pytest
from scipy.integrate import quad

from clutchocp.errors import ModelError
from clutchocp.hvd import HvdModel, operating_point, rest_state, static_map
from clutchocp.hvd.films import HvdFilm, smooth_clamp
from clutchocp.physics import hvc
from clutchocp.physics.shear import grooved_viscous_torque
from clutchocp.scene import load_scene

LIAO_FILMS = {"hvc.friction_ratio": "0.1 1/mm^2", "hvc.first_film": "0.1 mm", "hvd.spline_friction": 0.1}


@pytest.fixture(scope="module")
def liao():
    return HvdModel(load_scene("liao2021_hvd"))


@pytest.fixture(scope="module")
def cui():
    return HvdModel(load_scene("cui2019_hvd"))


def test_scenes_build_with_named_states_and_inputs(liao, cui):
    for model in (liao, cui):
        assert model.state_names == ["w", "p", "h_1"]
        assert model.algebraic_names == ["q_1"]
        assert list(model.u) == ["p_cmd", "load_torque"]
    assert liao.orientation == "spring_applied" and cui.orientation == "pressure_applied"
    # Liao Table 2: 318 N m at 1500 r/min is 50 kW; cylinder 80/112 mm
    assert liao.rated_torque * liao.rated_speed == pytest.approx(49.95e3, rel=1e-3)
    assert liao.piston_area == pytest.approx(math.pi * (0.112**2 - 0.08**2), rel=1e-12)


def test_smooth_film_torque_is_liao_eq2_without_roughness():
    """No roughness, no contact: lands (Cui Eq. 9, Newtonian) + grooves = Liao Eq. 2 exactly."""
    raw = load_scene("liao2021_hvd").raw
    raw = {k: dict(v) for k, v in raw.items() if k not in ("roughness", "contact", "friction")}
    scene = load_scene("liao2021_hvd").__class__(raw)
    film = HvdFilm(scene)
    h, w = np.array([20e-6, 100e-6, 300e-6]), 80.0
    expected = grooved_viscous_torque(w, h, 0.021, 0.11, 0.16, 0.3e-3, 2.0)
    np.testing.assert_allclose(film.torque(h, w), expected, rtol=1e-13)


def test_rough_film_tends_to_liao_eq2_for_thick_films(liao):
    """With roughness the land shear factor phi_f -> 1 + 1/H^2 (Patir-Cheng), so thick films approach Eq. 2."""
    h = 50 * liao.film.sigma
    expected = grooved_viscous_torque(50.0, h, 0.021, 0.11, 0.16, 0.3e-3, 2.0)
    assert float(liao.film.torque(h, 50.0)) == pytest.approx(expected, rel=1.5e-3)


def test_film_symbolic_equals_numeric(cui):
    h, dh, w = ca.SX.sym("h"), ca.SX.sym("dh"), ca.SX.sym("w")
    film = cui.film
    f = ca.Function("f", [h, dh, w], [film.load(h, dh, cui.w_in, w), film.torque(h, cui.w_in - w)])
    for hv, dv, wv in ((12e-6, -1e-6, 80.0), (30e-6, 2e-6, 40.0), (150e-6, 0.0, 10.0)):
        load, torque = (float(v) for v in f(hv, dv, wv))
        assert load == pytest.approx(float(film.load(hv, dv, cui.w_in, wv)), rel=1e-12)
        assert torque == pytest.approx(float(film.torque(hv, cui.w_in - wv)), rel=1e-12)


def test_smooth_clamp_error_bound():
    """softplus(x) - max(x, 0) = w ln(1 + exp(-|x|/w)) <= w exp(-|x|/w): exact away from the corners."""
    lo, hi, width = 0.1e6, 1e6, 0.01e6
    x = np.array([-1e6, 0.05e6, 0.1e6, 0.5e6, 0.95e6, 1e6, 2e6])
    distance = np.minimum(np.abs(x - lo), np.abs(x - hi))
    bound = width * np.minimum(np.exp(-distance / width), math.log(2)) * (1 + 1e-9) + 1e-9
    assert np.all(np.abs(smooth_clamp(x, lo, hi, width) - np.clip(x, lo, hi)) <= bound)


def test_cylinder_force_is_the_integral_of_the_rotating_oil_pressure(liao):
    """Liao Eq. 15 F_l = int_R1^R2 rho w^2 (r^2 - r0^2)/2 2 pi r dr (scipy quadrature)."""
    w, rho, (R1, R2), r0 = 120.0, liao.film.rho, liao.cylinder_radii, liao.control_oil_radius
    integral, _ = quad(lambda r: rho * w**2 * (r**2 - r0**2) / 2 * 2 * math.pi * r, R1, R2, epsabs=0, epsrel=1e-13)
    assert liao.cylinder_force(w) == pytest.approx(integral, rel=1e-12)


@pytest.mark.parametrize("name", ["liao2021_hvd", "cui2019_hvd"])
@pytest.mark.parametrize("fraction", [0.4, 0.6, 0.9])
def test_operating_point_balances_torque_and_forces(name, fraction, liao, cui):
    model = liao if name == "liao2021_hvd" else cui
    op = operating_point(model, fraction * model.rated_speed)
    h, w, p = op.films[0], op.speed, op.pressure
    torque = model.n * float(model.film.torque(h, model.w_in - w))
    assert torque == pytest.approx(model.load_coefficient * w**2, rel=1e-9)
    # film load (no squeeze) = closing force of Liao Eq. 15, written out independently
    k, x0 = model.spring_rate, model.spring_preload
    hydraulic = p * model.piston_area + model.cylinder_force(w)
    close = (k * (x0 + model.n * h) - hydraulic if model.orientation == "spring_applied"
             else hydraulic - k * (x0 + model.open_clearance - model.n * h))
    force_scale = model.p_max * model.piston_area
    assert float(model.film.load(h, 0.0, model.w_in, w)) == pytest.approx(close, rel=1e-8, abs=1e-9 * force_scale)
    dx, _, _ = model.evaluate(op.x, op.u)
    assert op.within_limits and abs(dx[2]) < 1e-15 and abs(dx[0]) < 1e-9


@pytest.mark.parametrize("name", ["liao2021_hvd", "cui2019_hvd"])
def test_static_map_runs_from_viscous_to_mixed_friction(name, liao, cui):
    model = liao if name == "liao2021_hvd" else cui
    data = static_map(model)
    speed, p = data["speed_rad_s"], data["pressure_Pa"]
    assert np.all(np.diff(speed) > 0)                                   # thinner films, faster output
    closing = 1 if model.orientation == "pressure_applied" else -1      # and more (less) pressure
    assert np.all(closing * np.diff(p) > 0)
    share = data["contact_torque_Nm"] / (data["contact_torque_Nm"] + data["viscous_torque_Nm"])
    assert share[0] < 1e-6 and share[-1] > 0.95                        # viscous -> mixed friction
    inside = data["within_valve_range"] > 0
    assert speed[inside].min() < 0.4 * model.rated_speed and speed[inside].max() > 0.9 * model.rated_speed


def test_rest_state_balances_the_films(cui):
    x = rest_state(cui, cui.p_min)
    # pressure-applied at the lift-off pressure: the piston just leaves its stop, films open
    assert x[2] == pytest.approx(cui.open_clearance, rel=1e-3)
    dx, _, _ = cui.evaluate(x, [cui.p_min, 0.0])
    assert abs(dx[2]) < 1e-12 and dx[0] > 0                            # films at rest, output accelerates


def test_unequal_films_follow_liao_eq13_when_contact_is_negligible():
    """With [hvc] and thick films, each plate balance reduces to Liao Eq. 13 (trailing friction)."""
    # the centrifugal film term is divided by the flow factor phi_r(H), which Liao takes equal for all films
    model = HvdModel(load_scene("liao2021_hvd", overrides={**LIAO_FILMS, "film.centrifugal": False}))
    data = static_map(model, n_points=6, film_range=(150e-6, 60e-6))
    for films in data["films_m"]:
        expected = hvc.film_distribution(films[0], 5, 0.3e-3, 2.0, 1e5).ravel()
        np.testing.assert_allclose(films, expected, rtol=1e-6)
        assert np.all(np.diff(films) > 0)                                # back films thicker (Liao Sec. 4)


def test_model_errors_name_the_field():
    with pytest.raises(ModelError, match="kind = 'hvd'"):
        HvdModel(load_scene("cui2019"))
    with pytest.raises(ModelError, match="hvd.pressure_min"):
        HvdModel(load_scene("cui2019_hvd", overrides={"hvd.pressure_min": "2 MPa"}))
    with pytest.raises(ModelError, match="hvd.spline_friction"):
        HvdModel(load_scene("liao2021_hvd", overrides={"hvc.friction_ratio": 1e5, "hvc.first_film": 1e-4}))
    with pytest.raises(ModelError, match="plates.land_fraction"):
        HvdModel(load_scene("liao2021_hvd", overrides={"plates.land_fraction": 0.5}))
    with pytest.raises(ModelError, match="operating speed"):
        operating_point(HvdModel(load_scene("cui2019_hvd")), 200.0)
