"""What no command can do, checked before solving (clutchocp.optimal.feasibility): each bound against an
independent value (closed form, conservation law, IDAS run), and each refusal one line with its numbers."""

import math
from pathlib import Path

import casadi as ca
import numpy as np
import pytest
from scipy.integrate import quad

from clutchocp.engagement.model import EngagementModel
from clutchocp.engagement.run import simulate_engagement
from clutchocp.errors import ModelError, PhysicalRangeError
from clutchocp.optimal.clamp import ClampModel
from clutchocp.optimal.feasibility import (
    FILM_FLOOR,
    holding_capacity,
    lockup_energy_bound,
    own_profile_within_contact,
    temperature_bound,
    thermal_response,
    usable_pressure,
)
from clutchocp.engagement.edges import check_contact_capacity, zero_gap_pressure
from clutchocp.optimal.problem import EngagementOCP, solver_verdict
from clutchocp.scene import default_scene, load_scene

CATALOGUE = Path(__file__).resolve().parents[2] / "models" / "catalogue"
F52_AT_ZERO = 0.61663            # Greenwood-Tripp F_5/2(0)


@pytest.fixture(scope="module")
def scene():
    return default_scene()


@pytest.fixture(scope="module")
def model(scene):
    return EngagementModel(scene, pressure_command=ca.SX.sym("u"))


def test_zero_gap_pressure_is_greenwood_tripps_closed_form(scene, model):
    n, beta, sigma = (scene.value(k) for k in ("roughness.asperity_density", "roughness.asperity_radius",
                                               "roughness.sigma"))
    closed = 16 * math.sqrt(2) / 15 * math.pi * (n * beta * sigma) ** 2 * math.sqrt(sigma / beta) \
        * scene.value("contact.E_equiv") * F52_AT_ZERO
    assert zero_gap_pressure(model.film) == pytest.approx(closed, rel=1e-4)
    assert zero_gap_pressure(model.film) == pytest.approx(1.79e6, rel=3e-3)     # the catalogue's table


def test_holding_capacity_is_the_settled_clamp_capacity(scene, model):
    """Without a piston the plate force is p A at any film: the bound is the settled pack's capacity."""
    p = scene.value("actuation.max_pressure")
    capacity, plate, contact, by_contact = holding_capacity(model, p)
    assert plate == pytest.approx(p) and not by_contact and contact > p
    assert capacity == pytest.approx(ClampModel(scene).capacity(p), rel=1e-6)
    # and the closed form mu_s p A r_eff n
    film = model.film
    assert capacity == pytest.approx(0.12 * p * film.area * film.r_eff * 4, rel=1e-12)


def test_energy_identity_and_bound_on_an_idas_run(scene, model):
    """E_slip = 1/2 I_eq w_rel0^2 + T_lock int w_rel dt (the identity the bound rests on), checked on the
    scene's own IDAS run; and the bound 1/2 I_eq w_rel0^2 below what the run dissipates."""
    run = simulate_engagement(scene)
    res = run.result
    t_lock = run.summary["engagement_time_s"]
    lock = next(e for e in res.events if e.name == "lockup")
    keep = (res.t <= t_lock) & (np.asarray(res.mode) == "pressing_slip_forward")
    t, idx = np.unique(res.t[keep], return_index=True)
    w_rel = (res["w_in_rad_s"] - res["w_out_rad_s"])[keep][idx]
    I_in, I_out = 0.25, 2.0
    I_eq = I_in * I_out / (I_in + I_out)
    T_lock = I_eq * (150.0 / I_in + 100.0 / I_out)
    identity = 0.5 * I_eq * 150.0**2 + T_lock * np.trapezoid(w_rel, t)
    # E_slip + the residual slip's kinetic energy at the event (E_impact) is the slip energy
    assert lock.x_before["E_slip"] + lock.x_after["E_impact"] == pytest.approx(identity, rel=2e-3)
    bound = lockup_energy_bound(model, t_lock)
    assert bound == pytest.approx(0.5 * I_eq * 150.0**2, rel=1e-12)
    assert bound < run.summary["dissipated_energy_J"]


