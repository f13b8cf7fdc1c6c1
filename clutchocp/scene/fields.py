"""One scene field: its raw TOML value checked and converted to SI (used by the loader and the uncertainty)."""

import difflib
import math

import numpy as np

from ..errors import ParameterTypeError, PhysicalRangeError, UnknownVariantError
from ..units import to_si
from .schema import CHECKS


def suggest(word, options):
    """"; did you mean 'x'?" for the closest of ``options``, or an empty string."""
    close = difflib.get_close_matches(word, list(options), n=1, cutoff=0.5)
    return f"; did you mean '{close[0]}'?" if close else ""


def _check_value(name, value, spec, unit_hint):
    ok, phrase = CHECKS[spec.check]
    if not math.isfinite(value):
        raise PhysicalRangeError(f"{name} = {value}: must be a finite number {phrase}")
    if not ok(value):
        raise PhysicalRangeError(f"{name} = {value:g}{unit_hint}: must be {phrase}")


def check_value(name, value, spec):
    """Check an SI value given outside a scene file (an API argument) as the scene field ``spec`` would.

    Raises ParameterTypeError (not a number, or not a whole number for an int field) or
    PhysicalRangeError (outside the field's range), naming ``name``.
    """
    whole = spec.kind == "int"
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) or \
            (whole and not float(value).is_integer()):
        raise ParameterTypeError(f"{name} = {value!r}: expected {'a whole number' if whole else 'a number'}")
    _check_value(name, float(value), spec, "" if spec.dim == "1" else f" ({spec.dim})")


def parse_field(name, raw, spec, density=None):
    """Convert one raw TOML value to its SI value, or raise a one-line SceneError.

    ``density`` [kg/m^3] converts a kinematic viscosity (cSt) given for a dynamic one.
    """
    unit_hint = "" if spec.dim == "1" else f" (SI, {spec.dim})"
    if spec.kind == "quantity":
        if isinstance(raw, (list, dict)):
            raise ParameterTypeError(f"{name}: expected one number or quantity in {spec.dim}, got a {type(raw).__name__}")
        value = to_si(raw, spec.dim, name, density=density)
        _check_value(name, value, spec, unit_hint)
        return value
    if spec.kind == "quantity_list":
        items = raw if isinstance(raw, list) else [raw]
        if not items:
            raise ParameterTypeError(f"{name}: expected at least one value in {spec.dim}")
        values = []
        for i, item in enumerate(items):
            if isinstance(item, (list, dict)):
                raise ParameterTypeError(f"{name}[{i}]: expected a number or quantity in {spec.dim}")
            value = to_si(item, spec.dim, f"{name}[{i}]")
            _check_value(f"{name}[{i}]", value, spec, unit_hint)
            values.append(value)
        return np.array(values)
    if spec.kind == "int":
        if isinstance(raw, bool) or not isinstance(raw, int):
            raise ParameterTypeError(f"{name}: expected a whole number, got {raw!r}")
        _check_value(name, raw, spec, "")
        return raw
    if spec.kind == "bool":
        if not isinstance(raw, bool):
            raise ParameterTypeError(f"{name}: expected true or false, got {raw!r}")
        return raw
    if spec.kind == "str":
        if not isinstance(raw, str):
            raise ParameterTypeError(f"{name}: expected text, got {raw!r}")
        return raw
    if spec.kind == "str_list":
        if not isinstance(raw, list) or not all(isinstance(x, str) for x in raw):
            raise ParameterTypeError(f"{name}: expected a list of text lines")
        return tuple(raw)
    if spec.kind == "choice":
        if raw not in spec.choices:
            raise UnknownVariantError(f"{name} = {raw!r}: allowed values are {', '.join(spec.choices)}")
        return raw
    raise AssertionError(f"schema error: unknown field kind {spec.kind}")
