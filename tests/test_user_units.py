"""Units a clutch engineer types: mPa s, cSt with the oil's density, psi, degC, Hz for a rotation."""

import math

import pytest

from clutchocp.errors import UnitError
from clutchocp.scene import load_scene
from clutchocp.units import to_si


def test_millipascal_seconds_and_centipoise_agree():
    assert to_si("40 mPa s", "Pa s", "oil.viscosity") == pytest.approx(0.040, rel=1e-15)
    assert to_si("40 cP", "Pa s", "oil.viscosity") == pytest.approx(0.040, rel=1e-15)


def test_centistokes_need_a_density_and_use_it():
    # 46 cSt = 46e-6 m^2/s; at 870 kg/m^3 that is mu = rho nu = 0.04002 Pa s
    assert to_si("46 cSt", "Pa s", "oil.viscosity", density=870.0) == pytest.approx(46e-6 * 870.0, rel=1e-15)
    with pytest.raises(UnitError, match="kinematic viscosity.*oil.density"):
        to_si("46 cSt", "Pa s", "oil.viscosity")


def test_a_scene_in_centistokes_takes_its_own_density():
    scene = load_scene("zhang2021", overrides={"oil.viscosity": "80 cSt", "oil.density": "850 kg/m^3"})
    assert scene.value("oil.viscosity") == pytest.approx(80e-6 * 850.0, rel=1e-15)


def test_psi_is_the_pound_force_per_square_inch():
    # 1 psi = 0.45359237 kg x 9.80665 m/s^2 / (0.0254 m)^2, exact by definition
    assert to_si("1 psi", "Pa", "actuation.pressure") == pytest.approx(0.45359237 * 9.80665 / 0.0254**2, rel=1e-15)
    assert to_si("87 psi", "Pa", "actuation.pressure") == pytest.approx(5.998e5, rel=1e-3)   # ~6 bar


def test_bar_is_still_fine():
    assert to_si("6 bar", "Pa", "actuation.pressure") == 6e5


def test_temperatures_in_degC_kelvin_and_fahrenheit():
    assert to_si("80 degC", "degC", "friction.temperature_C") == 80.0
    assert to_si("353.15 K", "degC", "friction.temperature_C") == pytest.approx(80.0, abs=1e-12)
    assert to_si("176 degF", "degC", "friction.temperature_C") == pytest.approx(80.0, abs=1e-12)
    assert to_si(80, "degC", "friction.temperature_C") == 80.0


def test_deg_alone_is_an_angle_and_not_a_temperature():
    with pytest.raises(UnitError, match="degC"):
        to_si("80 deg", "degC", "friction.temperature_C")


def test_a_scene_temperature_in_kelvin():
    scene = load_scene("chen2021", overrides={"operating.temperature_C": "373.15 K"})
    assert scene.value("operating.temperature_C") == pytest.approx(100.0, abs=1e-12)


def test_hertz_for_an_angular_speed_is_a_rotation_frequency():
    # 159.155 Hz is 1000 rad/s, not 159 rad/s
    assert to_si("159.155 Hz", "rad/s", "driveline.input_speed") == pytest.approx(1000.0, rel=1e-5)
    assert to_si("50 Hz", "rad/s", "driveline.input_speed") == pytest.approx(100 * math.pi, rel=1e-15)
    assert to_si("3000 rpm", "rad/s", "driveline.input_speed") == pytest.approx(100 * math.pi, rel=1e-15)
    # a plain rate (1/s) keeps 1 Hz = 1/s
    assert to_si("100 Hz", "1/s", "controller.rate") == 100.0


def test_a_scene_speed_in_hertz():
    scene = load_scene("zhang2021", overrides={"driveline.input_speed": "159.1549431 Hz"})
    assert scene.value("driveline.input_speed") == pytest.approx(1000.0, rel=1e-9)
