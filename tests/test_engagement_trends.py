"""The seed papers' parameter trends, one test per trend, as signs of finite differences.

Bao 2020 Section 4.3-4.6 (Figs 11-14) on bao2020, Zhang 2021 Section 3.1-3.5 (Figs 3-7) on
zhang2021. A trend the model does not reproduce is marked ``xfail(strict=True)`` with what the
model says and why (so it fails loudly if a change of the physics makes it come out); where the
mechanism can be pinned, a second test asserts it.
"""

import numpy as np
import pytest

from clutchocp.engagement.run import simulate_engagement
from clutchocp.scene.loader import load_scene


def bao(overrides, **kw):
    return simulate_engagement(load_scene("bao2020").with_overrides(overrides), **kw).summary


def zhang(overrides):
    return simulate_engagement(load_scene("zhang2021").with_overrides(overrides)).summary


# ------------------------------------------------------------------------------- Bao 2020
def test_bao_more_spring_preload_engages_sooner():
    # Fig. 11; measured 0.480 / 0.407 s
    assert bao({"piston.spring_preload": "0.044 m"})["engagement_time_s"] < \
        bao({"piston.spring_preload": "0.036 m"})["engagement_time_s"]


@pytest.mark.xfail(strict=True, reason=(
    "model: higher viscosity engages SOONER (0.449 s at 0.018 Pa s, 0.432 s at 0.022 Pa s). Bao's mechanism "
    "is there: more viscous oil drains more slowly, so at 20 ms the film is 7 % thicker and the asperity "
    "torque 45 % lower. But the 80 kN spring ends the squeeze stage after ~0.1 s of the 0.44 s engagement; "
    "from then on the film thickness, set by the spring force against asperity contact and the static film "
    "load (inlet pressure, centrifugal term), no longer depends on viscosity, and the viscous shear torque, "
    "proportional to viscosity and ~30 % of the clutch torque, transmits more. Bao's trend needs a squeeze "
    "stage that lasts a large part of the engagement (a weaker spring or a larger gap than the scene's)."))
def test_bao_higher_viscosity_engages_later():
    # Fig. 12
    assert bao({"oil.viscosity": "0.022 Pa s"})["engagement_time_s"] > \
        bao({"oil.viscosity": "0.018 Pa s"})["engagement_time_s"]


def test_bao_viscosity_slows_the_squeeze_but_adds_slip_torque():
    """What the model says instead of Fig. 12: with more viscous oil the film is thicker and the
    asperity torque lower early in the squeeze (20 ms), the film is the same once squeezed (0.1 %
    at 0.1 s and 0.2 s), and the viscous torque of the slip is higher (by 17 % at 0.2 s)."""
    runs = {eta: simulate_engagement(load_scene("bao2020").with_overrides({"oil.viscosity": eta})).result
            for eta in ("0.018 Pa s", "0.022 Pa s")}

    def at(eta, name, t):
        res = runs[eta]
        return res[name][np.searchsorted(res.t, t)]

    thin, thick = "0.018 Pa s", "0.022 Pa s"
    assert at(thick, "h_1_m", 0.02) > 1.05 * at(thin, "h_1_m", 0.02)
    assert at(thick, "contact_torque_Nm", 0.02) < 0.7 * at(thin, "contact_torque_Nm", 0.02)
    for t in (0.1, 0.2):
        assert at(thick, "h_1_m", t) == pytest.approx(at(thin, "h_1_m", t), rel=2e-3)
    assert at(thick, "viscous_torque_Nm", 0.2) > 1.1 * at(thin, "viscous_torque_Nm", 0.2)


@pytest.mark.xfail(strict=True, reason=(
    "model: a heavier friction plate engages LATER, by 1.1e-8 s of 0.44 s when its mass doubles "
    "(0.367 -> 0.734 kg; resolved at rtol 1e-10, where the lock time is good to 1e-11 s). Plate inertia "
    "acts only while the films are squeezed after the impact (its time constant m/K is microseconds); "
    "the slip, which sets the engagement time, does not see it. Bao too finds the difference 'not great'."))
def test_bao_heavier_friction_plate_engages_sooner():
    # Fig. 14; plate 2 is the friction plate (Bao Table 1 m2)
    tight = {"rtol": 1e-10, "atol": 1e-12}
    assert bao({"pack.plate_masses": ["0.367 kg", "0.734 kg"]}, **tight)["engagement_time_s"] < \
        bao({"pack.plate_masses": ["0.367 kg", "0.367 kg"]}, **tight)["engagement_time_s"]


@pytest.mark.xfail(strict=True, reason=(
    "model: with free travel (collision at 6.3 m/s) the lock-up torque jump is SMALLER (3120 vs 3160 N m). "
    "The piston meets the pack 0.5 mm further out, where the spring (2e6 N/m) pushes 1 kN less; the impact "
    "energy (6 J in the plastic impact plus the squeeze) is dissipated within milliseconds, long before "
    "lock-up. The scene's assumption that the free travel is taken from the spring compression drives it; "
    "at equal spring force on the pack the jump does not change (next test)."))
