"""Quantities with units, as people write them in scene files ("6000 rpm", "8.4 um", "0.02 Pa s").

A quantity string is a number followed by a unit expression: unit symbols joined by spaces or
``*`` (product) and ``/`` (quotient; everything after a ``/`` divides), each with an optional
exponent ``^n`` or ``**n``.  Examples: ``"0.02 Pa s"``, ``"775 kg/m^3"``, ``"7e7 1/m^2"``,
``"190 N/mm"``, ``"2 kg m^2"``.  The value is converted to SI and its dimension is checked
against the one the field expects.  Angles count as dimensionless (rad), so rpm -> rad/s.

Units a clutch engineer types: ``mPa s`` and ``cP`` (dynamic viscosity), ``cSt`` and ``St``
(kinematic viscosity: converted with the oil's density, see :func:`to_si`), ``psi``, ``bar``;
``Hz`` in an angular-speed field is a rotation frequency (1 Hz = 2 pi rad/s; in a 1/s field,
e.g. a sample rate, 1 Hz = 1/s). Temperatures (fields in deg C, ``dimension="degC"``) take
``degC``, ``K`` or ``degF``; ``deg`` alone is an angle and is refused there.
"""

import functools
import math
import re

from .errors import UnitError

# Dimension vectors: (kg, m, s, K).
_DIMENSIONLESS = (0, 0, 0, 0)
_KG, _M, _S, _K = (1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (0, 0, 0, 1)
PSI = 6894.757293168361      # Pa per pound-force per square inch (0.45359237 kg * 9.80665 m/s^2 / 0.0254^2 m^2)


def _combine(*pairs):
    """Dimension of a product of base dimensions raised to powers."""
    out = [0, 0, 0, 0]
    for dim, power in pairs:
        for i, d in enumerate(dim):
            out[i] += d * power
    return tuple(out)


_N = _combine((_KG, 1), (_M, 1), (_S, -2))
_PA = _combine((_N, 1), (_M, -2))
_J = _combine((_N, 1), (_M, 1))
_W = _combine((_J, 1), (_S, -1))

# symbol -> (factor to SI, dimension)
_UNITS = {
    "m": (1.0, _M), "mm": (1e-3, _M), "um": (1e-6, _M), "µm": (1e-6, _M), "μm": (1e-6, _M),
    "nm": (1e-9, _M), "cm": (1e-2, _M), "km": (1e3, _M),
    "kg": (1.0, _KG), "g": (1e-3, _KG), "t": (1e3, _KG),
    "s": (1.0, _S), "ms": (1e-3, _S), "us": (1e-6, _S), "min": (60.0, _S), "h": (3600.0, _S),
    "N": (1.0, _N), "kN": (1e3, _N), "mN": (1e-3, _N),
    "Pa": (1.0, _PA), "kPa": (1e3, _PA), "MPa": (1e6, _PA), "GPa": (1e9, _PA), "bar": (1e5, _PA),
    "mPa": (1e-3, _PA), "mbar": (1e2, _PA), "psi": (PSI, _PA),
    "J": (1.0, _J), "kJ": (1e3, _J), "W": (1.0, _W), "kW": (1e3, _W),
    "rad": (1.0, _DIMENSIONLESS), "deg": (math.pi / 180.0, _DIMENSIONLESS),
    "rev": (2 * math.pi, _DIMENSIONLESS),
    "rpm": (2 * math.pi / 60.0, _combine((_S, -1))),
    "Hz": (1.0, _combine((_S, -1))),
    "cP": (1e-3, _combine((_PA, 1), (_S, 1))), "P": (0.1, _combine((_PA, 1), (_S, 1))),
    "cSt": (1e-6, _combine((_M, 2), (_S, -1))), "St": (1e-4, _combine((_M, 2), (_S, -1))),
    "K": (1.0, _K), "degC": (1.0, _K), "degF": (5.0 / 9.0, _K),
    "L": (1e-3, _combine((_M, 3))),
    "percent": (0.01, _DIMENSIONLESS), "%": (0.01, _DIMENSIONLESS),
    "1": (1.0, _DIMENSIONLESS),
}

# Field dimensions by name, as schema entries write them.
DIMENSIONS = {
    "1": _DIMENSIONLESS,
    "m": _M, "m^2": _combine((_M, 2)), "m^4": _combine((_M, 4)), "1/m^2": _combine((_M, -2)),
    "kg": _KG, "s": _S, "1/s": _combine((_S, -1)), "rad/s": _combine((_S, -1)),
    "rad/s^2": _combine((_S, -2)),
    "N": _N, "N/m": _combine((_N, 1), (_M, -1)), "N m": _J, "N m s^2": _combine((_J, 1), (_S, 2)),
    "N m/(rad/s)^2": _combine((_J, 1), (_S, 2)), "N m s": _combine((_J, 1), (_S, 1)),
    "N s/m": _combine((_N, 1), (_S, 1), (_M, -1)),
    "Pa": _PA, "Pa s": _combine((_PA, 1), (_S, 1)), "kg/m^3": _combine((_KG, 1), (_M, -3)),
    "kg m^2": _combine((_KG, 1), (_M, 2)), "J": _J, "W": _W, "m/s": _combine((_M, 1), (_S, -1)),
    "rad": _DIMENSIONLESS, "m^2/s": _combine((_M, 2), (_S, -1)),
    "J/K": _combine((_J, 1), (_K, -1)), "W/m^2/K": _combine((_W, 1), (_M, -2), (_K, -1)),
    "W/m/K": _combine((_W, 1), (_M, -1), (_K, -1)), "J/kg/K": _combine((_J, 1), (_KG, -1), (_K, -1)),
    "degC": _K,       # a temperature in deg C (the value is returned in deg C, not K)
}

_KINEMATIC = _combine((_M, 2), (_S, -1))
_DYNAMIC = _combine((_PA, 1), (_S, 1))
# offsets of absolute temperature scales, to deg C: T[degC] = factor * value + offset
_TEMPERATURE = {"degC": (1.0, 0.0), "K": (1.0, -273.15), "degF": (5.0 / 9.0, -32.0 * 5.0 / 9.0)}

_NUMBER = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(.*?)\s*$")
_FACTOR = re.compile(r"^([^\s^*/]+?)(?:(?:\^|\*\*)([-+]?\d+))?$")


@functools.lru_cache(maxsize=1024)
def _parse_unit(expr, field, angular=False):
    """Return (factor to SI, dimension) of a unit expression such as ``"kg/m^3"``.

    ``angular``: the field is an angular speed, so a frequency in Hz counts 2 pi rad per cycle.
    Cached: a sweep re-reads the same scene's unit strings at every point (the result depends on
    the arguments alone; a unit that does not parse raises each time, errors are not cached).
    """
    text = expr.replace("·", " ").replace("**", "^")
    text = re.sub(r"\s*\^\s*", "^", text)
    text = re.sub(r"\s*/\s*", " / ", text)
    text = re.sub(r"\s*\*\s*", " ", text)
    factor, dim, sign = 1.0, _DIMENSIONLESS, 1
    for token in text.split():
        if token == "/":
            sign = -1
            continue
        match = _FACTOR.match(token)
        if not match or match.group(1) not in _UNITS:
            raise UnitError(
                f"{field}: unit '{expr}' does not parse (unknown symbol '{token}'); "
                f"known symbols: {', '.join(sorted(k for k in _UNITS if k.isascii()))}"
            )
        power = sign * int(match.group(2) or 1)
        unit_factor, unit_dim = _UNITS[match.group(1)]
        if angular and match.group(1) == "Hz":
            unit_factor = 2 * math.pi          # cycles per second -> rad/s
        factor *= unit_factor**power
        dim = _combine((dim, 1), (unit_dim, power))
    return factor, dim


def to_si(value, dimension, field, density=None):
    """Convert a scene value (number or ``"number unit"`` string) to an SI float.

    Parameters
    ----------
    value : float or int or str
        A plain number (taken as SI) or a quantity string such as ``"6000 rpm"``.
    dimension : str
        Expected dimension, a key of :data:`DIMENSIONS` (e.g. ``"Pa s"``).
    field : str
        Dotted field name used in error messages.
    density : float, optional
        Density [kg/m^3] that turns a kinematic viscosity (``"46 cSt"``) into the dynamic one a
        ``"Pa s"`` field holds (mu = rho nu). Without it a kinematic viscosity is refused.

    Returns
    -------
    float
        The value in SI units.
    """
    if isinstance(value, bool):
        raise UnitError(f"{field}: expected a number or a quantity in {dimension}, got true/false")
    if isinstance(value, (int, float)):
        return float(value)
    if not isinstance(value, str):
        raise UnitError(f"{field}: expected a number or a quantity in {dimension}, got {type(value).__name__}")
    match = _NUMBER.match(value)
    if not match:
        raise UnitError(f"{field}: '{value}' is not a number followed by a unit (e.g. '0.02 Pa s')")
    number, unit = float(match.group(1)), match.group(2)
    if not unit:
        return number
    if dimension == "degC":
        if unit.strip() not in _TEMPERATURE:
            raise UnitError(f"{field}: unit '{unit}' is not a temperature; write degC, K or degF "
                            "(deg alone is an angle)")
        scale, offset = _TEMPERATURE[unit.strip()]
        return scale * number + offset
    factor, dim = _parse_unit(unit, field, angular=dimension in ("rad/s", "rad/s^2"))
    if dimension == "Pa s" and dim == _KINEMATIC:
        if density is None:
            raise UnitError(f"{field}: '{value}' is a kinematic viscosity; give the oil's density "
                            "(oil.density) or a dynamic viscosity such as '0.04 Pa s' or '40 mPa s'")
        return number * factor * density                      # mu = rho nu
    if dim != DIMENSIONS[dimension]:
        raise UnitError(f"{field}: unit '{unit}' is not a {dimension} quantity (expected units of {dimension})")
    return number * factor
