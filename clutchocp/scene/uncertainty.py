"""Uncertainty of a scene: which fields spread, and how, for robust optimisation, sweeps and Monte Carlo.

A scene declares it in an ``[uncertainty]`` table whose keys are scene fields::

    [uncertainty]
    "friction.mu" = "uniform 10 %"          # nominal +- 10 %, uniform
    "oil.viscosity" = "normal 5 %"          # sigma = 5 % of nominal, truncated at +- 3 sigma
    "load.torque" = "uniform 20 N m"        # nominal +- 20 N m (a half-width with units; plain number: SI)
    "film.flow_factor" = ["patir_cheng", "none"]   # a list of values, drawn with equal weight

(``friction.mu = "..."`` without quotes, or ``[uncertainty.friction]`` tables, mean the same.)
On the command line the same is written ``--uncertain "friction.mu=uniform 10 %"`` (repeatable).
The nominal of a spread is the scene's own value. A list may hold quantities with units or the
choices of a choice field; it is how model-form choices (e.g. a load-sharing law) enter a study.

Every draw is a plain ``{"part.key": value}`` dict (SI numbers or choice strings), ready for
:meth:`clutchocp.scene.Scene.with_overrides`: the unit of work a worker process can rebuild from.
"""

import itertools
import tomllib
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterTypeError, PhysicalRangeError, SceneError, UnknownKeyError
from ..units import to_si
from .fields import parse_field
from .schema import PARTS

KINDS = ("uniform", "normal")
NORMAL_TRUNCATION = 3.0   # normal draws are truncated at +- 3 sigma (so every draw is a valid scene)
NORMAL_CORNER = 2.0       # corners of a normal field: +- 2 sigma
SPEC_HELP = ("write 'uniform 10 %', 'normal 5 %', 'uniform 20 N m' (a half-width or sigma with units) "
             "or a list of values like [\"0.1\", \"0.12\"]")


@dataclass(frozen=True)
class Spread:
    """The spread of one scene field.

    Attributes
    ----------
    key : str
        The scene field, ``"part.key"``.
    kind : str
        ``"uniform"`` (nominal +- ``width``), ``"normal"`` (sigma = ``width``, truncated at +- 3 sigma)
        or ``"values"`` (one of ``values``, equal weights).
    nominal : float or str
        The scene's own value (SI).
    width : float
        Half-width (uniform) or standard deviation (normal), SI; 0 for ``"values"``.
    values : tuple
        The listed values (SI floats or choice strings) of a ``"values"`` spread.
    text : str
        The spec as written, for reports.
    """

    key: str
    kind: str
    nominal: object
    width: float = 0.0
    values: tuple = ()
    text: str = ""

    @property
    def bounds(self):
        """(low, high) of the values a draw can take (numeric spreads), SI."""
        if self.kind == "values":
            return min(self.values), max(self.values)
        reach = self.width * (NORMAL_TRUNCATION if self.kind == "normal" else 1.0)
        return self.nominal - reach, self.nominal + reach

    def corner_values(self):
        """The values this field takes at the corners of the uncertainty box."""
        if self.kind == "values":
            return list(self.values)
        reach = self.width * (NORMAL_CORNER if self.kind == "normal" else 1.0)
        return [self.nominal - reach, self.nominal + reach]

    def draw(self, rng, n):
        """``n`` random values of this field (a list)."""
        if self.kind == "values":
            return [self.values[i] for i in rng.integers(0, len(self.values), n)]
        if self.kind == "uniform":
            return list(self.nominal + self.width * rng.uniform(-1.0, 1.0, n))
        z = rng.standard_normal(n)
        while np.any(bad := np.abs(z) > NORMAL_TRUNCATION):      # truncated normal by rejection
            z[bad] = rng.standard_normal(int(bad.sum()))
        return list(self.nominal + self.width * z)


