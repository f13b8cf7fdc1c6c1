"""Oil viscosity against temperature: Walther / ASTM D341 fit, published values, scene option."""

import casadi as ca
import numpy as np
import pytest

from clutchocp.errors import MissingParameterError, PhysicalRangeError, SceneError
from clutchocp.physics.viscosity import OilViscosity, walther_coefficients, walther_kinematic_viscosity
from clutchocp.scene import load_scene

CST = 1e-6  # m^2/s per mm^2/s


def test_fit_reproduces_its_points():
    A, B = walther_coefficients(40.0, 80.12 * CST, 100.0, 9.5 * CST)
    assert walther_kinematic_viscosity(40.0, A, B) == pytest.approx(80.12 * CST, rel=1e-12)
    assert walther_kinematic_viscosity(100.0, A, B) == pytest.approx(9.5 * CST, rel=1e-12)
    assert B > 0


def test_astm_d341_worked_examples():
    """Worked examples of the ASTM D341 extrapolation (olezol.com, 'Viscosity-temperature extrapolation
    ASTM D341'): an SAE 140 gear oil of 404 cSt at 40 degC and 28 cSt at 100 degC has 132.126 cSt at
    60 degC; an oil of 68 cSt at 40 degC and 14.85 cSt at 80 degC has 8.8 cSt at 100 degC."""
    A, B = walther_coefficients(40.0, 404 * CST, 100.0, 28 * CST)
    assert walther_kinematic_viscosity(60.0, A, B) / CST == pytest.approx(132.126, abs=5e-4)
    A, B = walther_coefficients(40.0, 68 * CST, 80.0, 14.85 * CST)
    assert walther_kinematic_viscosity(100.0, A, B) / CST == pytest.approx(8.8, abs=0.05)


# Dynamic viscosity [mPa s] at 30, 60 and 100 degC of published mineral oils: Stachowiak & Batchelor,
# Engineering Tribology (Elsevier), Table 2.3 "Dynamic viscosity and pressure-viscosity coefficients
# of some commonly used lubricants".
STACHOWIAK_TABLE_2_3 = {
    "light machine oil (38)": (38, 12.1, 5.3), "heavy machine oil (153)": (153, 34, 9.1),
    "heavy machine oil (250)": (250, 50.5, 12.6), "cylinder oil (810)": (810, 135, 26.8),
    "spindle oil (18.6)": (18.6, 6.3, 2.4), "light machine oil (45)": (45, 12, 3.9),
    "medicinal white oil": (107, 23.3, 6.4), "heavy machine oil (122)": (122, 26.3, 7.3),
    "heavy machine oil (171)": (171, 31, 7.5), "spindle oil (30.7)": (30.7, 8.6, 3.1),
    "heavy machine oil (165)": (165, 30, 6.8), "heavy machine oil (310)": (310, 44.2, 9.4),
    "cylinder oil (2000)": (2000, 180, 24),
}


def test_published_oils_between_fitting_points():
    """Fitted through the 30 and 100 degC values, the law predicts the published 60 degC value of all
    13 oils within 12 % (median within 3 %): Walther's line is a few per cent off on real oils, and
    the table is of dynamic viscosity, converted here with a constant density (which the scene
    option assumes as well)."""
    rho = 880.0
    errors = []
    for name, (e30, e60, e100) in STACHOWIAK_TABLE_2_3.items():
        A, B = walther_coefficients(30.0, e30 * 1e-3 / rho, 100.0, e100 * 1e-3 / rho)
        predicted = walther_kinematic_viscosity(60.0, A, B) * rho * 1e3
        errors.append(predicted / e60 - 1)
    errors = np.abs(errors)
    assert errors.max() < 0.12
    assert np.median(errors) < 0.03


def test_symbolic_equals_numeric():
    A, B = walther_coefficients(40.0, 30 * CST, 100.0, 6 * CST)
    theta = ca.SX.sym("theta")
    f = ca.Function("nu", [theta], [walther_kinematic_viscosity(theta, A, B)])
    for value in (20.0, 70.0, 150.0):
        assert float(f(value)) == pytest.approx(walther_kinematic_viscosity(value, A, B), rel=1e-13)


def test_fit_rejects_bad_points():
    with pytest.raises(PhysicalRangeError, match="fall"):
        walther_coefficients(40.0, 5 * CST, 100.0, 9 * CST)
    with pytest.raises(PhysicalRangeError, match="2 mm"):
        walther_coefficients(40.0, 5 * CST, 100.0, 1.5 * CST)
    with pytest.raises(PhysicalRangeError, match="different"):
        walther_coefficients(40.0, 5 * CST, 40.0, 4 * CST)


def walther_scene(**oil):
    base = load_scene("zhang2021")
    values = {"oil.viscosity": None, "oil.model": "walther", "oil.kinematic_viscosity_40C": "80.12 cSt",
              "oil.kinematic_viscosity_100C": "9.5 mm^2/s"}
    values.update({f"oil.{k}": v for k, v in oil.items()})
    return base.with_overrides(values)


def test_scene_option_and_derived_viscosity():
    scene = walther_scene(temperature_C=100)
    law = OilViscosity(scene)
    assert law.temperature_dependent
    assert scene.value("oil.viscosity") == pytest.approx(850 * 9.5 * CST, rel=1e-12)
    assert law.dynamic(40.0) == pytest.approx(850 * 80.12 * CST, rel=1e-12)
    constant = OilViscosity(load_scene("default_driveline"))
    assert not constant.temperature_dependent and constant.dynamic(120.0) == 0.0681


def test_scene_option_errors():
    with pytest.raises(MissingParameterError, match="oil.temperature_C"):
        walther_scene()
    with pytest.raises(PhysicalRangeError, match="oil.kinematic_viscosity_40C"):
        walther_scene(temperature_C=40, kinematic_viscosity_100C="90 cSt")
    thermal = load_scene("default_driveline_thermal")
    with pytest.raises(SceneError, match="thermal.oil_temperature_C"):
        thermal.with_overrides({"oil.temperature_C": 40})
