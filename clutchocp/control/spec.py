"""Controller spec files (TOML in controllers/): reading one and checking its tables against a schema.

A schema maps each key of a table to ``(dimension, check or choices, default)``: the dimension is a
unit dimension for :func:`clutchocp.units.to_si` (quantities may carry units, ``"10 ms"``,
``"60 deg"``), or ``"str"``, ``"bool"``, ``"choice"`` (the allowed values in place of the check) or
``"fractions"`` (a list of numbers); the check names an entry of :data:`CHECKS`. Every mistake
raises a :class:`~clutchocp.errors.SceneError` subclass whose one-line message names the field.
"""

import math

from ..errors import (
    MissingParameterError,
    ParameterTypeError,
    PhysicalRangeError,
    SceneError,
    UnknownKeyError,
    UnknownVariantError,
)
from ..scene.fields import suggest
from ..scene.loader import read_toml
from ..units import to_si

# check name -> (test on the SI value, what is allowed)
CHECKS = {
    "positive": (lambda v: v > 0, "> 0"),
    "nonnegative": (lambda v: v >= 0, ">= 0"),
    "fraction": (lambda v: 0 < v < 1, "in (0, 1)"),
    "angle": (lambda v: 0 < v < math.pi / 2, "in (0, 90) deg"),
    "above_one": (lambda v: v > 1, "> 1"),
    # LQI weights act on states scaled to about 1; beyond a ratio of 1e12 between two weights the
    # Riccati equation cannot be solved in double precision (integral_weight = 1e300 failed in LAPACK)
    "weight": (lambda v: 0 <= v <= 1e6, "in [0, 1e6] (weights on scaled states; larger ones make the LQR "
                                        "problem numerically singular)"),
    "positive_weight": (lambda v: 1e-6 <= v <= 1e6, "in [1e-6, 1e6] (weights on scaled states; others make "
                                                    "the LQR problem numerically singular)"),
}


def read_spec(name_or_path, parse):
    """Read a spec file of controllers/ (built-in name or path) and validate it with ``parse``.

    Errors name the file; the returned spec keeps its ``path``.
    """
    path, raw = read_toml(name_or_path, "controllers", "controller spec")
    try:
        spec = parse(raw)
    except SceneError as exc:
        raise type(exc)(f"{path.name}: {exc}") from None
    spec.path = path
    return spec


def check_tables(raw, tables, what):
    """``raw`` (parsed TOML) is a dict whose tables are all among ``tables``; ``what`` names the spec kind."""
    if not isinstance(raw, dict):
        raise ParameterTypeError(f"{what}: expected TOML tables")
    for table in raw:
        if table not in tables:
            raise UnknownKeyError(f"[{table}]: unknown table{suggest(table, tables)} (allowed: {', '.join(tables)})")


def parse_table(name, table, schema, required=()):
    """The values of table ``name`` in SI, defaults filled in; the keys in ``required`` must be given.

    Parameters
    ----------
    name : str
        Table name, for messages.
    table : dict
        The raw TOML table.
    schema : dict
        ``key -> (dimension, check or choices, default)`` (see the module docstring).
    required : sequence of str
        Keys without a default that must be present.

    Returns
    -------
    dict
    """
    if not isinstance(table, dict):
        raise ParameterTypeError(f"[{name}]: expected a table of parameters, got {table!r}")
    for key in table:
        if key not in schema:
            raise UnknownKeyError(f"{name}.{key}: unknown key in [{name}]{suggest(key, schema)} "
                                  f"(allowed: {', '.join(schema)})")
    out = {}
    for key, (dim, check, default) in schema.items():
        field_name = f"{name}.{key}"
        if key not in table:
            if default is None and key in required:
                raise MissingParameterError(f"{field_name}: missing required parameter")
            out[key] = default
            continue
        out[key] = _value(field_name, table[key], dim, check)
    return out


def _value(name, raw, dim, check):
    if dim == "str":
        if not isinstance(raw, str):
            raise ParameterTypeError(f"{name}: expected text, got {raw!r}")
        return raw
    if dim == "bool":
        if not isinstance(raw, bool):
            raise ParameterTypeError(f"{name}: expected true or false, got {raw!r}")
        return raw
    if dim == "choice":
        if raw not in check:
            raise UnknownVariantError(f"{name} = {raw!r}: allowed values are {', '.join(check)}"
                                      + (suggest(raw, check) if isinstance(raw, str) else ""))
        return raw
    if dim == "fractions":
        if not isinstance(raw, list) or not raw:
            raise ParameterTypeError(f"{name}: expected a list of fractions of the rated speed, e.g. [0.4, 0.6, 0.9]")
        return tuple(_number(f"{name}[{i}]", v, "1", check) for i, v in enumerate(raw))
    return _number(name, raw, dim, check)


def _number(name, raw, dim, check):
    if isinstance(raw, (bool, list, dict)):
        raise ParameterTypeError(f"{name}: expected a number, got {raw!r}")
    value = to_si(raw, dim, name)
    if not math.isfinite(value):
        raise PhysicalRangeError(f"{name} = {value}: must be a finite number")
    ok, phrase = CHECKS[check]
    if not ok(value):
        raise PhysicalRangeError(f"{name} = {raw!r}: must be {phrase}")
    return value
