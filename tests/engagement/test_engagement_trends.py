"""The seed papers' parameter trends, one test per trend, as signs of finite differences.

Bao 2020 Section 4.3-4.6 (Figs 11-14) on bao2020 and on bao2020_as_published (Bao's Eqs. 19, 20 and
26 as printed), Zhang 2021 Section 3.1-3.5 (Figs 3-7) on zhang2021 with Zhang's torque response time
(to 90 % of the stable transmitted torque, summary key ``torque_response_time_stable_s``). A trend
the model does not reproduce is marked ``xfail(strict=True)`` with what the model says and why (so
it fails loudly if a change of the physics makes it come out); where the mechanism can be pinned, a
second test asserts it. The peak-based torque response time (``torque_response_time_s``, to 90 % of
the largest slipping torque) is kept at the end of the file, on zhang2021 with its roughness split
equally between the surfaces (the scene's form before the lining was made the rough surface).
"""

import numpy as np
import pytest
from scipy.optimize import brentq

from clutchocp.engagement.measures import _first_crossing as first_crossing
from clutchocp.engagement.run import simulate_engagement
from clutchocp.scene.loader import load_scene


BAO_SCENES = ("bao2020", "bao2020_as_published")


def bao(overrides, scene="bao2020", **kw):
    return simulate_engagement(load_scene(scene).with_overrides(overrides), **kw).summary


def zhang(overrides, **kw):
    return simulate_engagement(load_scene("zhang2021").with_overrides(overrides), **kw).summary


# Zhang's torque peaks come before 0.2 s: a 0.1 ms output grid up to 0.4 s resolves the response
# times to 1e-6 s (the scene's 3 ms grid over 6 s interpolates them to ~5e-5 s).
ZHANG_FINE = {"t_end": 0.4, "output_points": 4001}
# Zhang's response to the stable torque needs the pressure settled: 1 s is 10 lags of the longest
# t_s = 0.1 s of the sweep (P_s within 5e-5 of P_o), on the same 0.1 ms grid.
ZHANG_STABLE = {"t_end": 1.0, "output_points": 10001}
# Zhang Section 3 sweeps viscosity 0.0381-0.0981 Pa s (Fig. 4) and the lag t_s 0.02-0.1 s.
ZHANG_VISCOSITIES = ("0.0381 Pa s", "0.0681 Pa s", "0.0981 Pa s")
ZHANG_LAGS = ("0.02 s", "0.04 s", "0.1 s")


def zhang_stable_time(overrides):
    """Zhang's torque response time [s] (to 90 % of the stable torque) of zhang2021 with ``overrides``."""
    return zhang(overrides, **ZHANG_STABLE)["torque_response_time_stable_s"]


# ------------------------------------------------------------------------------- Bao 2020
@pytest.mark.parametrize("scene", BAO_SCENES)
def test_bao_more_spring_preload_engages_sooner(scene):
    # Fig. 11; measured 0.480 / 0.407 s (bao2020), 0.861 / 0.750 s (bao2020_as_published)
    assert bao({"piston.spring_preload": "0.044 m"}, scene)["engagement_time_s"] < \
        bao({"piston.spring_preload": "0.036 m"}, scene)["engagement_time_s"]


@pytest.mark.xfail(strict=True, reason=(
    "model: more preload gives a LARGER lock-up torque peak: jump -2804 N m at 0.036 m, -3437 N m at 0.044 m "
    "(+22.6 %) on bao2020; -1419 / -1735 N m (+22.3 %) on bao2020_as_published. Bao's own equations cannot "
    "give his claim: at lock the slip is quasi-static (the plates' time constants m/K are 1e-6 to 1e-9 s "
    "against a 0.4-0.8 s slip), so the asperity load equals the spring force less the static film load, and "
    "the torque that vanishes at lock, mu_s r_eff F_c per driving film, grows with the spring force "
    "k (preload - x0): +22 % of preload against +23 % of jump. Bao's Fig. 11 text ('the larger the rough "
    "contact torque ..., the smaller the torque peak at the lock') has no mechanism in Eqs. 19-27."))
@pytest.mark.parametrize("scene", BAO_SCENES)
def test_bao_more_spring_preload_gives_a_smaller_lockup_torque_peak(scene):
    # Fig. 11 text: 'the larger the rough contact torque ..., the smaller the torque peak at the lock'
    assert abs(bao({"piston.spring_preload": "0.044 m"}, scene)["lockup_torque_jump_Nm"]) < \
        abs(bao({"piston.spring_preload": "0.036 m"}, scene)["lockup_torque_jump_Nm"])


@pytest.mark.xfail(strict=True, reason=(
    "model: higher viscosity engages SOONER (0.449 s at 0.018 Pa s, 0.432 s at 0.022 Pa s). Bao's mechanism "
    "is there: more viscous oil drains more slowly, so at 20 ms the film is 7 % thicker and the asperity "
    "torque 45 % lower. But with the scene's 80 kN spring and mu_k = 0.10 the viscous shear, proportional to "
    "viscosity, carries 27-31 % of the slip's angular impulse: up to the earlier lock the thicker oil adds "
    "50.8 N m s of viscous impulse and loses only 9.6 N m s of asperity impulse to the slower squeeze. A "
    "weaker spring or a larger gap does not help, the film then settles thicker and the viscous share grows "
    "(0.022 - 0.018 Pa s: -19.5 ms at 0.036 m preload, -43.6 ms at 0.02 m, -17.7 ms with H0 = 1 mm). Bao's "
    "trend needs the asperity torque to carry the slip (Bao Section 4.2); that regime is tested below."))
