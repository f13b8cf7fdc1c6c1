"""Tests of clutchocp.physics.rough_wall_flow (film over a rough wall, smooth wall sliding)."""

import numpy as np
import pytest

from clutchocp.physics.rough_wall_flow import (SHEAR_CUTOFF_GAP, cosine_wall_closed_form, gaussian_wall,
                                               periodic_wall_flow_1d, solve_film, transmitted_shear_ensemble,
                                               wall_from_samples)

# ------------------------------------------------------------------------------ 1D, exact


def cosine_gap(eps, n=256, h0=1.0):
    x = 2 * np.pi * np.arange(n) / n
    return x, h0 * (1 + eps * np.cos(x))


def test_cosine_wall_review_numbers():
    # smooth-wall drag and rough-wall viscous shear in units of eta U E[1/h]
    for eps, smooth, rough in [(0.1, 1.015, 0.985), (0.3, 1.129, 0.871), (0.5, 1.333, 0.667)]:
        c = cosine_wall_closed_form(eps)
        assert round(float(c.smooth_drag), 3) == smooth
        assert round(float(c.rough_viscous), 3) == rough


@pytest.mark.parametrize("eps", [0.1, 0.3, 0.5, 0.9])
def test_cosine_wall_quadrature_equals_closed_form(eps):
    _, h = cosine_gap(eps, n=512)
    h0, U, eta = 2e-6, 3.0, 0.04
    r = periodic_wall_flow_1d(h0 * h, speed=U, eta=eta)
    unit = eta * U / (h0 * np.sqrt(1 - eps**2))            # eta U E[1/h]
    c = cosine_wall_closed_form(eps)
    assert r.couette / unit == pytest.approx(1.0, rel=1e-12)
    assert r.smooth_drag / unit == pytest.approx(float(c.smooth_drag), rel=1e-12)
    assert r.rough_viscous / unit == pytest.approx(float(c.rough_viscous), rel=1e-12)
    assert r.form_drag / unit == pytest.approx(float(c.form_drag), rel=1e-12)


def test_general_1d_wall_pressure_on_flanks_balances_shear():
    # a non-symmetric periodic wall; the form drag is evaluated here from the pressure itself
    # (integrated from p_x = 6 eta U/h^2 - 12 eta q/h^3) and the wall slope, independently of
    # the function's closed form, and must close the momentum balance to round-off
    n = 4096
    x = 2 * np.pi * np.arange(n) / n
    h = 1.0 + 0.3 * np.cos(x) + 0.2 * np.sin(3 * x) + 0.1 * np.cos(5 * x + 0.4)
    r = periodic_wall_flow_1d(h)
    q = 0.5 * np.mean(h**-2) / np.mean(h**-3)
    k = np.fft.fftfreq(n, d=1.0 / n)
    px = 6 / h**2 - 12 * q / h**3
    assert abs(np.mean(px)) < 1e-13                          # periodic pressure
    px_hat = np.fft.fft(px)
    px_hat[0] = 0.0
    p = np.real(np.fft.ifft(np.where(k == 0, 0.0, px_hat / (1j * np.where(k == 0, 1, k)))))
    hx = np.real(np.fft.ifft(1j * k * np.fft.fft(h)))
    form_drag = np.mean(-p * hx)
    assert form_drag == pytest.approx(r.form_drag, rel=1e-11)
    assert r.rough_viscous + form_drag == pytest.approx(r.smooth_drag, rel=1e-11)
    assert r.smooth_drag == pytest.approx(r.couette + r.form_drag / 2, rel=1e-13)
    assert r.form_drag > 0


def test_cosine_wall_small_amplitude_limit():
    # form drag = 3 eps^2 + O(eps^4); both walls -> Couette
    for eps in (1e-2, 1e-3):
        c = cosine_wall_closed_form(eps)
        assert float(c.form_drag) / eps**2 == pytest.approx(3.0, rel=eps**2)
        assert (float(c.smooth_drag) - 1) / eps**2 == pytest.approx(1.5, rel=2 * eps**2)
        assert (1 - float(c.rough_viscous)) / eps**2 == pytest.approx(1.5, rel=2 * eps**2)
    _, h = cosine_gap(0.0)
    r = periodic_wall_flow_1d(h)
    assert r.smooth_drag == r.rough_viscous == r.couette == 1.0 and r.form_drag == 0.0


