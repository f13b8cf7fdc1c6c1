"""The lumped thermal part: closed forms, energy conservation, an absent part, coupling to the laws."""

import math

import casadi as ca
import numpy as np
import pytest

from clutchocp.engagement.model import EngagementModel
from clutchocp.engagement.run import simulate_engagement
from clutchocp.engagement.thermal import LumpedPlates, NoThermal, plate_thermal
from clutchocp.errors import MissingParameterError, SceneError
from clutchocp.physics import thermal
from clutchocp.scene import load_scene

THERMAL_KEYS = {"thermal.oil_temperature_C": 40, "thermal.separator_heat_capacity": "142 J/K",
                "thermal.friction_plate_heat_capacity": "144 J/K", "thermal.heat_partition": 0.961,
                "thermal.convection_coefficient": "1000 W/m^2 K"}


@pytest.fixture(scope="module")
def thermal_scene():
    return load_scene("default_driveline_thermal")


def test_effusivity_partition_and_contact_temperature():
    steel = thermal.effusivity(50.0, 7850.0, 460.0)
    assert steel == pytest.approx(13436.9, abs=0.1)
    a = thermal.heat_partition(steel, steel)
    assert a == 0.5                                   # equal bodies share the heat equally
    assert thermal.interface_temperature(100.0, 50.0, a) == 75.0
    assert thermal.interface_temperature(80.0, 20.0, 1.0) == 80.0


def test_constant_heat_reproduces_closed_form(thermal_scene):
    """The part's equations under a constant heat input, integrated by CVODES, against
    T = T_oil + Q/G + (T0 - T_oil - Q/G) exp(-G t / C) for each plate group."""
    part = LumpedPlates(thermal_scene.with_overrides({"thermal.initial_temperature_C": 90}))
    Q = ca.SX.sym("Q")
    rates = part.rates(Q)
    x = ca.vertcat(part.symbols["T_friction"], part.symbols["T_separator"])
    dae = {"x": x, "p": Q, "ode": ca.vertcat(rates["T_friction"], rates["T_separator"])}
    times = np.linspace(0.0, 10.0, 11)
    sim = ca.integrator("heat", "cvodes", dae, 0.0, times[1:], {"reltol": 1e-11, "abstol": 1e-9})
    q = 20e3
    out = np.array(sim(x0=[90.0, 90.0], p=q)["xf"])
    G = part.conductance
    expected_f = thermal.constant_heat_temperature(times[1:], (1 - part.partition) * q, part.C_friction, G, 90.0, 40.0)
    expected_s = thermal.constant_heat_temperature(times[1:], part.partition * q, part.C_separator, G, 90.0, 40.0)
    np.testing.assert_allclose(out[0], expected_f, rtol=1e-8)
    np.testing.assert_allclose(out[1], expected_s, rtol=1e-8)
    # Without convection the rise is linear: Q t / C (the limit of the closed form).
    assert thermal.constant_heat_temperature(2.0, 100.0, 50.0, 0.0, 20.0, 40.0) == pytest.approx(24.0)
    assert thermal.constant_heat_temperature(2.0, 100.0, 50.0, 1e-9, 20.0, 40.0) == pytest.approx(24.0, rel=1e-9)


def test_no_heat_loss_stores_exactly_the_dissipated_energy(thermal_scene):
    run = simulate_engagement(thermal_scene.with_overrides({"thermal.convection_coefficient": 0}))
    energy = run.summary["energy"]
    assert energy["heat_to_oil_J"] == 0.0
    assert energy["heat_stored_J"] == pytest.approx(run.summary["interface_heat_J"], rel=1e-6)
    assert run.summary["energy_balance_rel_error"] < 1e-6
    # Stored heat from the temperatures: C_f dT_f + C_s dT_s.
    stored = 144 * (run.summary["final_friction_plate_temperature_C"] - 40) + 142 * (
        run.summary["final_separator_temperature_C"] - 40)
    assert stored == pytest.approx(energy["heat_stored_J"], rel=1e-9)


def test_energy_balance_with_convection_closes(thermal_scene):
    run = simulate_engagement(thermal_scene)
    s = run.summary
    assert s["energy_balance_rel_error"] < 1e-6
    assert s["energy"]["heat_to_oil_J"] > 0
    assert s["energy"]["heat_stored_J"] + s["energy"]["heat_to_oil_J"] == pytest.approx(s["interface_heat_J"],
                                                                                         rel=1e-6)
    assert s["specific_energy_J_mm2"] == pytest.approx(s["interface_heat_J"] / s["friction_area_mm2"])
    area = 4 * math.pi * (0.085**2 - 0.064**2) * 1e6
    assert s["friction_area_mm2"] == pytest.approx(area)
    assert 40 < s["final_interface_temperature_C"] < s["peak_interface_temperature_C"]