class Uncertainty:
    """The uncertain fields of a scene and their spreads (empty: a deterministic scene).

    Build it with :meth:`from_scene`; draw with :meth:`samples`, :meth:`corners`, :meth:`centre`.
    """

    def __init__(self, spreads=()):
        self.spreads = tuple(spreads)

    @property
    def names(self):
        """The uncertain scene fields, in declaration order."""
        return tuple(s.key for s in self.spreads)

    def __len__(self):
        return len(self.spreads)

    def __bool__(self):
        return bool(self.spreads)

    def __repr__(self):
        return f"Uncertainty({', '.join(f'{s.key}: {s.text}' for s in self.spreads) or 'none'})"

    @classmethod
    def from_scene(cls, scene, extra=(), check=True):
        """The scene's ``[uncertainty]`` table, with command-line specs added or replacing its entries.

        Parameters
        ----------
        scene : clutchocp.scene.Scene
        extra : sequence of str
            ``"part.key=spec"`` texts as given to ``--uncertain``.
        check : bool
            Also build the scene at each field's extremes (:meth:`check_extremes`).

        Returns
        -------
        Uncertainty

        Raises
        ------
        SceneError
            An unknown or absent field, a spec that does not parse, or a spread that leaves the
            field's allowed range (the message names the field and what is allowed).
        """
        specs = dict(flatten_section(scene.raw.get("uncertainty", {})))
        for text in extra:
            key, spec = parse_uncertain(text)
            specs[key] = spec
        spreads = [parse_spread(key, spec, scene) for key, spec in specs.items()]
        out = cls(spreads)
        if check:
            out.check_extremes(scene)
        return out

    def check_extremes(self, scene):
        """Build the scene at each field's lowest and highest value; a SceneError names the field."""
        base = scene.without_uncertainty()
        for spread in self.spreads:
            for value in spread.corner_values() if spread.kind == "values" else spread.bounds:
                try:
                    base.with_overrides({spread.key: value})
                except SceneError as exc:
                    raise type(exc)(f"uncertainty.{spread.key} = {spread.text!r} reaches {_show(value)}, "
                                    f"where the scene is not valid: {exc}") from None

    def centre(self):
        """The nominal scene as an override dict (every uncertain field at its nominal value)."""
        return {s.key: s.nominal for s in self.spreads}

    def corners(self):
        """Every corner of the uncertainty box (2^k for k numeric fields; a list field: each value).

        Returns
        -------
        list of dict
            ``{"part.key": value}`` per corner, in lexicographic order of (low, high) per field.
        """
        if not self.spreads:
            return [{}]
        grid = itertools.product(*(s.corner_values() for s in self.spreads))
        return [dict(zip(self.names, combo)) for combo in grid]

    def samples(self, n, seed=0):
        """``n`` random draws, reproducible with ``seed`` (fields independent).

        Returns
        -------
        list of dict
            ``{"part.key": value}`` per draw.
        """
        if not (isinstance(n, (int, np.integer)) and not isinstance(n, bool) and n >= 1):
            raise SceneError(f"samples = {n!r}: must be a whole number >= 1")
        rng = np.random.default_rng(seed)
        columns = [spread.draw(rng, n) for spread in self.spreads]
        return [{key: _plain(col[i]) for key, col in zip(self.names, columns)} for i in range(n)]

    def describe(self):
        """One line per uncertain field, for the command line."""
        return [f"{s.key}: {s.text} (nominal {_show(s.nominal)})" for s in self.spreads]

    def to_dict(self):
        """A JSON-ready description (for summary.json)."""
        return {s.key: {"spread": s.text, "kind": s.kind, "nominal": _plain(s.nominal),
                        **({"width_SI": s.width} if s.kind != "values" else {"values": list(s.values)})}
                for s in self.spreads}