def test_energy_bound_is_approached_by_a_hard_constant_torque_lock():
    """A lock by a constant clutch torque T_c dissipates 1/2 I_eq w0^2 T_c / (T_c - T_lock) (closed form of
    the linear slip decay), which tends to the bound as T_c grows and never falls below it."""
    I_eq, w0, T_lock = 0.25 * 2 / 2.25, 150.0, 0.25 * 2 / 2.25 * (150 / 0.25 + 100 / 2)
    for T_c in (200.0, 1e3, 1e5):
        t_lock = w0 * I_eq / (T_c - T_lock)
        energy = T_c * w0 * t_lock / 2                      # int T_c w_rel dt with w_rel linear
        assert energy == pytest.approx(0.5 * I_eq * w0**2 * T_c / (T_c - T_lock), rel=1e-12)
        assert energy >= 0.5 * I_eq * w0**2
    assert energy == pytest.approx(0.5 * I_eq * w0**2, rel=2e-3)


def _thermal_numbers(scene):
    """(C_sep, C_f, C_lining, g_lining, G): the default thermal scene's capacities [J/K] and conductances
    [W/K] from its keys: n A d rho c of the paper lining, n A k / d across it, h n A to the oil per side."""
    n, d = scene.value("plates.n_interfaces"), scene.value("plates.lining_thickness")
    A = math.pi * (scene.value("plates.r_outer") ** 2 - scene.value("plates.r_inner") ** 2)
    k, rho, c = 0.2, 1000.0, 1500.0                              # thermal.lining_material = "paper"
    return 142.0, 144.0, n * A * d * rho * c, n * A * k / d, 1000.0 * n * A


def test_thermal_responses_are_the_two_node_closed_forms():
    """One conduction cell: the surface node (separator and half the lining, C_0 = C_sep + C_l/2) and the
    back node (the other half and the core, C_1 = C_f - C_l/2), joined by g = n A k / d, each convecting
    G = h n A. The 2 x 2 system's exponential in closed form, e^(At) = e^(st) [cosh(dt) I + sinh(dt)/d (A - sI)]
    (s = tr A / 2, d = sqrt(s^2 - det A)), gives the impulse response of the interface temperature and its
    free cooling from 70 degC to the 40 degC oil; the linearised model (thermal_response) must equal them."""
    scene = load_scene("default_driveline_thermal").with_overrides(
        {"thermal.initial_temperature_C": 70.0, "thermal.lining_cells": 1})
    model = EngagementModel(scene, pressure_command=ca.SX.sym("u"))
    free, impulse = thermal_response(model)
    C_sep, C_f, C_l, g, G = _thermal_numbers(scene)
    C0, C1 = C_sep + C_l / 2, C_f - C_l / 2
    A = np.array([[-(g + G) / C0, g / C0], [g / C1, -(g + G) / C1]])
    s = np.trace(A) / 2
    d = math.sqrt(s**2 - np.linalg.det(A))

    def row0(t):                   # the first row of e^(At)
        ch, sh = math.cosh(d * t), math.sinh(d * t) / d
        return math.exp(s * t) * np.array([ch + sh * (A[0, 0] - s), sh * A[0, 1]])

    for t in (0.0, 0.05, 0.3, 5.0):
        e = row0(t)
        assert impulse(t) == pytest.approx(e[0] / C0, rel=1e-9)
        assert free(t) == pytest.approx(40.0 + 30.0 * (e[0] + e[1]), rel=1e-9)