def test_bao_higher_viscosity_engages_later():
    # Fig. 12
    assert bao({"oil.viscosity": "0.022 Pa s"})["engagement_time_s"] > \
        bao({"oil.viscosity": "0.018 Pa s"})["engagement_time_s"]


@pytest.mark.xfail(strict=True, reason=(
    "model: on bao2020_as_published too, higher viscosity engages SOONER: 0.821 s at 0.018 Pa s, 0.783 s at "
    "0.022 Pa s (-38 ms, twice bao2020's -17 ms). Only film 1 drives the output there and the Eq. 20 contact "
    "force C p_c A_n is far weaker, so the film settles thinner (10.2 against 16.6 um) and the viscous torque, "
    "proportional to viscosity, carries the slip longer; the competition is the one decomposed for bao2020 "
    "below (added viscous impulse against the delayed asperity impulse), not decomposed again here."))
def test_bao_as_published_higher_viscosity_engages_later():
    # Fig. 12, Bao's equations as printed
    assert bao({"oil.viscosity": "0.022 Pa s"}, "bao2020_as_published")["engagement_time_s"] > \
        bao({"oil.viscosity": "0.018 Pa s"}, "bao2020_as_published")["engagement_time_s"]


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


# Bao's regime for Fig. 12: scene assumptions only (Table 1 gives no spring count z1 and no friction
# curve): four springs (320 kN) and mu = 0.14 throughout the slip (Cui 2019's Cu-based value).
BAO_ASPERITY_SLIP = {"piston.spring_count": 4, "friction.mu_kinetic": 0.14, "friction.mu_static": 0.14}


def test_bao_higher_viscosity_engages_later_when_the_asperity_torque_carries_the_slip():
    """Fig. 12 where Bao's explanation applies. Bao Section 4.2 (Fig. 10): the viscous torque 'begins
    to decrease ... until it reaches zero, where a rough torque ... begins to continuously increase',
    and Section 4.4 explains the trend by the squeeze alone ('the smaller the viscosity of the
    lubricating oil and the faster the eventual increase in the rough torque'): the asperity friction
    carries the slip. With 4 springs and mu = 0.14 (BAO_ASPERITY_SLIP) the viscous share of the slip
    impulse falls from 27-31 % to 9-11 % (next test) and the more viscous oil engages later:
    0.10580 s at 0.018 Pa s, 0.10668 s at 0.022 Pa s (+0.88 ms; monotone over 0.015-0.025 Pa s; the
    same to 1e-7 s at rtol 1e-10). Boundary: with mu = 0.14 it needs z1 >= 3 springs (+0.21 ms;
    z1 = 2: -1.5 ms), with the scene's mu_k = 0.10 z1 >= 6 (+0.59 ms)."""
    thin = bao({**BAO_ASPERITY_SLIP, "oil.viscosity": "0.018 Pa s"}, t_end=0.15)["engagement_time_s"]
    thick = bao({**BAO_ASPERITY_SLIP, "oil.viscosity": "0.022 Pa s"}, t_end=0.15)["engagement_time_s"]
    assert thick > thin + 2e-4


def _slip_impulses(overrides, t_end):
    """Viscous and asperity angular impulses [N m s] of the clutch torque up to just before the
    earlier lock of the 0.018 / 0.022 Pa s runs, and I_out w_out there (their sum, no load)."""
    scene = load_scene("bao2020").with_overrides(overrides)
    runs = {eta: simulate_engagement(scene.with_overrides({"oil.viscosity": eta}), t_end=t_end).result
            for eta in ("0.018 Pa s", "0.022 Pa s")}
    t_cut = 0.999 * min(res.t[np.char.endswith(res.mode.astype(str), "locked")][0] for res in runs.values())
    out = {}
    for eta, res in runs.items():
        keep = res.t < t_cut
        t = np.append(res.t[keep], t_cut)
        J = {name: np.trapezoid(np.append(res[name][keep], np.interp(t_cut, res.t, res[name])), t)
             for name in ("viscous_torque_Nm", "contact_torque_Nm")}
        out[eta] = (J["viscous_torque_Nm"], J["contact_torque_Nm"],
                    scene.value("driveline.output_inertia") * np.interp(t_cut, res.t, res["w_out_rad_s"]))
    return out["0.018 Pa s"], out["0.022 Pa s"]


