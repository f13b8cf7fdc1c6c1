"""One scene field: its raw TOML value checked and converted to SI (used by the loader and the uncertainty)."""

import difflib
import math
import re

import numpy as np

from ..errors import ParameterTypeError, PhysicalRangeError, UnitError, UnknownVariantError
from ..units import to_si
from .schema import CHECKS

# Units a number outside its key's span (schema.Span) was probably meant in, most likely first.
LIKELY_UNITS = {
    "m": ("mm", "um", "cm", "nm"), "m^2": ("mm^2", "cm^2"), "1/m^2": ("1/mm^2", "1/um^2"),
    "Pa": ("bar", "MPa", "kPa", "GPa"), "Pa s": ("mPa s",), "m^2/s": ("cSt",), "kg/m^3": ("g/cm^3",),
    "rad/s": ("rpm",), "kg m^2": ("kg cm^2",), "kg": ("g",), "s": ("ms",), "N/m": ("N/mm",),
    "N m": ("kN m",), "m/s": ("mm/s",), "degC": ("K", "degF"), "J/K": ("kJ/K",), "J/kg/K": ("kJ/kg/K",),
    "W/m^2/K": ("kW/m^2/K",),
}
_WRITTEN = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(.*?)\s*$")


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


def _as_written(raw, spec):
    """(number, unit) as the scene wrote the value; a plain number is in SI (the key's unit)."""
    if isinstance(raw, str):
        match = _WRITTEN.match(raw)
        if match:
            return float(match.group(1)), match.group(2) or spec.dim
    return float(raw), spec.dim


def _likely_units(name, raw, spec):
    """"; did you mean 85 mm?" for the units that put the number as written inside the key's typical span."""
    number, written = _as_written(raw, spec)
    lo, hi = spec.span.typical
    meant = []
    for unit in LIKELY_UNITS.get(spec.dim, ()):
        if unit == written:
            continue
        try:
            value = to_si(f"{number:g} {unit}", spec.dim, name)
        except UnitError:
            continue
        if lo <= value <= hi:
            meant.append(f"{number:g} {unit}")
    return f"; did you mean {' or '.join(meant[:2])}?" if meant else ""


def check_span(name, raw, value, spec, notes=None):
    """Where a key's value lies against its :class:`~clutchocp.scene.schema.Span`.

    Outside the limits: a one-line PhysicalRangeError naming the typical span and the unit the number
    was probably meant in; outside the typical span: the same words appended to ``notes`` (a warning,
    the run goes on); 0 of a key whose span has ``zero`` passes.
    """
    span = spec.span
    if span is None or (span.zero and value == 0):
        return
    (lo, hi), (low, high) = span.typical, span.limit
    if lo <= value <= hi:
        return
    unit = "" if spec.dim == "1" else f" {spec.dim}"
    shown = raw.strip() if isinstance(raw, str) else f"{value:g}{unit}"
    typical = f"{lo:g} to {hi:g}{unit}"
    if not low <= value <= high:
        raise PhysicalRangeError(f"{name} = {shown} is not {span.what} (typical {typical}, refused outside "
                                 f"{low:g} to {high:g}{unit}){_likely_units(name, raw, spec)}")
    if notes is not None:
        notes.append(f"{name} = {shown} is unusual for {span.what} (typical {typical})"
                     f"{_likely_units(name, raw, spec)}")


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


def parse_field(name, raw, spec, density=None, notes=None):
    """Convert one raw TOML value to its SI value, or raise a one-line SceneError.

    ``density`` [kg/m^3] converts a kinematic viscosity (cSt) given for a dynamic one. A value
    outside its key's typical span (:func:`check_span`) adds a warning to the list ``notes``.
    """
    unit_hint = "" if spec.dim == "1" else f" (SI, {spec.dim})"
    if spec.kind == "quantity":
        if isinstance(raw, (list, dict)):
            raise ParameterTypeError(f"{name}: expected one number or quantity in {spec.dim}, got a {type(raw).__name__}")
        value = to_si(raw, spec.dim, name, density=density)
        _check_value(name, value, spec, unit_hint)
        check_span(name, raw, value, spec, notes)
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
            check_span(f"{name}[{i}]", item, value, spec, notes)
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