def test_thermal_impulse_response_of_the_lining_nodes():
    """The default 6 cells: at t = 0 the heat is in the surface node alone, g(0) = 1 / (C_sep + half the first
    cell); over all time the heat of an impulse leaves through both convections, so int_0^inf g dt is the
    steady rise per watt, 1 / (G + 1 / (d / (n A k) + 1 / G)) (the lining's series resistance is d / (n A k)
    whatever the cells); and g falls all the time (the premise of the temperature bound)."""
    scene = load_scene("default_driveline_thermal")
    model = EngagementModel(scene, pressure_command=ca.SX.sym("u"))
    _, impulse = thermal_response(model)
    C_sep, _, C_l, g, G = _thermal_numbers(scene)
    first_cell = 1.0 / sum(1.5**j for j in range(6))             # the cells grow 1.5 x from the surface
    assert impulse(0.0) == pytest.approx(1.0 / (C_sep + C_l * first_cell / 2), rel=1e-9)
    total = sum(quad(impulse, a, b, limit=200)[0] for a, b in ((0.0, 0.1), (0.1, 10.0), (10.0, 400.0)))
    assert total == pytest.approx(1.0 / (G + 1.0 / (1.0 / g + 1.0 / G)), rel=1e-6)
    samples = [impulse(t) for t in np.geomspace(1e-5, 60.0, 60)]
    assert all(b < a for a, b in zip(samples, samples[1:]))


def test_temperature_bound_holds_for_any_heat_history():
    """The bound T_free(t_f) + E g(t_f) against the chain's own temperatures (ConductionChain.relax, the
    matrix exponential of the conduction nodes, not the model's linearisation): E released at a constant
    power over [0, t_f], or all in the last tenth, heats the interface more; all at t = 0 gives the bound."""
    scene = load_scene("default_driveline_thermal").with_overrides({"thermal.initial_temperature_C": 55.0})
    model = EngagementModel(scene, pressure_command=ca.SX.sym("u"))
    chain, T_oil = model.thermal.chain, 40.0
    energy, t_f = 2500.0, 0.2
    bound = temperature_bound(model, energy, t_f, t_f)
    start = np.full(chain.size, 55.0)
    at_once = chain.relax(start + energy * chain.matrix()[1], t_f, T_oil)[0]
    assert bound == pytest.approx(at_once, rel=1e-9)
    steady = chain.relax(start, t_f, T_oil, heat=energy / t_f)[0]
    late = chain.relax(chain.relax(start, 0.9 * t_f, T_oil), 0.1 * t_f, T_oil, heat=energy / (0.1 * t_f))[0]
    assert bound < steady < late


def test_temperature_bound_is_below_the_idas_peak():
    scene = load_scene("default_driveline_thermal")
    model = EngagementModel(scene, pressure_command=ca.SX.sym("u"))
    run = simulate_engagement(scene)
    t_lock = run.summary["engagement_time_s"]
    bound = temperature_bound(model, lockup_energy_bound(model, t_lock), 0.5 * t_lock, t_lock)
    peak = np.max(run.result["interface_temperature_C"][run.result.t <= t_lock])
    assert 40.0 < bound < peak


@pytest.mark.parametrize("name, words", [
    ("infeasible_dct_overload_launch", ["pressure limit", "356 N m", "409.4 N m", "0.6 MPa",
                                        "raise actuation.max_pressure to at least"]),
    ("infeasible_fill_spring_over_limit", ["kiss point", "0.512 MPa", "0.45 MPa", "piston.spring_preload"]),
    ("infeasible_paper_gw_contact", ["contact capacity", "zero gap", "N m", "roughness.sigma_*"]),
])
def test_infeasible_catalogue_clutches_are_refused_before_any_run(name, words):
    """The three deliberately infeasible clutches: one line with the limit, both numbers and the field."""
    with pytest.raises(ModelError) as info:
        EngagementOCP(load_scene(CATALOGUE / f"{name}.toml"), intervals=5)
    message = str(info.value)
    assert "\n" not in message and all(w in message for w in words), message
    assert "ipopt" not in message.lower() and "e_max" not in message


