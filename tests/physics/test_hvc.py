"""Tests of clutchocp.physics.hvc (Liao 2021 film distribution and revised torque)."""

import casadi as ca
import numpy as np
import pytest
from hypothesis import given, reject, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

from clutchocp.errors import ModelError
from clutchocp.physics.hvc import (film_balance_residual, film_distribution, friction_load_factor,
                                   groove_load_factor, modified_factors, revised_torque)
from clutchocp.physics.shear import grooved_viscous_torque

MM = 1e-3
PER_MM2 = 1e6
# Liao 2021 Table 1
R1, R2, ETA, DW = 0.11, 0.16, 0.021, 100.0
H_A, K2, KAPPA = 0.3 * MM, 2.0, 0.1 * PER_MM2


def g(x, h_a=H_A, k2=K2):
    return x**3 + k2 * (x + h_a) ** 3


def f(x, h_a=H_A, k2=K2):
    return k2 / x + 1 / (x + h_a)


def test_load_factors_are_liao_eq9_and_eq11():
    x = 0.12 * MM
    assert groove_load_factor(x, H_A, K2) == pytest.approx(1 / g(x), rel=1e-15)
    assert friction_load_factor(x, H_A, K2) == pytest.approx(f(x), rel=1e-15)


@pytest.mark.parametrize("friction_film", ["trailing", "leading"])
def test_no_static_friction_gives_equal_films(friction_film):
    films = film_distribution(0.13 * MM, 6, H_A, K2, 0.0, friction_film=friction_film)
    np.testing.assert_allclose(films, 0.13 * MM, rtol=1e-15)


def test_trailing_recursion_against_brentq():
    """Second method: solve 1/g(x_i) = 1/g(x_{i+1}) + kappa f(x_{i+1}) film by film with brentq."""
    films = film_distribution(0.12 * MM, 5, H_A, K2, KAPPA)
    x = [0.12 * MM]
    for _ in range(4):
        c = 1 / g(x[-1])
        x.append(brentq(lambda y: 1 / g(y) + KAPPA * f(y) - c, x[-1], 1.0, xtol=1e-18, rtol=1e-15))
    np.testing.assert_allclose(films, x, rtol=1e-12)


def test_leading_recursion_is_eq13_as_printed():
    """Eq. 13 as printed: 1/g(x_{i+1}) = 1/g(x_i) - kappa f(x_i), explicit in 1/g."""
    films = film_distribution(0.12 * MM, 5, H_A, K2, KAPPA, friction_film="leading")
    for a, b in zip(films[:-1], films[1:]):
        assert 1 / g(b) == pytest.approx(1 / g(a) - KAPPA * f(a), rel=1e-12)
        assert film_balance_residual(a, b, H_A, K2, KAPPA, friction_film="leading") == pytest.approx(
            0.0, abs=1e-12 / g(a))


def test_leading_without_solution_raises():
    # friction term larger than the whole film load: 1/g(x2) would have to be negative
    with pytest.raises(ModelError, match="exceeds the film load"):
        film_distribution(0.3 * MM, 5, H_A, K2, 10 * PER_MM2, friction_film="leading")


@settings(max_examples=60, deadline=None)
@given(first=st.floats(0.02, 0.5), h_a=st.floats(0.0, 0.6), k2=st.floats(0.5, 4.0),
       kappa=st.floats(0.001, 0.3), n=st.integers(2, 8))
def test_films_grow_along_the_pack_and_balance(first, h_a, k2, kappa, n):
    """Liao Sec. 4: with static friction every film is thicker than the one before."""
    try:
        films = film_distribution(first * MM, n, h_a * MM, k2, kappa * PER_MM2)
    except ModelError as exc:   # only a genuine runaway (checked below) may stop the recursion
        assert "run away" in str(exc)
        reject()
    assert np.all(np.diff(films) > 0)
    for a, b in zip(films[:-1], films[1:]):
        r = film_balance_residual(a, b, h_a * MM, k2, kappa * PER_MM2)
        assert abs(r) <= 1e-10 * groove_load_factor(a, h_a * MM, k2)


def test_runaway_films_raise_and_are_genuine():
    """First film 0.5 mm, h_a 0.5 mm, K2 1, K3/K1 0.25/mm^2: each film ~ the cube of the one before."""
    args = (0.5 * MM, 8, 0.5 * MM, 1.0, 0.25 * PER_MM2)
    with pytest.raises(ModelError, match="run away"):
        film_distribution(*args)
    films = film_distribution(0.5 * MM, 6, 0.5 * MM, 1.0, 0.25 * PER_MM2, max_film=1e6)
    assert films[4] > 0.1 and films[5] > 1e3     # a 0.2 m, then a 8.6 km "film"
    x = [0.5 * MM]                                # second method for the first five films
    for _ in range(4):
        c = 1 / g(x[-1], 0.5 * MM, 1.0)
        x.append(brentq(lambda y: 1 / g(y, 0.5 * MM, 1.0) + 0.25 * PER_MM2 * f(y, 0.5 * MM, 1.0) - c,
                        x[-1], 10.0, xtol=1e-18, rtol=1e-14))
    np.testing.assert_allclose(films[:5], x, rtol=1e-12)