def test_bao_viscosity_trend_is_the_delayed_asperity_impulse_against_the_added_viscous_impulse():
    """Why the sign of Fig. 12 differs between the scene and Bao's regime. The output speed is the
    angular impulse of the clutch torque, I w_out(t) = J_v(t) + J_c(t) (no load). Up to the earlier
    lock, the more viscous oil (0.022 vs 0.018 Pa s) adds viscous impulse, dJ_v > 0, and, squeezing
    more slowly, delays the asperity torque, dJ_c < 0; it engages later iff |dJ_c| > dJ_v.
    Scene: dJ_v = +50.8, dJ_c = -9.6 N m s, viscous share of the impulse 0.27 / 0.31.
    BAO_ASPERITY_SLIP: dJ_v = +25.6, dJ_c = -36.5 N m s, viscous share 0.09 / 0.11."""
    for overrides, t_end in (({}, 0.5), (BAO_ASPERITY_SLIP, 0.15)):
        thin, thick = _slip_impulses(overrides, t_end)
        for J_v, J_c, I_w in (thin, thick):
            assert J_v + J_c == pytest.approx(I_w, rel=1e-3)     # the decomposition closes
        dJ_v, dJ_c = thick[0] - thin[0], thick[1] - thin[1]
        assert dJ_v > 0 > dJ_c
        shares = [J_v / (J_v + J_c) for J_v, J_c, _ in (thin, thick)]
        if overrides:
            assert -dJ_c > 1.2 * dJ_v
            assert max(shares) < 0.15
        else:
            assert dJ_v > 2.5 * -dJ_c
            assert min(shares) > 0.25


@pytest.mark.xfail(strict=True, reason=(
    "model: a heavier friction plate engages LATER, by 1.1e-8 s of 0.44 s when its mass doubles "
    "(0.367 -> 0.734 kg; resolved at rtol 1e-10, where the lock time is good to 1e-11 s). No regime gives "
    "Bao's trend: the plate starts and ends the squeeze at rest, so the impulse of its inertia, the integral "
    "of m2 dv2/dt = W1 - W2, is zero; the mass only shifts load between its two films for about its time "
    "constant m2/K (K the film's squeeze coefficient, 1.4e5 N s/m at the open gap, 3e8 N s/m once settled: "
    "3e-6 to 1e-9 s). The delay is linear in the added mass, 3e-8 s per kg (1.0e-7 s at 10x, 1.1e-6 s at "
    "100x; 1.5e-9 s in BAO_ASPERITY_SLIP; the steel plate that moves with the piston, doubled: 4.5e-8 s), so "
    "1 ms would take a plate of ~30 t. The slip, which sets the engagement time, does not see the plate "
    "mass; Bao too finds the difference 'not great'."))
def test_bao_heavier_friction_plate_engages_sooner():
    # Fig. 14; plate 2 is the friction plate (Bao Table 1 m2)
    tight = {"rtol": 1e-10, "atol": 1e-12}
    assert bao({"pack.plate_masses": ["0.367 kg", "0.734 kg"]}, **tight)["engagement_time_s"] < \
        bao({"pack.plate_masses": ["0.367 kg", "0.367 kg"]}, **tight)["engagement_time_s"]


def test_bao_friction_plate_mass_acts_only_through_its_time_constant_on_the_films():
    """What the model says instead of Fig. 14, and why no regime can change it: the friction plate's
    inertia delays the lock by a time linear in the added mass (measured +1.12e-8 s for +0.367 kg,
    +1.00e-7 s for +3.30 kg: ratio 8.98 for 9) and far below its time constant on the open films,
    dm / K(H0) with the closed-form squeeze coefficient K = (3 pi / 2) eta [r2^4 - r1^4 -
    (r2^2 - r1^2)^2 / ln(r2/r1)] / H0^3 = 1.4e5 N s/m (2.3e-5 s for +3.30 kg)."""
    tight = {"rtol": 1e-10, "atol": 1e-12}
    t = {m: bao({"pack.plate_masses": ["0.367 kg", f"{m} kg"]}, **tight)["engagement_time_s"]
         for m in (0.367, 0.734, 3.67)}
    d_double, d_tenfold = t[0.734] - t[0.367], t[3.67] - t[0.367]
    assert d_double > 0
    assert d_tenfold / d_double == pytest.approx((3.67 - 0.367) / (0.734 - 0.367), rel=0.05)
    r1, r2, eta, H0 = 0.12, 0.16, 0.02, 2e-4                      # Bao Table 1
    K_open = 1.5 * np.pi * eta * (r2**4 - r1**4 - (r2**2 - r1**2) ** 2 / np.log(r2 / r1)) / H0**3
    assert d_tenfold < 0.1 * (3.67 - 0.367) / K_open


def test_bao_as_published_heavier_friction_plate_engages_sooner_by_nanoseconds():
    """Fig. 14 on Bao's equations as printed: the sign is Bao's, the size is not visible. With only
    film 1 driving the output (Eq. 26), the friction plate's inertia shifts load onto the driving film
    for its time constant m2/K, so a heavier plate locks sooner: by 2.4e-9 s (rtol 1e-10) / 3.2e-9 s
    (rtol 1e-11) of 0.80 s when its mass doubles, 2.6e-8 s at ten times the mass (both tolerances).
    The tenfold case is asserted (its size is resolved); it stays below 1e-7 of the lock time."""
    tight = {"rtol": 1e-10, "atol": 1e-12}
    light, heavy = (bao({"pack.plate_masses": ["0.367 kg", m]}, "bao2020_as_published", **tight)["engagement_time_s"]
                    for m in ("0.367 kg", "3.67 kg"))
    assert 1e-8 < light - heavy < 1e-7 * light