def test_the_contact_caps_the_usable_pressure_and_the_films():
    """sigma_1 = 6 um: Greenwood-Tripp carries 0.77 MPa at zero gap, below the 1.5 MPa limit. The step for
    the fastest lock-up and the clamp stop at the contact's pressure at the film floor, and the films
    may not go below that floor."""
    scene = default_scene().with_overrides({"roughness.sigma_1": 6e-6})
    model = EngagementModel(scene, pressure_command=ca.SX.sym("u"))
    film = model.film
    assert zero_gap_pressure(film) == pytest.approx(0.77e6, rel=0.01)
    p = usable_pressure(model, 1.5e6)
    assert p == pytest.approx(float(film.contact_force(FILM_FLOOR * film.sigma)) / film.area, rel=1e-12)
    assert p < zero_gap_pressure(film)
    clamp = ClampModel(scene)
    least, hardest = clamp.pressure_range()
    assert hardest == pytest.approx(p) and clamp.settled_films(hardest)[0] == pytest.approx(FILM_FLOOR * film.sigma,
                                                                                              rel=1e-6)


def test_a_profile_pressing_beyond_the_contact_is_held_within_it_for_the_baseline():
    """sigma_1 = 6 um: the scene's own 0.8 MPa presses harder than the 0.77 MPa the contact carries at zero gap,
    so its own run is refused; the optimiser's baseline is the same profile held at the usable pressure,
    which the contact check passes. The default scene keeps its own profile."""
    scene = default_scene().with_overrides({"roughness.sigma_1": 6e-6})
    model = EngagementModel(scene, pressure_command=ca.SX.sym("u"))
    with pytest.raises(PhysicalRangeError):
        check_contact_capacity(scene)
    held, note = own_profile_within_contact(scene, model, 1.5e6)
    p = usable_pressure(model, 1.5e6)
    assert held.value("actuation.pressure") == pytest.approx(p, rel=1e-12) and p < 0.8e6
    assert held.value("actuation.initial_pressure") == scene.value("actuation.initial_pressure")
    assert held.variant("actuation") == scene.variant("actuation")
    capacity, pack = check_contact_capacity(held)
    assert pack.pressure_Pa <= capacity.pressure_Pa
    assert "\n" not in note and "0.8 MPa" in note and f"{p / 1e6:.4g} MPa" in note
    plain = default_scene()
    assert own_profile_within_contact(plain, EngagementModel(plain, pressure_command=ca.SX.sym("u")), 1.5e6) \
        == (plain, None)


def test_a_pressure_table_pressing_beyond_the_contact_is_refused_in_one_line(tmp_path):
    """A table is the user's own profile: it is not changed for the baseline but refused, naming the capacity."""
    table = tmp_path / "pressure.csv"
    table.write_text("t_s,p_Pa\n0,0\n0.05,8e5\n", encoding="utf-8")
    scene = default_scene().with_overrides({"roughness.sigma_1": 6e-6, "actuation.model": "table",
                                            "actuation.file": str(table),
                                            "actuation.time_constant": None})
    model = EngagementModel(scene, pressure_command=ca.SX.sym("u"))
    with pytest.raises(PhysicalRangeError) as info:
        own_profile_within_contact(scene, model, 1.5e6)
    message = str(info.value)
    assert "\n" not in message and "carries at most 0.771 MPa at zero gap" in message
    assert "actuation.file" in message and message.count("contact:") == 1      # the table is the field to change


def test_a_clamp_margin_the_pack_cannot_hold_names_the_largest():
    scene = default_scene().with_overrides({"roughness.sigma_1": 5e-6})
    clamp = ClampModel(scene)
    largest = clamp.largest_margin()
    assert 1.0 < largest < 1.3
    with pytest.raises(ModelError) as info:
        clamp.clamp_pressure(1.3)
    message = str(info.value)
    assert "\n" not in message and f"--clamp-margin must be at most {math.floor(largest * 1000) / 1000:.3f}" in message
    assert "contact" in message and "actuation.max_pressure" not in message


def test_spring_applied_clamp_presses_with_less_pressure():
    """A spring-applied brake: pressure releases it, so the clamp pressure sits below the release pressure
    and its settled capacity is the margin times the locked torque."""
    scene = load_scene(CATALOGUE / "winch_sahr_brake_gear_oil_50C.toml")
    clamp = ClampModel(scene)
    least, hardest = clamp.pressure_range()
    assert hardest == 0.0 and least > 0.0
    p = clamp.clamp_pressure(1.3)
    assert 0.0 < p < least
    assert clamp.capacity(p) == pytest.approx(1.3 * abs(clamp.locked_torque()), rel=1e-6)