def test_more_friction_more_spread():
    growth = [film_distribution(0.12 * MM, 5, H_A, K2, k * PER_MM2)[-1] / (0.12 * MM)
              for k in (0.05, 0.1, 0.15)]
    assert growth[0] < growth[1] < growth[2]


def test_table3_alpha_pattern_in_mm_units():
    """Liao Table 3 rows 3 and 4: first film from the table (original-formula torque inverted,
    divided by alpha_1); the trailing recursion with K3/K1 in 1/mm^2 gives the other alphas."""
    for t_orig, h_a, k2, alphas, tol in ((31.8, 0.35 * MM, 2.0, (1.33, 0.98, 0.74, 0.56, 0.41), 0.035),
                                         (45.3, 0.30 * MM, 1.5, (1.00, 0.86, 0.74, 0.65, 0.57), 0.015)):
        sigma_bar = brentq(lambda h: grooved_viscous_torque(DW, h, ETA, R1, R2, h_a, k2, 5) - t_orig, 1e-6, 1e-2)
        films = film_distribution(sigma_bar / alphas[0], 5, h_a, k2, 0.1 * PER_MM2)
        np.testing.assert_allclose(sigma_bar / films, alphas, rtol=tol)


def test_modified_factors():
    films = np.array([0.1, 0.12, 0.15, 0.2]) * MM
    alpha, mean = modified_factors(films)
    assert mean == pytest.approx(films.mean(), rel=1e-15)
    assert np.sum(1 / alpha) == pytest.approx(len(films), rel=1e-14)
    alpha, _ = modified_factors([0.1 * MM] * 3)
    np.testing.assert_allclose(alpha, 1.0, rtol=1e-15)


def test_revised_torque_is_sum_of_film_torques():
    """Eq. 14 (alpha form) = sum over films of Liao Eq. 2 with n = 1 (shear.grooved_viscous_torque)."""
    films = film_distribution(0.1 * MM, 5, H_A, K2, KAPPA)
    expected = sum(grooved_viscous_torque(DW, h, ETA, R1, R2, H_A, K2) for h in films)
    assert revised_torque(DW, films, ETA, R1, R2, H_A, K2) == pytest.approx(expected, rel=1e-13)


def test_revised_torque_equal_films_is_n_times_eq2_and_eq1():
    h = 0.15 * MM
    t = revised_torque(DW, [h] * 5, ETA, R1, R2, H_A, K2)
    assert t == pytest.approx(grooved_viscous_torque(DW, h, ETA, R1, R2, H_A, K2, 5), rel=1e-14)
    # no grooves: Liao Eq. 1, T = n pi mu dw (r2^4 - r1^4) / (2 sigma)
    t1 = revised_torque(DW, [h] * 5, ETA, R1, R2, 0.0, K2)
    assert t1 == pytest.approx(5 * np.pi * ETA * DW * (R2**4 - R1**4) / (2 * h), rel=1e-14)


def test_unequal_films_transmit_more_than_their_mean():
    """1/h is convex: unequal films carry more torque than n films of the mean thickness."""
    films = film_distribution(0.1 * MM, 5, H_A, K2, KAPPA)
    assert revised_torque(DW, films, ETA, R1, R2, H_A, K2) > grooved_viscous_torque(
        DW, films.mean(), ETA, R1, R2, H_A, K2, 5)


@pytest.mark.parametrize("friction_film", ["trailing", "leading"])
def test_symbolic_equals_numeric(friction_film):
    first, kappa = ca.SX.sym("first"), ca.SX.sym("kappa")
    films = film_distribution(first, 5, H_A, K2, kappa, friction_film=friction_film)
    fn = ca.Function("films", [first, kappa],
                     [ca.vertcat(*films), revised_torque(DW, films, ETA, R1, R2, H_A, K2)])
    f_sym, t_sym = fn(0.11 * MM, KAPPA)
    f_num = film_distribution(0.11 * MM, 5, H_A, K2, KAPPA, friction_film=friction_film)
    np.testing.assert_allclose(np.array(f_sym).ravel(), f_num, rtol=1e-12)
    assert float(t_sym) == pytest.approx(revised_torque(DW, f_num, ETA, R1, R2, H_A, K2), rel=1e-12)


def test_array_first_film():
    firsts = np.array([0.08, 0.1, 0.14]) * MM
    films = film_distribution(firsts, 4, H_A, K2, KAPPA)
    assert films.shape == (4, 3)
    for j, x in enumerate(firsts):
        np.testing.assert_allclose(films[:, j], film_distribution(x, 4, H_A, K2, KAPPA), rtol=1e-14)


def test_invalid_input():
    with pytest.raises(ModelError):
        film_distribution(0.1 * MM, 0, H_A, K2, KAPPA)
    with pytest.raises(ModelError):
        film_distribution(0.1 * MM, 3, H_A, K2, KAPPA, friction_film="middle")
    with pytest.raises(ModelError, match="did not converge"):
        film_distribution(0.1 * MM, 3, H_A, K2, KAPPA, newton_steps=1)
