"""The kinematic lower bound of the jerk integral: closed form, end conditions, minimality."""

import itertools

import numpy as np
import pytest
from scipy import integrate

from clutchocp.errors import ModelError
from clutchocp.optimal.bound import (
    jerk_lower_bound,
    minimum_jerk_coefficients,
    minimum_jerk_slip,
    output_jerk_share,
)
from clutchocp.scene import default_scene

CASES = [(150.0, 533.0, 0.212, 0.0, 0.0), (1.0, 0.0, 1.0, 0.0, 0.0), (0.0, 2.0, 0.5, 0.0, 0.0),
         (80.0, -40.0, 0.3, 5.0, -3.0)]


@pytest.mark.parametrize("y0, v0, T, y1, v1", CASES)
def test_cubic_meets_the_end_conditions(y0, v0, T, y1, v1):
    a, b = minimum_jerk_coefficients(y0, v0, T, y1, v1)
    y = lambda t: y0 + v0 * t + a * t**2 + b * t**3
    dy = lambda t: v0 + 2 * a * t + 3 * b * t**2
    assert y(T) == pytest.approx(y1, abs=1e-9 * max(1.0, abs(y0)))
    assert dy(T) == pytest.approx(v1, abs=1e-9 * max(1.0, abs(v0)))


@pytest.mark.parametrize("y0, v0, T, y1, v1", CASES)
def test_closed_form_equals_quadrature_of_the_cubic(y0, v0, T, y1, v1):
    _, ddy = minimum_jerk_slip(np.array([0.0]), y0, v0, T, y1, v1)
    a, b = minimum_jerk_coefficients(y0, v0, T, y1, v1)
    ref, _ = integrate.quad(lambda t: (2 * a + 6 * b * t) ** 2, 0.0, T, epsabs=0, epsrel=1e-13)
    assert jerk_lower_bound(y0, v0, T, y1, v1) == pytest.approx(ref, rel=1e-11)
    assert ddy[0] == pytest.approx(2 * a)


def test_lock_up_form_of_the_bound():
    """y1 = v1 = 0: J = 4 (3 y0^2 + 3 y0 v0 T + v0^2 T^2) / T^3 (PHYSICS/DESIGN: a cubic in closed form)."""
    y0, v0, T = 150.0, 533.0, 0.212
    assert jerk_lower_bound(y0, v0, T) == pytest.approx(4 * (3 * y0**2 + 3 * y0 * v0 * T + v0**2 * T**2) / T**3,
                                                        rel=1e-13)


@pytest.mark.parametrize("shape", [np.poly1d([1, 0, 0]) * np.poly1d([-1, 1]) ** 2,
                                   np.poly1d([1, 0, 0]) * np.poly1d([-1, 1]) ** 3 * np.poly1d([4, 1]),
                                   np.poly1d([1, 0, 0, 0]) * np.poly1d([-1, 1]) ** 2])
def test_any_admissible_perturbation_raises_the_integral(shape):
    """y + eps e(t/T) with e = e' = 0 at both ends is admissible: the first variation vanishes and
    J grows by eps^2 int e''^2 (polynomials integrated exactly)."""
    y0, v0, T = 150.0, 533.0, 0.212
    a, b = minimum_jerk_coefficients(y0, v0, T)
    ddy = np.poly1d([6 * b, 2 * a])
    e = shape(np.poly1d([1.0 / T, 0.0]))                  # e(t / T) as a polynomial in t
    assert e(0.0) == e.deriv()(0.0) == 0.0 and abs(e(T)) < 1e-12 and abs(e.deriv()(T)) < 1e-9
    dde = e.deriv(2)
    cross = (ddy * dde).integ()(T)
    base = jerk_lower_bound(y0, v0, T)
    assert abs(cross) < 1e-9 * np.sqrt(base * (dde * dde).integ()(T))
    for eps in (-5.0, 1.0, 20.0):
        perturbed = ((ddy + eps * dde) ** 2).integ()(T)
        assert perturbed > base
        assert perturbed == pytest.approx(base + eps**2 * (dde * dde).integ()(T), rel=1e-9)


def test_bound_falls_with_engagement_time():
    values = [jerk_lower_bound(150.0, 533.0, T) for T in (0.1, 0.2, 0.4, 0.8)]
    assert all(later < earlier for earlier, later in itertools.pairwise(values))


def test_output_share_of_the_default_driveline():
    scene = default_scene()
    I_in, I_out = scene.value("driveline.input_inertia"), scene.value("driveline.output_inertia")
    assert output_jerk_share(scene) == pytest.approx(I_in / (I_in + I_out))


def test_nonpositive_time_is_a_model_error():
    with pytest.raises(ModelError, match="engagement time"):
        jerk_lower_bound(1.0, 0.0, 0.0)
    with pytest.raises(ModelError, match="engagement time"):
        minimum_jerk_coefficients(1.0, 0.0, -1.0)