def flatten_section(section):
    """``{"friction.mu": spec}`` or ``{"friction": {"mu": spec}}`` -> [("friction.mu", spec), ...]."""
    if not isinstance(section, dict):
        raise ParameterTypeError("[uncertainty]: expected a table of 'part.key = spec' entries")
    out = []
    for name, spec in section.items():
        if isinstance(spec, dict):
            out.extend((f"{name}.{key}", inner) for key, inner in spec.items())
        else:
            out.append((name, spec))
    return out


def parse_uncertain(text):
    """Parse ``"part.key=spec"`` from ``--uncertain``; a TOML list after ``=`` is a list of values."""
    name, eq, value = str(text).partition("=")
    if not eq or not name.strip() or not value.strip():
        raise UnknownKeyError(f"--uncertain {text}: write part.key=spec, e.g. --uncertain 'friction.mu=uniform 10 %'")
    value = value.strip()
    if value.startswith("["):
        try:
            return name.strip(), tomllib.loads(f"v = {value}")["v"]
        except tomllib.TOMLDecodeError:
            raise ParameterTypeError(f"--uncertain {text}: the list does not parse; {SPEC_HELP}") from None
    return name.strip(), value.strip("'\"")


def parse_spread(key, spec, scene):
    """One :class:`Spread` from a field name and its spec (as written in the scene or on the CLI)."""
    where = f"uncertainty.{key}"
    part, dot, field_name = key.partition(".")
    if not dot or part not in PARTS:
        raise UnknownKeyError(f"{where}: not a scene field; write part.key, e.g. \"friction.mu\"")
    variant = scene.variant(part) if part in scene.parts else PARTS[part].default_variant
    fields = PARTS[part].allowed_fields(variant)
    if field_name not in fields:
        raise UnknownKeyError(f"{where}: [{part}] has no field '{field_name}' here "
                              f"(allowed: {', '.join(sorted(fields))})")
    field = fields[field_name]
    nominal = scene.get(key)
    if nominal is None:
        raise UnknownKeyError(f"{where}: the scene does not set {key}; give it a nominal value first")
    if isinstance(spec, list):
        return _values_spread(key, spec, field, nominal)
    if field.kind != "quantity":
        raise ParameterTypeError(f"{where}: {key} is a {field.kind} field; give a list of its values "
                                 f"(e.g. {list(field.choices) if field.choices else '[...]'})")
    if not isinstance(spec, str):
        raise ParameterTypeError(f"{where} = {spec!r}: {SPEC_HELP}")
    kind, _, amount = spec.strip().partition(" ")
    if kind not in KINDS or not amount.strip():
        raise ParameterTypeError(f"{where} = {spec!r}: {SPEC_HELP}")
    amount = amount.strip()
    if amount.endswith("%"):
        try:
            width = abs(nominal) * float(amount[:-1]) / 100.0
        except ValueError:
            raise ParameterTypeError(f"{where} = {spec!r}: '{amount}' is not a percentage; {SPEC_HELP}") from None
    else:
        width = to_si(amount, field.dim, where)
    if not (np.isfinite(width) and width > 0):
        raise PhysicalRangeError(f"{where} = {spec!r}: the spread must be a finite amount > 0")
    return Spread(key, kind, nominal, width=float(width), text=spec.strip())


def _values_spread(key, spec, field, nominal):
    where = f"uncertainty.{key}"
    if len(spec) < 2:
        raise ParameterTypeError(f"{where}: give at least two values in the list")
    if field.kind not in ("quantity", "choice", "int"):
        raise ParameterTypeError(f"{where}: a {field.kind} field cannot be uncertain")
    values = tuple(_plain(parse_field(f"{where}[{i}]", item, field)) for i, item in enumerate(spec))
    return Spread(key, "values", _plain(nominal), values=values, text=str(list(spec)))


def _plain(value):
    """numpy scalars to Python numbers (JSON and TOML friendly)."""
    return value.item() if isinstance(value, np.generic) else value


def _show(value):
    return f"{value:.6g}" if isinstance(value, float) else repr(value)