@pytest.mark.xfail(strict=True, reason=(
    "model: at equal spring force at first contact (preload - travel = 39.5 mm) the collision at 6.3 m/s "
    "leaves the lock-up torque jump unchanged: -3120.4903 N m with and -3120.4902 N m without it on bao2020 "
    "(1.4e-9 relative), -1577.0605 / -1577.0605 N m (1.0e-9) on bao2020_as_published. No regime gives Bao's "
    "trend: the jump is the slipping torque at lock, mu_s r_eff F_c per driving film, with the asperity load "
    "F_c set by the quasi-static axial balance at lock (spring force = asperity load + static film load); the "
    "impact momentum, (m0 + m1) v = 12.6 N s after the plastic impact, is taken up by the spring-driven "
    "films within about (m0 + m1) / K = 17 us (K = 1.4e5 N s/m at the open gap), 0.44 s before lock-up. "
    "(Compared at equal preload instead, the free travel lowers the spring force by 1 kN and the jump falls, "
    "3120 against 3160 N m: the opposite of Bao's claim, and a comparison at unequal force.) Bao's Fig. 13 "
    "caption repeats Fig. 12's (viscosity), so the figure cannot be checked either."))
@pytest.mark.parametrize("scene", BAO_SCENES)
def test_bao_collision_velocity_raises_the_lockup_torque_peak(scene):
    # Fig. 13: the initial velocity of the collision (Bao Eq. 22) included or not, at equal spring force
    # when the piston meets the pack; Bao: 'the peak torque at the lock is sharply increased' (>= 1 % here)
    with_impact = bao({"piston.travel_to_pack": "0.5 mm", "piston.spring_preload": "0.040 m"}, scene)
    without = bao({"piston.travel_to_pack": "0 m", "piston.spring_preload": "0.0395 m"}, scene)
    assert abs(with_impact["lockup_torque_jump_Nm"]) > 1.01 * abs(without["lockup_torque_jump_Nm"])


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


def test_bao_lockup_torque_forgets_even_a_fast_collision():
    """No collision speed makes Fig. 13 come out: with 5 mm of free travel (preload 44.5 mm, the same
    spring force at first contact as at rest with 39.5 mm) the piston hits the pack at 20.5 m/s and
    65 J are lost in the impact, yet the lock-up torque jump equals the at-rest one to 1e-6 (measured
    3e-9) and the lock comes 5e-5 s SOONER (Bao: the engagement time is longer)."""
    run = simulate_engagement(load_scene("bao2020").with_overrides(
        {"piston.travel_to_pack": "5 mm", "piston.spring_preload": "0.0445 m"}))
    impact = next(e for e in run.result.events if e.name == "impact")
    assert impact.x_before["v0"] > 15.0
    rest = bao({"piston.travel_to_pack": "0 m", "piston.spring_preload": "0.0395 m"})
    collide = run.summary
    assert collide["lockup_torque_jump_Nm"] == pytest.approx(rest["lockup_torque_jump_Nm"], rel=1e-6)
    assert collide["engagement_time_s"] == pytest.approx(rest["engagement_time_s"], rel=1e-3)
    assert collide["engagement_time_s"] < rest["engagement_time_s"]


# ------------------------------------------------------------------------------- Zhang 2021
# Zhang's torque response time: from 50 % of P_o to 90 % of the stable transmitted torque (Zhang
# Section 3, Fig. 2), on zhang2021 as it is (lining rough, separator smooth, f_c = 0.12).
def test_zhang_stable_torque_is_f_c_P_o_A_r_eff_and_the_response_is_measured_from_t_s_ln2():
    """The definition against closed forms: the stable torque is the asperity torque once the film has
    drained, f_c P_o A r_eff (A = pi (b^2 - a^2), r_eff = 2 (b^3 - a^3) / (3 (b^2 - a^2)), Bao Eq. 25-26)
    = 53.08 N m; the lag P_o (1 - exp(-t/t_s)) passes 50 % at t_s ln 2; the response time is the first
    time the asperity torque reaches 90 % of the stable torque, less t_s ln 2 (70.04 ms here)."""
    f_c, a, b, P_o, t_s = 0.12, 0.064, 0.085, 6e5, 0.04                    # Zhang Table 1, scene
    stable = f_c * P_o * np.pi * (b**2 - a**2) * 2 * (b**3 - a**3) / (3 * (b**2 - a**2))
    run = simulate_engagement(load_scene("zhang2021"), **ZHANG_STABLE)
    assert run.summary["stable_torque_Nm"] == pytest.approx(stable, rel=1e-6)
    res = run.result
    t90 = first_crossing(res.t, np.abs(res["contact_torque_Nm"]), 0.9 * stable)
    assert run.summary["torque_response_time_stable_s"] == pytest.approx(t90 - t_s * np.log(2), abs=1e-6)
    # the total torque (43.6 N m of viscous shear on the open gap) passes 90 % of the stable torque
    # before the pressure reaches 50 %: a response time measured on it would be negative (-20.5 ms)
    assert first_crossing(res.t, np.abs(res["total_torque_Nm"]), 0.9 * stable) < t_s * np.log(2) - 0.01


