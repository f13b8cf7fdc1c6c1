"""Quantity strings -> SI, checked against hand conversions."""

import math

import pytest

from clutchocp.errors import UnitError
from clutchocp.units import to_si


@pytest.mark.parametrize(
    "text, dim, expected",
    [
        ("6000 rpm", "rad/s", 6000 * 2 * math.pi / 60),
        ("8.4 um", "m", 8.4e-6),
        ("8.4 µm", "m", 8.4e-6),
        ("0.02 Pa s", "Pa s", 0.02),
        ("20 cP", "Pa s", 0.02),
        ("2 MPa", "Pa", 2e6),
        ("2 bar", "Pa", 2e5),
        ("775 kg/m^3", "kg/m^3", 775.0),
        ("775 kg m^-3", "kg/m^3", 775.0),
        ("7e7 1/m^2", "1/m^2", 7e7),
        ("0.1 1/mm^2", "1/m^2", 1e5),
        ("190 N/mm", "N/m", 190e3),
        ("2 kg m^2", "kg m^2", 2.0),
        ("2 kg*m**2", "kg m^2", 2.0),
        ("30 deg", "rad", math.pi / 6),
        ("150 N m", "N m", 150.0),
        ("20 ms", "s", 0.02),
        ("-3.5e-2 m", "m", -0.035),
        ("1.5", "m", 1.5),
        (42, "Pa", 42.0),
    ],
)
def test_quantities_convert_to_si(text, dim, expected):
    assert to_si(text, dim, "f") == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize(
    "text, dim, needle",
    [
        ("8.4 furlongs", "m", "unknown symbol 'furlongs'"),
        ("8.4 kg", "m", "not a m quantity"),
        ("fast", "m/s", "not a number followed by a unit"),
        ("1 rpm", "Pa", "not a Pa quantity"),
        (True, "Pa", "true/false"),
    ],
)
def test_bad_units_name_the_field(text, dim, needle):
    with pytest.raises(UnitError, match="my.field") as info:
        to_si(text, dim, "my.field")
    assert needle in str(info.value)


def test_cached_unit_parse_equals_a_fresh_parse_and_keeps_refusing():
    """The unit parse is cached (a sweep re-reads its scene at every point): the cached answer is
    the uncached function's, the Hz rule still depends on the field, and a unit that does not
    parse is refused every time with the field that asked."""
    from clutchocp.units import _parse_unit

    for text in ("kg/m^3", "N/mm", "mPa s", "Hz", "1/m^2"):
        for angular in (False, True):
            assert _parse_unit(text, "a.b", angular) == _parse_unit.__wrapped__(text, "a.b", angular)
    assert to_si("1 Hz", "rad/s", "drive.speed") == pytest.approx(2 * math.pi, rel=1e-15)
    assert to_si("1 Hz", "1/s", "tcu.rate") == 1.0
    for field in ("oil.viscosity", "oil.density"):
        for _ in range(2):
            with pytest.raises(UnitError, match=f"^{field}: unit 'Pa x'"):
                to_si("0.04 Pa x", "Pa s", field)