def test_bao_collision_velocity_raises_the_lockup_torque_peak():
    # Fig. 13: the initial velocity of the collision (Bao Eq. 22) included or not
    with_impact = bao({"piston.travel_to_pack": "0.5 mm"})["lockup_torque_jump_Nm"]
    without = bao({"piston.travel_to_pack": "0 m"})["lockup_torque_jump_Nm"]
    assert abs(with_impact) > abs(without)


def test_bao_collision_velocity_leaves_the_lockup_torque_unchanged_at_equal_spring_force():
    """What the model says instead of Fig. 13: with the spring force at first contact held equal
    (preload - travel = 39.5 mm), colliding at 6.3 m/s or starting at the pack at rest gives the same
    lock-up torque jump to 1e-6 (measured 1e-9) and a lock time within 1e-4 (measured 1.2e-5)."""
    collide = bao({"piston.travel_to_pack": "0.5 mm", "piston.spring_preload": "0.040 m"})
    rest = bao({"piston.travel_to_pack": "0 m", "piston.spring_preload": "0.0395 m"})
    assert [e["name"] for e in collide["events"]] == ["impact", "lockup"]
    assert [e["name"] for e in rest["events"]] == ["lockup"]
    assert collide["lockup_torque_jump_Nm"] == pytest.approx(rest["lockup_torque_jump_Nm"], rel=1e-6)
    assert collide["engagement_time_s"] == pytest.approx(rest["engagement_time_s"], rel=1e-4)


# ------------------------------------------------------------------------------- Zhang 2021
ZHANG_VISCOUS_PEAK = (
    "With Zhang's Table 1 (eta = 0.0681 Pa s, w0 = 1000 rad/s, E = 27 MPa) and f_c = 0.12 the film "
    "settles at H = 0.9 (7.6 um) where viscous shear carries ~550 N m against ~50 N m of asperity "
    "friction, so the 'transmitted torque' (largest slipping torque) is the viscous peak when the film "
    "collapses, and the torque response time measures how fast the film drains.")


@pytest.mark.xfail(strict=True, reason=(
    "model: a longer lag gives a slightly SHORTER torque response time (0.0414 s at t_s = 0.036 s, "
    "0.0409 s at 0.044 s; 0.041 -> 0.029 s over t_s = 0.02-0.1 s), although the torque peak itself comes "
    "later (90 % at 0.055 -> 0.099 s). " + ZHANG_VISCOUS_PEAK + " The film drains under the pressure "
    "integral, so the 90 % torque time grows more slowly than the 50 % pressure time 0.69 t_s it is "
    "measured from."))
def test_zhang_longer_pressure_lag_slows_the_torque_response():
    # Fig. 3
    assert zhang({"actuation.time_constant": "0.044 s"})["torque_response_time_s"] > \
        zhang({"actuation.time_constant": "0.036 s"})["torque_response_time_s"]


def test_zhang_lower_lining_permeability_slows_the_torque_response():
    # Fig. 5; measured 0.0441 / 0.0386 s
    assert zhang({"plates.lining_permeability": "3.6e-12 m^2"})["torque_response_time_s"] > \
        zhang({"plates.lining_permeability": "4.4e-12 m^2"})["torque_response_time_s"]


@pytest.mark.xfail(strict=True, reason=(
    "model: a lower modulus gives a slightly FASTER torque response (0.04103 s at 24.3 MPa, 0.04139 s at "
    "29.7 MPa). " + ZHANG_VISCOUS_PEAK + " A softer contact lets the film thin further before the asperities "
    "carry the load, but there the real contact area is larger and the shear factor phi_f smaller, so the "
    "viscous peak is lower and earlier (594 N m at 0.076 s for 10 MPa, 613 N m at 0.082 s for 27 MPa); "
    "the asperity torque, on which Zhang's explanation rests, is a tenth of the torque."))
def test_zhang_lower_equivalent_modulus_slows_the_torque_response():
    # Fig. 6
    assert zhang({"contact.E_equiv": "2.43e7 Pa"})["torque_response_time_s"] > \
        zhang({"contact.E_equiv": "2.97e7 Pa"})["torque_response_time_s"]


@pytest.mark.xfail(strict=True, reason=(
    "model: a rougher pair gives a FASTER torque response (0.0402 s at sigma = 9.25 um, 0.0421 s at "
    "7.57 um). " + ZHANG_VISCOUS_PEAK + " With more roughness the asperities take the load at a thicker film "
    "(H = 0.9 at a larger h), so the viscous peak is lower and flatter (860, 613, 433 N m for sigma = 6, "
    "8.41, 12 um) and 90 % of it is reached earlier."))
def test_zhang_higher_roughness_slows_the_torque_response():
    # Fig. 7
    assert zhang({"roughness.sigma": "9.25e-6 m"})["torque_response_time_s"] > \
        zhang({"roughness.sigma": "7.57e-6 m"})["torque_response_time_s"]