def test_1d_rejects_touching_wall():
    with pytest.raises(ValueError, match="positive"):
        periodic_wall_flow_1d([1.0, 0.5, 0.0, 0.5])


# ------------------------------------------------------------------------------ 2D surfaces


def wall_1d(profile, m=16, along="x"):
    """A 2D wall varying along one axis only, heights profile(x) sampled at m corner points."""
    s = np.arange(m) * 2 * np.pi / m
    heights = np.tile(profile(s)[:, None], (1, m))
    return wall_from_samples(heights if along == "x" else heights.T, 2 * np.pi)


def test_gaussian_wall_statistics():
    wall = gaussian_wall(16.0, np.random.default_rng(3))
    assert wall.rms() == pytest.approx(1.0, rel=1e-14)
    s = wall.on_grid(128)
    assert np.mean(s.centre) == pytest.approx(0.0, abs=1e-14)
    assert np.std(s.centre) == pytest.approx(1.0, rel=1e-12)     # band-limited: grid RMS = series RMS
    # autocorrelation exp(-r^2 / lambda^2) and RMS slope sqrt(2) sigma / lambda, over 100 walls of
    # 32 x 32 lambda (sampling noise ~0.004; the zero-mean bias -pi lambda^2 / L^2 = -0.003)
    lags = np.array([2, 4, 8])                                   # 0.5, 1, 2 lambda at 4 cells / lambda
    acf, slope2 = np.zeros(3), 0.0
    for k in range(100):
        g = gaussian_wall(32.0, np.random.default_rng(100 + k)).on_grid(128)
        acf += [np.mean(g.centre * np.roll(g.centre, lag, axis=0)) for lag in lags]
        slope2 += np.mean(g.slope_x**2)
    np.testing.assert_allclose(acf / 100, np.exp(-(lags / 4.0) ** 2), atol=0.015)
    assert np.sqrt(slope2 / 100) == pytest.approx(np.sqrt(2), rel=0.01)


def test_wall_on_grid_is_its_fourier_series():
    wall = gaussian_wall(4.0, np.random.default_rng(7))
    m = wall.coefficients.shape[0]
    waves = np.fft.fftfreq(m) * m * 2 * np.pi / wall.length
    n = 40
    s = wall.on_grid(n)
    d = wall.length / n

    def series(x, y):
        return np.real(np.sum(wall.coefficients * np.exp(1j * (waves[:, None] * x + waves[None, :] * y))))

    def series_dx(x, y):
        return np.real(np.sum(1j * waves[:, None] * wall.coefficients
                              * np.exp(1j * (waves[:, None] * x + waves[None, :] * y))))

    for i, j in [(0, 0), (3, 17), (39, 5)]:
        assert s.centre[i, j] == pytest.approx(series((i + 0.5) * d, (j + 0.5) * d), abs=1e-12)
        assert s.x_face[i, j] == pytest.approx(series((i + 1) * d, (j + 0.5) * d), abs=1e-12)
        assert s.y_face[i, j] == pytest.approx(series((i + 0.5) * d, (j + 1) * d), abs=1e-12)
        assert s.slope_x[i, j] == pytest.approx(series_dx((i + 0.5) * d, (j + 0.5) * d), abs=1e-11)
    with pytest.raises(ValueError, match="coarser"):
        wall.on_grid(m - 2)


# ------------------------------------------------------------------------------ 2D Reynolds


def test_2d_solver_reproduces_exact_1d_cosine_wall():
    eps, H = 0.5, 1.0
    wall = wall_1d(lambda x: -eps * np.cos(x))               # gap H (1 + eps cos x)
    c = cosine_wall_closed_form(eps)
    unit = 1 / np.sqrt(1 - eps**2)                           # E[1/h]
    errors = {"smooth_drag": [], "rough_viscous": [], "form_drag": []}
    for n in (32, 64, 128):
        r = solve_film(wall.on_grid(n), H, cutoff=0.0)
        # the face evaluation is exact here (constant flux, trapezoidal means of a cosine)
        assert r.smooth_drag_faces / unit == pytest.approx(float(c.smooth_drag), rel=1e-12)
        for field in errors:
            errors[field].append(abs(getattr(r, field) / unit - float(getattr(c, field))))
    # the velocity-averaged shears and the pressure-on-flank form drag converge at second order
    for e in errors.values():
        assert e[0] / e[1] == pytest.approx(4, rel=0.05)
        assert e[1] / e[2] == pytest.approx(4, rel=0.05)
        assert e[2] < 2e-4