def test_absent_thermal_part_adds_no_state_and_no_equation(default_without_thermal):
    scene = default_without_thermal
    assert isinstance(plate_thermal(scene), NoThermal)
    model = EngagementModel(scene)
    assert not any(n.startswith("T_") for n in model.state_names)
    assert "E_convection" not in model.energy_terms
    assert model.n_states == 7
    with_part = EngagementModel(scene.with_overrides(THERMAL_KEYS))
    assert with_part.n_states == 9
    assert len(with_part.state_names) == len(model.state_names) + 3     # two temperatures, E_convection


def test_passive_thermal_part_leaves_the_mechanics_unchanged(default_without_thermal):
    """With a constant viscosity and friction nothing reads the temperature: the same engagement
    (default_driveline has such a part; without it the run is the same)."""
    plain = simulate_engagement(default_without_thermal)
    heated = simulate_engagement(load_scene("default_driveline"))
    assert heated.summary["engagement_time_s"] == pytest.approx(plain.summary["engagement_time_s"], rel=1e-7)
    assert heated.summary["interface_heat_J"] == pytest.approx(plain.summary["interface_heat_J"], rel=1e-6)
    assert "peak_interface_temperature_C" not in plain.summary


def test_viscosity_and_friction_read_the_interface_temperature(thermal_scene):
    model = EngagementModel(thermal_scene)
    T = ca.vertcat(model.state("T_friction"), model.state("T_separator"))
    assert ca.depends_on(ca.SX(model.film.eta), T)
    chen = EngagementModel(thermal_scene.with_overrides({"friction.model": "chen2021", "friction.mu": None}))
    T_chen = ca.vertcat(chen.state("T_friction"), chen.state("T_separator"))
    assert ca.depends_on(ca.SX(chen.film.mu(10.0, 1e6)), T_chen)
    assert isinstance(EngagementModel(load_scene("default_driveline")).film.eta, float)   # constant law


def test_hot_oil_slows_the_engagement(thermal_scene):
    """The viscous torque falls as the film heats, so the Walther oil locks later than the same oil
    held at 40 degC (default_driveline)."""
    hot = simulate_engagement(thermal_scene).summary["engagement_time_s"]
    cold = simulate_engagement(load_scene("default_driveline")).summary["engagement_time_s"]
    # Measured: 0.3029 s against 0.2847 s (+6.4 %) with the lining rough and the separator smooth,
    # where Patir-Cheng's phi_fs already lowers the viscous share; far above the event tolerance (1e-9 s).
    assert hot > 1.02 * cold


def test_scene_errors(thermal_scene, default_without_thermal):
    chen = thermal_scene.with_overrides({"friction.model": "chen2021", "friction.mu": None})
    with pytest.raises(SceneError, match="friction.temperature_C"):
        chen.with_overrides({"friction.temperature_C": 80})
    with pytest.raises(MissingParameterError, match="friction.temperature_C"):
        default_without_thermal.with_overrides({"friction.model": "chen2021", "friction.mu": None})
    with pytest.raises(SceneError, match="thermal.oil_temperature_C = 20: must be > 24.5"):
        chen.with_overrides({"thermal.oil_temperature_C": 20, "thermal.initial_temperature_C": 30})
    with pytest.raises(SceneError, match="thermal.heat_partition"):
        thermal_scene.with_overrides({"thermal.heat_partition": 1.5})
    with pytest.raises(SceneError, match="thermal.separator_heat_capacity"):
        thermal_scene.with_overrides({"thermal.separator_heat_capacity": "3 kg"})


def test_chen_friction_follows_the_heating(thermal_scene, default_without_thermal):
    """Chen 2021 Eq. 5 grips harder as the surface heats (its stick term grows with ln Theta): held
    at the 40 degC oil temperature the pack never locks within 1.5 s; with the plates heating it does."""
    chen = {"friction.model": "chen2021", "friction.mu": None}
    heated = simulate_engagement(thermal_scene.with_overrides(chen)).summary
    cold = simulate_engagement(default_without_thermal.with_overrides(
        {**chen, "friction.temperature_C": 40})).summary
    assert cold["engagement_time_s"] is None
    assert heated["engagement_time_s"] is not None
    assert heated["energy_balance_rel_error"] < 1e-6