@pytest.mark.parametrize("eta", ZHANG_VISCOSITIES)
def test_zhang_longer_pressure_lag_slows_the_torque_response(eta):
    """Fig. 3: the response time grows with the lag over Zhang's sweep at each viscosity of Fig. 4
    (0.0681 Pa s: 56.9, 70.0, 100.7, 165.0 ms for t_s = 0.02, 0.04, 0.06, 0.1 s)."""
    times = [zhang_stable_time({"oil.viscosity": eta, "actuation.time_constant": t_s})
             for t_s in ("0.02 s", "0.04 s", "0.06 s", "0.1 s")]
    assert np.all(np.diff(times) > 1e-3)


def test_zhang_higher_viscosity_slows_the_torque_response_when_the_pressure_rises_fast():
    """Fig. 4, Section 3.2: 'When the pressure response time is short, ... the greater the viscosity
    ..., the torque response time is longer'; t_s = 0.02 s: 36.7, 56.9, 78.5 ms for 0.0381, 0.0681,
    0.0981 Pa s."""
    times = [zhang_stable_time({"oil.viscosity": eta, "actuation.time_constant": "0.02 s"}) for eta in ZHANG_VISCOSITIES]
    assert np.all(np.diff(times) > 5e-3)


def test_zhang_lower_viscosity_is_more_sensitive_to_the_pressure_response():
    """Fig. 4, Section 3.2: 'the lubricant with a lower viscosity demonstrates more sensitivity of
    transmitted torque response time to pressure response time'. From t_s = 0.02 to 0.1 s the response
    time grows by 126.4 ms at 0.0381 Pa s, 108.1 ms at 0.0681 Pa s and 88.3 ms at 0.0981 Pa s."""
    growth = [zhang_stable_time({"oil.viscosity": eta, "actuation.time_constant": "0.1 s"})
              - zhang_stable_time({"oil.viscosity": eta, "actuation.time_constant": "0.02 s"}) for eta in ZHANG_VISCOSITIES]
    assert np.all(np.diff(growth) < -10e-3)


@pytest.mark.xfail(strict=True, reason=(
    "model: with Zhang's equations (no centrifugal term in his Eq. 1 and 4) the more viscous oil still "
    "responds later at t_s = 0.1 s: 163.2 ms at 0.0381 Pa s, 166.8 ms at 0.0981 Pa s (+3.7 ms; +41.8 ms at "
    "t_s = 0.02 s). More viscous oil only slows the squeeze in Eqs. 1-10. Zhang explains the reversal by 'the "
    "centrifugal force on the cooling lubricating oil in the separation gap', a term his model does not "
    "contain; with it (film.centrifugal = true, next test) the reversal appears."))
def test_zhang_higher_viscosity_speeds_the_torque_response_when_the_pressure_rises_slowly():
    # Fig. 4, Section 3.2: 'when the pressure response time is relatively long ... the greater the
    # viscosity ..., the torque response time is shorter'
    thin, thick = (zhang_stable_time({"oil.viscosity": eta, "actuation.time_constant": "0.1 s"})
                   for eta in ("0.0381 Pa s", "0.0981 Pa s"))
    assert thick < thin


def test_zhang_viscosity_reversal_at_slow_pressure_rise_comes_with_the_centrifugal_term():
    """Zhang's explanation of the long-lag reversal, with the centrifugal term of the Reynolds equation
    (Bao Eq. 11; the disc at 1000 rad/s against the separator at rest) switched on: at t_s = 0.02 s the
    more viscous oil responds later (33.4 against 73.9 ms), at t_s = 0.1 s sooner (143.7 against
    140.8 ms), as Zhang's Fig. 4 says."""
    def time(eta, t_s):
        return zhang_stable_time({"oil.viscosity": eta, "actuation.time_constant": t_s, "film.centrifugal": True})

    assert time("0.0981 Pa s", "0.02 s") > time("0.0381 Pa s", "0.02 s") + 20e-3
    assert time("0.0981 Pa s", "0.1 s") < time("0.0381 Pa s", "0.1 s") - 1e-3


@pytest.mark.parametrize("t_s", ZHANG_LAGS)
@pytest.mark.parametrize("eta", ZHANG_VISCOSITIES)
def test_zhang_lower_lining_permeability_slows_the_torque_response(eta, t_s):
    """Fig. 5 in all nine combinations of Zhang's viscosities and lags: 3.6e-12 against 4.4e-12 m^2
    responds later by 0.46-10.5 ms (scene point 0.0681 Pa s, 0.04 s: +3.63 ms)."""
    base = {"oil.viscosity": eta, "actuation.time_constant": t_s}
    assert zhang_stable_time({**base, "plates.lining_permeability": "3.6e-12 m^2"}) > \
        zhang_stable_time({**base, "plates.lining_permeability": "4.4e-12 m^2"}) + 2e-4