def test_clamp_of_a_pack_with_plate_masses_is_its_massless_twins():
    from clutchocp.optimal.models import SceneModels, quasi_static_scene
    scene = load_scene(CATALOGUE / "helicopter_spring_applied_masses_2face_60C.toml")
    clamp = SceneModels(scene).clamp()
    assert clamp.clamp_pressure(1.3) == pytest.approx(ClampModel(quasi_static_scene(scene)).clamp_pressure(1.3))


def test_a_prescribed_input_with_a_rising_load_locks_carrying_its_load_at_the_input_speed():
    """tractor PTO: the load rises with speed squared; at the start (output at rest) it is zero, at lock-up
    it is the rated 900 N m. The problem must know the lock carries torque."""
    scene = load_scene(CATALOGUE / "tractor_pto_clutch_60C.toml")
    ocp = EngagementOCP(scene, intervals=5)
    assert ocp.lock_torque == pytest.approx(900.0, rel=1e-3) and ocp.holds_torque


def test_temperature_limit_below_what_the_lockup_energy_gives_is_refused():
    ocp = EngagementOCP(load_scene("default_driveline_thermal"), intervals=5, max_temperature_C=45.0)
    with pytest.raises(ModelError) as info:
        ocp.solve()
    message = str(info.value)
    assert "\n" not in message and "--max-temperature must be at least" in message and "45 degC" in message
    least = float(message.split("--max-temperature must be at least ")[1].split(" degC")[0])
    assert 45.0 < least < 82.1                     # the optimum at the default limits peaks at 82.1 degC


def test_specific_power_limit_below_what_the_lockup_energy_needs_is_refused(scene):
    """0.15 W/mm^2 is above the open pack's drag at t = 0 (0.0995 W/mm^2) but 2500 J over 39 320 mm^2
    take 0.42 s at that rate: no lock-up by 0.3 s."""
    ocp = EngagementOCP(scene, intervals=5, max_specific_power_W_mm2=0.15)
    with pytest.raises(ModelError) as info:
        ocp.solve(t_max=0.3)
    message = str(info.value)
    area = 4 * ocp.model.film.area * 1e6
    need = 0.5 * (0.25 * 2 / 2.25) * 150**2 / (area * 0.3)
    assert "\n" not in message and f"--max-specific-power must be at least {need:.4g} W/mm^2" in message
    assert "--t-max at least" in message


def test_specific_power_limit_below_the_open_packs_drag_is_refused(scene):
    """The open pack's drag at t = 0 (viscous torque at the initial gap times the slip) over the friction area."""
    ocp = EngagementOCP(scene, intervals=5, max_specific_power_W_mm2=0.05)
    with pytest.raises(ModelError) as info:
        ocp.solve(t_max=0.3)
    message = str(info.value)
    run = simulate_engagement(scene)
    drag = run.result["interface_heat_power_W"][0] / (4 * ocp.model.film.area * 1e6)
    assert "\n" not in message and f"--max-specific-power must be at least {drag:.4g} W/mm^2" in message


def test_solver_statuses_are_said_in_words():
    for status in ("Infeasible_Problem_Detected", "Maximum_Iterations_Exceeded", "Invalid_Number_Detected",
                   "Something_New"):
        text = solver_verdict(status)
        assert "_" not in text and "ipopt" not in text.lower()


def test_native_output_is_caught_not_printed(capfd):
    """What C code writes to file descriptors 1 and 2 inside the block is handed over, not printed."""
    import os
    from clutchocp.optimal.quiet import native_output_caught
    print("before", flush=True)
    with native_output_caught() as caught:
        os.write(1, b"native stdout\n")
        os.write(2, b"CasADi - WARNING(NaN detected)\n")
    print("after", flush=True)
    out, err = capfd.readouterr()
    assert out == "before\nafter\n" and err == ""
    assert caught == ["native stdout\nCasADi - WARNING(NaN detected)"]