def test_longitudinal_ridges_carry_no_pressure():
    # a wall varying across the sliding direction only: pure Couette on every strip
    wall = wall_1d(lambda y: 0.6 * np.cos(y) + 0.2 * np.sin(2 * y), along="y")
    s = wall.on_grid(32)
    r = solve_film(s, 1.0, cutoff=0.0)
    couette = np.mean(1 / (1.0 - s.centre))
    assert r.smooth_drag == pytest.approx(couette, rel=1e-13)
    assert r.rough_viscous == pytest.approx(couette, rel=1e-13)
    assert abs(r.form_drag) < 1e-13 and abs(r.poiseuille) < 1e-13


def test_small_amplitude_checkerboard_form_drag():
    # delta = a cos(kx x) cos(ky y): p = -6 a kx sin(kx x) cos(ky y) / (H^3 k^2) to first order,
    # form drag mean(p d(delta)/dx) = 1.5 a^2 kx^2 / (H^3 k^2) (+ O(a^4))
    a, H, kx, ky = 0.01, 1.0, 1, 2
    m = 16
    s_ = np.arange(m) * 2 * np.pi / m
    wall = wall_from_samples(a * np.cos(kx * s_)[:, None] * np.cos(ky * s_)[None, :], 2 * np.pi)
    expected = 1.5 * a**2 * kx**2 / (H**3 * (kx**2 + ky**2))
    r = solve_film(wall.on_grid(128), H, cutoff=0.0)
    assert r.form_drag == pytest.approx(expected, rel=2e-3)
    assert r.smooth_drag - r.rough_viscous == pytest.approx(expected, rel=2e-3)


def test_random_wall_far_field_form_drag():
    # second order in sigma / h for any wall: form drag = 6 sum |c_k|^2 kx^2 / k^2 / H^3, which
    # is 3 / H^3 on average for an isotropic wall (half the transverse-ridge value)
    wall = gaussian_wall(8.0, np.random.default_rng(11))
    m = wall.coefficients.shape[0]
    k = np.fft.fftfreq(m) * m
    k2 = k[:, None] ** 2 + k[None, :] ** 2
    share = np.sum(np.abs(wall.coefficients) ** 2 * np.where(k2 > 0, k[:, None] ** 2 / np.where(k2 > 0, k2, 1), 0))
    assert share == pytest.approx(0.5, abs=0.1)
    s = wall.on_grid(64)
    for H in (20.0, 40.0):
        r = solve_film(s, H)
        assert r.form_drag * H**3 == pytest.approx(6 * share, rel=3 / H)
        assert (r.smooth_drag - r.couette) * H**3 == pytest.approx(3 * share, rel=3 / H)


def test_energy_balance_of_the_pressure_flow():
    # with contacts, trapped pockets and the shear cut-off: the solved pressure satisfies
    # mean(h^3 |grad p|^2 / 12) = mean((h/2) dp/dx) to round-off
    s = gaussian_wall(8.0, np.random.default_rng(5)).on_grid(64)
    for H in (0.25, 1.0, 2.0):
        r = solve_film(s, H)
        assert r.contact_fraction > 0
        assert r.dissipation == pytest.approx(r.poiseuille, rel=1e-9)
        assert r.poiseuille > 0


