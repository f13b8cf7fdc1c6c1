"""Roughness per surface (roughness.sigma_1 of the friction plate, sigma_2 of the separator) in the
film laws of an engagement: Patir-Cheng's shear factor phi_fs = (V_r1 - V_r2) Phi_fs(H) (Cui Eq. 7-8),
V_ri = sigma_i^2 / sigma^2, reaches the viscous torque of Cui Eq. 9."""

import math

import numpy as np
import pytest
from scipy import special

from clutchocp.engagement.films import FilmLaw
from clutchocp.engagement.run import simulate_engagement
from clutchocp.physics.shear import shear_factor_phi_f
from clutchocp.scene.loader import load_scene

SIGMA = 8.41e-6                                   # Zhang Table 1, combined RMS [m]
EQUAL_SPLIT = {"roughness.sigma_1": f"{SIGMA / math.sqrt(2)} m", "roughness.sigma_2": f"{SIGMA / math.sqrt(2)} m"}
ROUGH_SEPARATOR = {"roughness.sigma_1": "0 m", "roughness.sigma_2": f"{SIGMA} m"}


def patir_cheng_Phi_fs(H):
    """Patir & Cheng (1979) isotropic shear-flow function, typed from Cui 2019 Eq. 8 (0 <= H <= 7)."""
    return 11.1 * H**2.31 * math.exp(-2.38 * H + 0.11 * H * H)


def hand_viscous_torque(film, h, w_rel, phi_fs):
    """Cui Eq. 9 with the average gap h_T = h Phi(H) + sigma phi(H) (Bao Eq. 10), from the film's data."""
    H = h / SIGMA
    h_T = h * special.ndtr(H) + SIGMA * math.exp(-0.5 * H * H) / math.sqrt(2 * math.pi)
    delta = float(film.area_ratio(h))
    return ((1 - delta) * (float(shear_factor_phi_f(H)) - phi_fs) * math.pi * 0.0681 * w_rel
            * (0.085**4 - 0.064**4) / (2 * h_T))


def test_zhang2021_puts_all_the_roughness_on_the_lining():
    scene = load_scene("zhang2021")
    assert scene.value("roughness.sigma_1") == SIGMA and scene.value("roughness.sigma_2") == 0.0
    assert scene.value("roughness.sigma") == pytest.approx(SIGMA, rel=1e-15)     # Table 1's combined RMS
    default = load_scene("default_driveline")
    assert default.value("roughness.sigma_1") == pytest.approx(SIGMA) and default.value("roughness.sigma_2") == 0.0


@pytest.mark.parametrize("H", [0.5, 1.0, 2.0, 4.0])
def test_equal_roughness_gives_phi_fs_zero(H):
    film = FilmLaw(load_scene("zhang2021").with_overrides(EQUAL_SPLIT))
    h = H * SIGMA
    assert float(film.viscous_torque(h, 1000.0)) == pytest.approx(hand_viscous_torque(film, h, 1000.0, 0.0), rel=1e-12)


@pytest.mark.parametrize("H", [0.5, 1.0, 2.0, 4.0])
def test_one_smooth_surface_gives_patir_chengs_phi_fs(H):
    """Lining rough, separator smooth (the scene): V_r1 - V_r2 = 1, phi_fs = +Phi_fs(H), the torque
    falls; roughness on the separator instead: phi_fs = -Phi_fs(H), the torque rises by as much."""
    h = H * SIGMA
    lining = FilmLaw(load_scene("zhang2021"))
    separator = FilmLaw(load_scene("zhang2021").with_overrides(ROUGH_SEPARATOR))
    Phi = patir_cheng_Phi_fs(H)
    assert float(lining.viscous_torque(h, 1000.0)) == pytest.approx(hand_viscous_torque(lining, h, 1000.0, Phi), rel=1e-12)
    assert float(separator.viscous_torque(h, 1000.0)) == pytest.approx(hand_viscous_torque(separator, h, 1000.0, -Phi),
                                                                       rel=1e-12)


def test_combined_roughness_override_keeps_the_split():
    one_sided = load_scene("zhang2021").with_overrides({"roughness.sigma": "9.25 um"})
    assert one_sided.value("roughness.sigma_1") == pytest.approx(9.25e-6) and one_sided.value("roughness.sigma_2") == 0
    mixed = load_scene("zhang2021").with_overrides({"roughness.sigma_1": "3 um", "roughness.sigma_2": "4 um"})
    doubled = mixed.with_overrides({"roughness.sigma": "10 um"})
    assert doubled.value("roughness.sigma_1") == pytest.approx(6e-6) and doubled.value("roughness.sigma_2") == pytest.approx(8e-6)
    assert doubled.value("roughness.sigma") == pytest.approx(10e-6)
    # both surfaces on a scene that gives the combined sigma replace it
    split = load_scene("bao2020").with_overrides({"roughness.sigma_1": "6 um", "roughness.sigma_2": "8 um"})
    assert split.value("roughness.sigma") == pytest.approx(10e-6) and split.value("roughness.sigma_2") == 8e-6


def test_a_rough_lining_on_a_smooth_separator_lowers_the_viscous_peak():
    """zhang2021's viscous peak: 613 N m with the roughness split equally (phi_fs = 0), 255 N m with
    the lining rough alone (phi_fs = Phi_fs, up to 1.15 near H = 1 against phi_f = 1.64 there)."""
    grid = {"t_end": 0.4, "output_points": 4001}
    equal = simulate_engagement(load_scene("zhang2021").with_overrides(EQUAL_SPLIT), **grid).summary
    lining = simulate_engagement(load_scene("zhang2021"), **grid).summary
    assert equal["peak_torque_Nm"] == pytest.approx(613, rel=5e-3)
    assert lining["peak_torque_Nm"] == pytest.approx(255, rel=5e-3)
    # the axial side is untouched: the same equations, equal to the integration tolerance (rtol 1e-8)
    assert np.isclose(lining["stable_torque_Nm"], equal["stable_torque_Nm"], rtol=1e-7)


def test_the_viscous_torque_of_one_rough_surface_is_continuous_at_the_phi_fs_cutoff():
    """Cui Eq. 8 cuts Phi_fs to 0 above H = 7, a jump of 0.0127 against phi_f = 1.02: the film law
    uses the smooth cut, so the torque is continuous there (exact cut: a 1.2 % step), and equals the
    exact form to 5e-5 below H = 6.5 and 1e-6 (absolute, in phi_fs) above 7.5."""
    film = FilmLaw(load_scene("zhang2021"))
    below, above = float(film.viscous_torque(7 * SIGMA * (1 - 1e-9), 1000.0)), float(film.viscous_torque(7 * SIGMA * (1 + 1e-9), 1000.0))
    assert below == pytest.approx(above, rel=1e-7)
    for H, tol in ((6.5, 5e-5), (7.5, 1e-6)):
        exact = hand_viscous_torque(film, H * SIGMA, 1000.0, patir_cheng_Phi_fs(H) if H <= 7 else 0.0)
        assert float(film.viscous_torque(H * SIGMA, 1000.0)) == pytest.approx(exact, rel=tol)