@pytest.mark.parametrize("t_s", ZHANG_LAGS)
@pytest.mark.parametrize("eta", ZHANG_VISCOSITIES)
def test_zhang_lower_equivalent_modulus_slows_the_torque_response(eta, t_s):
    """Fig. 6 in all nine combinations: E = 24.3 against 29.7 MPa responds later by 0.055-1.29 ms
    (scene point: +0.43 ms). A softer contact needs a thinner film to carry P_o on the asperities,
    so the last of the squeeze, through the lining, takes longer (Zhang Section 3.4)."""
    base = {"oil.viscosity": eta, "actuation.time_constant": t_s}
    assert zhang_stable_time({**base, "contact.E_equiv": "2.43e7 Pa"}) > \
        zhang_stable_time({**base, "contact.E_equiv": "2.97e7 Pa"}) + 3e-5


def test_zhang_higher_roughness_slows_the_torque_response():
    """Fig. 7 at the scene's point (0.0681 Pa s, t_s = 0.04 s): sigma = 9.25 against 7.57 um (the
    combined RMS, all on the lining) responds later by 0.32 ms (70.18 against 69.86 ms)."""
    assert zhang_stable_time({"roughness.sigma": "9.25e-6 m"}) > zhang_stable_time({"roughness.sigma": "7.57e-6 m"}) + 1e-4


@pytest.mark.xfail(strict=True, reason=(
    "model: with the fastest lag of the sweep, t_s = 0.02 s, the rougher pair responds SOONER: -1.17 ms at "
    "0.0681 Pa s (57.41 against 56.24 ms for sigma = 7.57 / 9.25 um), -1.93 ms at 0.0981 Pa s, -0.04 ms at "
    "0.0381 Pa s; at t_s = 0.04 s it is +0.27 / +0.32 / -1.13 ms and at t_s = 0.1 s +0.26 / +0.47 / +0.70 ms "
    "(0.0381 / 0.0681 / 0.0981 Pa s). The rougher pair meets the asperities at a thicker film (9.0 against "
    "6.6 um when 90 % is reached), so its asperity torque starts sooner (1 % of the stable torque at 45.8 "
    "against 50.0 ms, t_s = 0.02 s) and reaches 50 % sooner; its last 10 % comes later, as its thicker film "
    "still carries load while it drains through the lining. When the pressure is up early (t_s = 0.02 s: "
    "97 % of P_o at the 90 % time) the early start wins; when the pressure rise paces the end (t_s = 0.04 s: "
    "91 %) the slow end wins. Zhang's Fig. 7 claims the delay at every pressure response time."))
def test_zhang_higher_roughness_slows_the_torque_response_at_the_fastest_pressure_rise():
    # Fig. 7 at t_s = 0.02 s (pressure response time 0.044 s), scene viscosity
    assert zhang_stable_time({"roughness.sigma": "9.25e-6 m", "actuation.time_constant": "0.02 s"}) > \
        zhang_stable_time({"roughness.sigma": "7.57e-6 m", "actuation.time_constant": "0.02 s"})


# ------------------------------------------------------------------------------- Zhang 2021, peak-based
# The torque response time to 90 % of the largest slipping torque (summary torque_response_time_s).
# These tests keep the roughness split equally between the surfaces (phi_fs = 0) and the scene's former
# 4 s / 2 ms output grid, the form their numbers were measured on.
ZHANG_EQUAL_SPLIT = {"roughness.sigma_1": f"{8.41e-6 / np.sqrt(2)} m", "roughness.sigma_2": f"{8.41e-6 / np.sqrt(2)} m"}


def zhang_peak(overrides, **kw):
    return zhang({**ZHANG_EQUAL_SPLIT, **overrides}, **({"t_end": 4.0} | kw))


ZHANG_VISCOUS_PEAK = (
    "With Zhang's Table 1 (eta = 0.0681 Pa s, w0 = 1000 rad/s, E = 27 MPa) and f_c = 0.12 the film "
    "settles at H = 0.9 (7.6 um) where viscous shear carries ~550 N m against ~50 N m of asperity "
    "friction, so the 'transmitted torque' (largest slipping torque) is the viscous peak when the film "
    "collapses, and the torque response time measures how fast the film drains.")
ZHANG_NO_ASPERITY_REGIME = (
    "No regime with a plausible asperity friction coefficient makes the asperity torque Zhang's "
    "explanation rests on carry the torque: it cannot exceed f_c P_o A r_eff = 442 f_c N m (all of P_o on "
    "the asperities, reached once the film has drained), while the viscous peak is ~320 N m even at Zhang's "
    "lowest viscosity 0.0381 Pa s (asperity share of the peak 0.13, 0.20, 0.28, 0.40, 0.59 for f_c = 0.12, "
    "0.2, 0.3, 0.5, 1); it would need f_c > 0.7, against ~0.1-0.15 for a paper lining in ATF.")