def test_momentum_balance_converges_without_contact():
    wall = gaussian_wall(8.0, np.random.default_rng(2))
    imbalance, faces_gap = [], []
    for n in (32, 64, 128):
        r = solve_film(wall.on_grid(n), 3.5)
        assert r.contact_fraction == 0
        imbalance.append(abs(r.rough_viscous + r.form_drag - r.smooth_drag) / r.smooth_drag)
        faces_gap.append(abs(r.smooth_drag_faces - r.smooth_drag) / r.smooth_drag)
    # second order: the error falls ~4x per halved cell
    for errors in (imbalance, faces_gap):
        assert errors[0] / errors[1] == pytest.approx(4, rel=0.15)
        assert errors[1] / errors[2] == pytest.approx(4, rel=0.15)
    assert imbalance[2] < 3e-3 and faces_gap[2] < 1e-3


def test_momentum_balance_converges_with_contact_lines():
    # with a cut-off gap the grid can resolve (0.3 sigma: pressure scale 0.3 / |grad delta| ~ 0.2
    # lambda), the pressure on the flanks and on the contact steps closes the balance as the
    # grid is refined, at first order (the staircase of the wetted region's edge); the two
    # evaluations of the transmitted stress converge together
    wall = gaussian_wall(4.0, np.random.default_rng(2))
    imbalance, faces_gap = [], []
    for n in (32, 64, 128):
        r = solve_film(wall.on_grid(n), 1.0, cutoff=0.3)
        assert 0.25 < r.contact_fraction < 0.35
        imbalance.append(abs(r.rough_viscous + r.form_drag - r.smooth_drag) / r.smooth_drag)
        faces_gap.append(abs(r.smooth_drag_faces - r.smooth_drag) / r.smooth_drag)
    for errors in (imbalance, faces_gap):
        assert errors[0] / errors[1] == pytest.approx(2, rel=0.25)
        assert errors[1] / errors[2] == pytest.approx(2, rel=0.25)
    assert imbalance[2] < 0.06 and faces_gap[2] < 0.03


def test_stresses_do_not_depend_on_the_correlation_length():
    # Reynolds lubrication is invariant under x, y -> c x, c y: same noise, lambda and the box
    # scaled together give the same stresses
    a = gaussian_wall(6.0, np.random.default_rng(9), correlation_length=1.0).on_grid(48)
    b = gaussian_wall(15.0, np.random.default_rng(9), correlation_length=2.5).on_grid(48)
    np.testing.assert_allclose(a.centre, b.centre, atol=1e-13)
    for H in (1.0, 3.0):
        ra, rb = solve_film(a, H), solve_film(b, H)
        for field in ("smooth_drag", "rough_viscous", "form_drag", "couette"):
            assert getattr(ra, field) == pytest.approx(getattr(rb, field), rel=1e-9)


def test_rejects_negative_cutoff():
    s = gaussian_wall(4.0, np.random.default_rng(0)).on_grid(16)
    with pytest.raises(ValueError, match="cutoff"):
        solve_film(s, 1.0, cutoff=-0.1)
    assert SHEAR_CUTOFF_GAP == pytest.approx(0.01)


@pytest.mark.slow
def test_transmitted_stress_converges_with_contact_lines():
    # at Cui's cut-off 0.01 sigma the pressure near contact lines varies on 0.007 lambda: the
    # depth-averaged-velocity evaluation converges on grids that do not resolve it (within 3 % at
    # 32 cells per lambda, the table's grid, 1.5 % at 64), the face evaluation creeps up towards it
    # (log of the cell)
    for seed in (3, 4):
        wall = gaussian_wall(4.0, np.random.default_rng(seed))
        runs = {cpl: [solve_film(wall.on_grid(4 * cpl), H) for H in (0.5, 1.0, 2.0)] for cpl in (32, 64, 128)}
        for cpl, tolerance in ((32, 0.03), (64, 0.015)):
            for coarse, fine in zip(runs[cpl], runs[128]):
                assert coarse.smooth_drag == pytest.approx(fine.smooth_drag, rel=tolerance)
        for coarse, fine in zip(runs[32], runs[128]):
            gap_coarse = fine.smooth_drag - coarse.smooth_drag_faces
            gap_fine = fine.smooth_drag - fine.smooth_drag_faces
            assert 0 < gap_fine < 0.75 * gap_coarse


def test_ensemble_needs_two_walls():
    with pytest.raises(ValueError, match="n_walls"):
        transmitted_shear_ensemble([3.0], 1)