@pytest.mark.xfail(strict=True, reason=(
    "model: a longer lag gives a slightly SHORTER torque response time (0.0414 s at t_s = 0.036 s, "
    "0.0409 s at 0.044 s; 0.0409, 0.0415, 0.0412, 0.0386, 0.0292 s at t_s = 0.02, 0.03, 0.04, 0.06, 0.1 s), "
    "although the torque peak itself comes later. " + ZHANG_VISCOUS_PEAK + " The film collapses (90 % of "
    "that peak, at t90) after a fixed pressure impulse J* (21.6 kPa s at 0.0681 Pa s, the same to 0.5 % for "
    "t_s = 0.02-0.1 s). From the integral of P_o (1 - exp(-t/t_s)) up to t90 = J*, dt90/dt_s = "
    "[1 - (1 + u) e^-u] / (1 - e^-u) with u = t90/t_s, and the response time t90 - t_s ln 2 grows with t_s "
    "iff that exceeds ln 2, i.e. u > 2.03 (the film outlasts 87 % of the pressure rise): t_s < J* / (1.16 P_o) "
    "= 0.031 s at this viscosity. The scene's lag is past it; where it holds is tested below."))
def test_zhang_peak_longer_pressure_lag_slows_the_torque_response():
    # Fig. 3
    assert zhang_peak({"actuation.time_constant": "0.044 s"})["torque_response_time_s"] > \
        zhang_peak({"actuation.time_constant": "0.036 s"})["torque_response_time_s"]


def test_zhang_longer_pressure_lag_slows_the_torque_response_when_the_squeeze_outlasts_the_pressure_rise():
    """Fig. 3 where Zhang's explanation applies. Zhang Section 3.2: 'When the pressure response time
    is short, ... in the squeeze stage, the greater the viscosity of the lubricating oil, ... the longer
    the squeeze stage lasts, the slower the transmitted torque response is': the response is governed
    by the squeeze when the film outlasts the pressure rise. With Zhang's highest viscosity 0.0981 Pa s
    (Fig. 4) and the first two lags of the sweep, t_s = 0.02 and 0.04 s (Section 3: 0.02-0.1 s), the
    film collapses after the pressure has passed 87 % (next test) and the torque response time grows
    with the lag: 0.0564 s -> 0.0585 s (+2.1 ms; the fine grid resolves it to 1e-6 s). It holds for
    t_s < 0.044 s at 0.0981 Pa s and t_s < 0.031 s at 0.0681 Pa s (0.0409 -> 0.0415 s for
    0.02 -> 0.03 s), at no lag of the sweep at 0.0381 Pa s. The torque is still the viscous peak here
    (asperity share 3.5 %): the trend comes from the timing of the squeeze, not from asperity torque."""
    fast = zhang_peak({"oil.viscosity": "0.0981 Pa s", "actuation.time_constant": "0.02 s"}, **ZHANG_FINE)
    slow = zhang_peak({"oil.viscosity": "0.0981 Pa s", "actuation.time_constant": "0.04 s"}, **ZHANG_FINE)
    assert slow["torque_response_time_s"] > fast["torque_response_time_s"] + 5e-4


def test_zhang_torque_response_follows_the_lag_iff_the_film_outlasts_87_percent_of_the_pressure_rise():
    """The mechanism of the two lag tests above. The 90 % torque time t90 is reached after a pressure
    impulse J* that does not depend on the lag (measured 30.54 / 30.51 kPa s at 0.0981 Pa s,
    21.63 kPa s at 0.0681 Pa s), so d t90 / d t_s = f(u) = [1 - (1 + u) e^-u] / (1 - e^-u), u = t90/t_s,
    and the response time t90 - t_s ln 2 grows with t_s iff f(u) > ln 2, i.e. u > u* = 2.03.
    0.0981 Pa s, t_s = 0.02 / 0.04 s: u = 3.52 / 2.16 (grows); scene, 0.0681 Pa s, t_s = 0.036 /
    0.044 s: u = 1.84 / 1.62 (shrinks). Asperity torque is under 10 % of the peak in both."""
    def lag_sensitivity(u):      # d t90 / d t_s at a fixed pressure impulse, u = t90 / t_s
        return (1 - (1 + u) * np.exp(-u)) / (1 - np.exp(-u))

    u_star = brentq(lambda u: lag_sensitivity(u) - np.log(2), 0.5, 10.0)
    assert u_star == pytest.approx(2.03, abs=0.005)
    for eta, lags, grows in (("0.0981 Pa s", (0.02, 0.04), True), ("0.0681 Pa s", (0.036, 0.044), False)):
        impulses = []
        for t_s in lags:
            run = simulate_engagement(load_scene("zhang2021").with_overrides(
                {**ZHANG_EQUAL_SPLIT, "oil.viscosity": eta, "actuation.time_constant": f"{t_s} s"}), **ZHANG_FINE)
            res = run.result
            torque = np.abs(res["total_torque_Nm"])
            t90 = first_crossing(res.t, torque, 0.9 * torque.max())
            assert run.summary["torque_response_time_s"] == pytest.approx(t90 - t_s * np.log(2), abs=1e-5)
            keep = res.t < t90
            p = np.append(res["pressure_Pa"][keep], np.interp(t90, res.t, res["pressure_Pa"]))
            impulses.append(np.trapezoid(p, np.append(res.t[keep], t90)))
            assert (t90 / t_s > u_star) == grows
            peak = int(np.argmax(torque))
            assert abs(res["contact_torque_Nm"][peak]) < 0.1 * torque[peak]
        assert impulses[1] == pytest.approx(impulses[0], rel=1e-2)


def test_zhang_peak_lower_lining_permeability_slows_the_torque_response():
    # Fig. 5; measured 0.0441 / 0.0386 s
    assert zhang_peak({"plates.lining_permeability": "3.6e-12 m^2"})["torque_response_time_s"] > \
        zhang_peak({"plates.lining_permeability": "4.4e-12 m^2"})["torque_response_time_s"]


@pytest.mark.xfail(strict=True, reason=(
    "model: a lower modulus gives a slightly FASTER torque response (0.04103 s at 24.3 MPa, 0.04139 s at "
    "29.7 MPa). " + ZHANG_VISCOUS_PEAK + " A softer contact lets the film thin further before the asperities "
    "carry the load, but there the real contact area is larger and the shear factor phi_f smaller, so the "
    "viscous peak is lower and earlier (594 N m at 0.076 s for 10 MPa, 613 N m at 0.082 s for 27 MPa); "
    "the asperity torque, on which Zhang's explanation rests, is a tenth of the torque. " + ZHANG_NO_ASPERITY_REGIME
    + " For E the trend appears only at 0.0381 Pa s with f_c >= 0.3 and t_s <= 0.04 s (+0.13 / +0.06 ms at "
    "t_s = 0.02 / 0.04 s), where the asperities still carry only 28 % of the peak; at f_c <= 0.2 it is "
    "reversed in all 21 combinations of viscosity (0.0381-0.0981 Pa s) and lag (0.02-0.1 s) tried."))
def test_zhang_peak_lower_equivalent_modulus_slows_the_torque_response():
    # Fig. 6
    assert zhang_peak({"contact.E_equiv": "2.43e7 Pa"})["torque_response_time_s"] > \
        zhang_peak({"contact.E_equiv": "2.97e7 Pa"})["torque_response_time_s"]


@pytest.mark.xfail(strict=True, reason=(
    "model: a rougher pair gives a FASTER torque response (0.0402 s at sigma = 9.25 um, 0.0421 s at "
    "7.57 um). " + ZHANG_VISCOUS_PEAK + " With more roughness the asperities take the load at a thicker film "
    "(H = 0.9 at a larger h), so the viscous peak is lower and flatter (860, 613, 433 N m for sigma = 6, "
    "8.41, 12 um) and 90 % of it is reached earlier. " + ZHANG_NO_ASPERITY_REGIME + " For sigma the trend "
    "appears only at 0.0381 Pa s with f_c >= 0.25 and t_s >= 0.04 s (+0.18 / +0.25 ms at f_c = 0.25, "
    "t_s = 0.04 / 0.1 s); at f_c <= 0.2 it is reversed in 20 of the 21 combinations of viscosity "
    "(0.0381-0.0981 Pa s) and lag (0.02-0.1 s) tried and flat (+1 us) in the last."))
def test_zhang_peak_higher_roughness_slows_the_torque_response():
    # Fig. 7
    assert zhang_peak({"roughness.sigma": "9.25e-6 m"})["torque_response_time_s"] > \
        zhang_peak({"roughness.sigma": "7.57e-6 m"})["torque_response_time_s"]


def test_zhang_asperity_torque_stays_a_minority_even_at_the_lowest_viscosity():
    """The claim behind the E and sigma xfails. At Zhang's lowest viscosity 0.0381 Pa s and a high
    paper-lining coefficient f_c = 0.2, the asperity torque reaches the closed-form bound
    f_c P_o A r_eff (A = pi (b^2 - a^2), r_eff = 2 (b^3 - a^3) / (3 (b^2 - a^2)), Bao Eq. 25-26) = 88.5 N m
    once the film has drained, and at the torque peak it is 82 N m of 404 N m (20 %): the viscous part
    there, 322 N m, exceeds three times the largest possible asperity torque."""
    f_c, a, b, P_o = 0.2, 0.064, 0.085, 6e5                     # Zhang Table 1
    bound = f_c * P_o * np.pi * (b**2 - a**2) * 2 * (b**3 - a**3) / (3 * (b**2 - a**2))
    res = simulate_engagement(load_scene("zhang2021").with_overrides(
        {**ZHANG_EQUAL_SPLIT, "oil.viscosity": "0.0381 Pa s", "friction.mu": f_c, "actuation.time_constant": "0.02 s"}),
        **ZHANG_FINE).result
    assert abs(res["contact_torque_Nm"][-1]) == pytest.approx(bound, rel=1e-3)
    torque = np.abs(res["total_torque_Nm"])
    peak = int(np.argmax(torque))
    assert abs(res["contact_torque_Nm"][peak]) < 0.25 * torque[peak]
    assert abs(res["viscous_torque_Nm"][peak]) > 3 * bound
