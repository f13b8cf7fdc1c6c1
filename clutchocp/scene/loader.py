"""Load, validate and override scene files.

``load_scene("bao2020")`` finds a built-in scene by name; ``load_scene("my/clutch.toml")`` reads a
file.  Validation turns every user mistake into one :class:`~clutchocp.errors.SceneError` line that
names the field and what is allowed.
"""

import math
import tomllib
import warnings
from pathlib import Path

import numpy as np

from ..errors import (
    MissingParameterError,
    ParameterTypeError,
    PhysicalRangeError,
    PlausibilityWarning,
    SceneError,
    SceneNotFoundError,
    UnknownKeyError,
    UnknownVariantError,
)
from ..physics.friction import CHEN_THETA_MIN
from ..physics.viscosity import walther_coefficients, walther_kinematic_viscosity
from .fields import check_value, parse_field, suggest  # noqa: F401 - check_value: engagement.run reads it here
from .schema import LINING_MATERIALS, PARTS, REQUIRED_PARTS, RETIRED
from .uncertainty import Uncertainty

# The table of a scene that declares its uncertain fields (see clutchocp.scene.uncertainty), not a part.
UNCERTAINTY = "uncertainty"

# Parts each static analysis reads.
ANALYSIS_PARTS = {
    "chen2021_pack": ("spline", "friction", "operating"),
    "cui2019_mixed": ("roughness", "contact", "friction", "oil", "operating"),
    "liao2021_hvc": ("groove", "hvc", "oil", "operating"),
}


def builtin_dir(folder):
    """A data folder (``models`` or ``controllers``): inside the installed package, or at the top of
    a source tree."""
    package = Path(__file__).resolve().parent.parent
    installed = package / "_data" / folder
    return installed if installed.is_dir() else package.parent / folder


def builtin_scene_dir():
    """Folder of the built-in scenes."""
    return builtin_dir("models")


def read_toml(name_or_path, folder, what):
    """Read a TOML file given by path, or by built-in name from ``builtin_dir(folder)``.

    Parameters
    ----------
    name_or_path : str or pathlib.Path
    folder : str
        ``"models"`` or ``"controllers"``.
    what : str
        What the file is, for messages (``"scene"``, ``"controller"``).

    Returns
    -------
    (pathlib.Path, dict)
    """
    path = Path(name_or_path)
    if not path.is_file():
        candidate = builtin_dir(folder) / f"{name_or_path}.toml"
        if not candidate.is_file():
            names = sorted(p.stem for p in builtin_dir(folder).glob("*.toml"))
            raise SceneNotFoundError(
                f"{what} '{name_or_path}': no such file and no built-in {what} of that name"
                f"{suggest(str(name_or_path), names)} (built-in: {', '.join(names)})"
            )
        path = candidate
    try:
        return path, tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{path.name}: not valid TOML ({exc})") from None
    except UnicodeDecodeError:
        raise SceneError(f"{path.name}: not a UTF-8 text file") from None


def _validate_part(part_name, table, notes=None):
    part = PARTS[part_name]
    if not isinstance(table, dict):
        raise ParameterTypeError(f"[{part_name}]: expected a table of parameters, got {table!r}")
    values = {}
    variant = ""
    if part.variants:
        variant = table.get("model", part.default_variant)
        if not isinstance(variant, str) or variant not in part.variants:
            raise UnknownVariantError(
                f"{part_name}.model = {variant!r}: unknown variant; allowed: {', '.join(part.variants)}"
                + (suggest(variant, part.variants) if isinstance(variant, str) else "")
            )
        values["model"] = variant
    allowed = part.allowed_fields(variant)
    for key in table:
        if key == "model" and part.variants:
            continue
        if f"{part_name}.{key}" in RETIRED:
            raise UnknownKeyError(f"{part_name}.{key}: no longer a key: {RETIRED[f'{part_name}.{key}']}")
        if key not in allowed:
            where = f"{part_name} (model = {variant})" if variant else part_name
            options = sorted(allowed) + (["model"] if part.variants else [])
            raise UnknownKeyError(
                f"{part_name}.{key}: unknown key in [{where}]{suggest(key, options)} "
                f"(allowed: {', '.join(options)})"
            )
    # the density first: a viscosity given in cSt is converted with it (mu = rho nu)
    for key, spec in sorted(allowed.items(), key=lambda item: item[0] != "density"):
        name = f"{part_name}.{key}"
        if key in table:
            values[key] = parse_field(name, table[key], spec, density=values.get("density"), notes=notes)
        elif spec.required:
            raise MissingParameterError(f"{name}: missing required parameter ({spec.doc})")
        elif spec.default is not None:
            values[key] = spec.default
    return values


def _require(values, name, why):
    part, key = name.split(".")
    if key not in values.get(part, {}):
        raise MissingParameterError(f"{name}: missing, required {why}")


def _cross_check(values, base_dir):
    """Checks that involve more than one field."""
    kind = values["scene"]["kind"]
    for part in REQUIRED_PARTS[kind]:
        if part not in values:
            raise MissingParameterError(f"[{part}]: missing part, required for a scene of kind '{kind}'")
    analysis = values["scene"].get("analysis")
    for part in ANALYSIS_PARTS.get(analysis, ()):
        if part not in values:
            raise MissingParameterError(f"[{part}]: missing part, required by analysis '{analysis}'")
    plates = values["plates"]
    if plates["r_inner"] >= plates["r_outer"]:
        raise PhysicalRangeError(
            f"plates.r_inner = {plates['r_inner']:g} m must be smaller than plates.r_outer = {plates['r_outer']:g} m"
        )
    rough = values.get("roughness")
    if rough is not None:
        if "sigma" not in rough:
            if "sigma_1" not in rough or "sigma_2" not in rough:
                raise MissingParameterError("roughness.sigma: missing (give sigma, or both sigma_1 and sigma_2)")
            rough["sigma"] = math.hypot(rough["sigma_1"], rough["sigma_2"])
        elif "sigma_1" in rough or "sigma_2" in rough:
            raise SceneError("roughness.sigma: give either sigma or sigma_1 and sigma_2, not both")
    contact = values.get("contact", {}).get("model")
    if contact and contact != "none":
        for key in ("asperity_density", "asperity_radius"):
            _require(values, f"roughness.{key}", f"by contact model '{contact}'")
        if values["roughness"]["sigma"] <= 0:
            raise PhysicalRangeError(f"roughness.sigma = 0: must be > 0 with contact model '{contact}'")
    _check_temperatures(values)
    friction = values.get("friction", {})
    if friction.get("model") == "table":
        p, mu = friction["pressure"], friction["mu"]
        if len(p) != len(mu) or len(p) < 2:
            raise SceneError("friction.mu: give one value per friction.pressure entry, at least two")
        if np.any(np.diff(p) <= 0):
            raise PhysicalRangeError("friction.pressure: values must increase strictly")
    pack = values.get("pack", {})
    if pack.get("model") == "masses" and len(pack["plate_masses"]) != plates["n_interfaces"]:
        raise SceneError(
            f"pack.plate_masses: give {plates['n_interfaces']} masses, one per film (plates.n_interfaces), "
            f"got {len(pack['plate_masses'])}"
        )
    drive = values.get("driveline", {})
    if drive.get("input") == "inertia":
        _require(values, "driveline.input_inertia", "when driveline.input = 'inertia'")
    if drive.get("output") == "inertia":
        _require(values, "driveline.output_inertia", "when driveline.output = 'inertia'")
    if drive.get("input") == "prescribed_speed" and drive.get("output") == "fixed":
        raise SceneError("driveline.output = 'fixed' needs driveline.input = 'inertia' (something must slow down)")
    act = values.get("actuation", {})
    if "max_pressure" in act and act["max_pressure"] < act["pressure"]:
        raise PhysicalRangeError(
            f"actuation.pressure = {act['pressure']:g} Pa exceeds actuation.max_pressure = {act['max_pressure']:g} Pa"
        )
    for part in ("actuation", "load"):
        if values.get(part, {}).get("model") == "table":
            path = (base_dir / values[part]["file"]).resolve()
            if not path.is_file():
                raise SceneNotFoundError(f"{part}.file: no file '{values[part]['file']}' next to the scene")
            values[part]["file"] = str(path)
    piston = values.get("piston")
    if piston is not None and piston["model"] == "spring_applied" and piston["spring_stiffness"] <= 0:
        raise PhysicalRangeError("piston.spring_stiffness: must be > 0 for a spring-applied piston")


def _check_temperatures(values):
    """The [thermal] part, the Walther oil and Chen's friction law: each temperature given once.

    A Walther oil gets its derived ``oil.viscosity`` [Pa s] at the oil temperature, for the parts
    that read a constant viscosity (piston seal, HVD and static analyses).
    """
    thermal, oil, friction = values.get("thermal"), values.get("oil", {}), values.get("friction", {})
    if thermal is not None:
        if values["scene"]["kind"] != "engagement":
            raise SceneError("[thermal]: plate temperatures are modelled for engagement scenes only")
        thermal.setdefault("initial_temperature_C", thermal["oil_temperature_C"])
        _check_lining(values)
    if friction.get("model") == "chen2021":
        _fixed_temperature("friction", friction, thermal is not None, "Chen's law reads the interface temperature")
        for key in ("oil_temperature_C", "initial_temperature_C") if thermal is not None else ():
            if not thermal[key] > CHEN_THETA_MIN:       # the plates never cool below the oil or their start
                raise PhysicalRangeError(f"thermal.{key} = {thermal[key]:g}: must be > {CHEN_THETA_MIN:.4g} degC "
                                         "with friction.model = 'chen2021' (Chen 2021 Eq. 5 fit domain)")
    if oil.get("model") != "walther":
        return
    _fixed_temperature("oil", oil, thermal is not None, "the oil temperature is thermal.oil_temperature_C")
    try:
        A, B = walther_coefficients(40.0, oil["kinematic_viscosity_40C"], 100.0, oil["kinematic_viscosity_100C"])
    except PhysicalRangeError as exc:
        raise PhysicalRangeError(f"oil.kinematic_viscosity_40C, oil.kinematic_viscosity_100C: {exc}") from None
    theta = thermal["oil_temperature_C"] if thermal is not None else oil["temperature_C"]
    oil["viscosity"] = oil["density"] * float(walther_kinematic_viscosity(theta, A, B))


def _check_lining(values):
    """The lining the [thermal] part conducts heat through: its properties (defaults from
    ``thermal.lining_material``), a thickness, and a friction-plate heat capacity that holds it."""
    thermal, plates = values["thermal"], values["plates"]
    for key, default in zip(("lining_conductivity", "lining_density", "lining_specific_heat"),
                            LINING_MATERIALS[thermal["lining_material"]]):
        thermal.setdefault(key, default)
    d = plates["lining_thickness"]
    if not d > 0:
        raise MissingParameterError("plates.lining_thickness: must be > 0 with a [thermal] part (the heat of the "
                                    "interface conducts through the friction lining); e.g. '0.5 mm' for paper")
    lining = (plates["n_interfaces"] * math.pi * (plates["r_outer"] ** 2 - plates["r_inner"] ** 2) * d
              * thermal["lining_density"] * thermal["lining_specific_heat"])
    if thermal["friction_plate_heat_capacity"] < lining:
        raise PhysicalRangeError(
            f"thermal.friction_plate_heat_capacity = {thermal['friction_plate_heat_capacity']:g} J/K is less than "
            f"the linings alone hold ({lining:.4g} J/K = n_interfaces x pi (r_outer^2 - r_inner^2) x "
            f"plates.lining_thickness x lining_density x lining_specific_heat): give the heat capacity of the "
            f"friction plates with their steel cores")


def _fixed_temperature(part, table, has_thermal, with_thermal):
    """``<part>.temperature_C``, a law's fixed temperature: required without [thermal], refused with it."""
    if has_thermal and "temperature_C" in table:
        raise SceneError(f"{part}.temperature_C: not used with a [thermal] part ({with_thermal}); remove it")
    if not has_thermal and "temperature_C" not in table:
        raise MissingParameterError(f"{part}.temperature_C: missing, required by {part}.model = '{table['model']}' "
                                    "without a [thermal] part")


class Scene:
    """A validated scene: the parts it declares and their parameters in SI.

    Use :meth:`value` for a parameter (``scene.value("plates.r_inner")``), :meth:`has` to ask
    whether a part is present, :meth:`variant` for a part's chosen model.
    """

    def __init__(self, raw, path=None):
        self.raw = raw
        self.path = Path(path) if path else None
        self._uncertainty = None
        notes = []
        try:
            self._values = validate(raw, self.path.parent if self.path else Path.cwd(), notes)
        except SceneError as exc:
            if self.path is None:
                raise
            raise type(exc)(f"{self.path.name}: {exc}") from None
        self.warnings = tuple(notes)

    @property
    def name(self):
        return self._values["scene"]["name"]

    @property
    def title(self):
        return self._values["scene"].get("title", "")

    @property
    def source(self):
        return self._values["scene"]["source"]

    @property
    def kind(self):
        return self._values["scene"]["kind"]

    @property
    def parts(self):
        """Names of the parts this scene declares."""
        return tuple(self._values)

    def has(self, part):
        """True if the scene declares ``part`` (and, for a variant part, not ``model = "none"``)."""
        return part in self._values and self._values[part].get("model") != "none"

    def variant(self, part):
        """The chosen ``model`` of a part with variants."""
        return self._values[part].get("model", "")

    def value(self, name):
        """SI value of ``"part.key"``; raises MissingParameterError if the scene lacks it."""
        part, _, key = name.partition(".")
        try:
            return self._values[part][key]
        except KeyError:
            raise MissingParameterError(f"{name}: not given in scene '{self.name}'") from None

    def get(self, name, default=None):
        """SI value of ``"part.key"``, or ``default`` if absent."""
        part, _, key = name.partition(".")
        return self._values.get(part, {}).get(key, default)

    def with_overrides(self, overrides):
        """A new scene with ``{"part.key": value}`` replaced (values as in a scene file; None removes the key).

        ``roughness.sigma`` (the combined RMS) on a scene that gives the roughness per surface scales
        ``sigma_1`` and ``sigma_2`` to the new combined value, keeping their ratio; ``sigma_1`` and
        ``sigma_2`` together on a scene that gives ``sigma`` replace it.
        """
        overrides = _roughness_overrides(self, overrides)
        raw = {part: dict(table) if isinstance(table, dict) else table for part, table in self.raw.items()}
        for name, value in overrides.items():
            part, dot, key = name.partition(".")
            if not dot or not key:
                raise UnknownKeyError(f"{name}: an override is written part.key=value (e.g. oil.viscosity=0.04)")
            if part not in PARTS:
                raise UnknownKeyError(f"{name}: unknown part '{part}'{suggest(part, PARTS)}")
            if value is None:
                raw.get(part, {}).pop(key, None)
            else:
                raw.setdefault(part, {})[key] = value
        return Scene(raw, self.path)

    @property
    def uncertainty(self):
        """The spread of the clutches this scene stands for (:class:`clutchocp.scene.uncertainty.Uncertainty`,
        empty if the scene has no ``[uncertainty]`` table). Read when first asked for, so that a
        deterministic run of a scene whose overrides change a part (e.g. ``load.model``) does not
        depend on it; studies that use it check it first (``Uncertainty.from_scene``)."""
        if self._uncertainty is None:
            try:
                self._uncertainty = Uncertainty.from_scene(self, check=False)
            except SceneError as exc:
                raise type(exc)(f"{self.path.name}: {exc}" if self.path else str(exc)) from None
        return self._uncertainty

    def without_uncertainty(self):
        """The same scene without its ``[uncertainty]`` table (one deterministic clutch)."""
        if UNCERTAINTY not in self.raw:
            return self
        return Scene({part: table for part, table in self.raw.items() if part != UNCERTAINTY}, self.path)

    def __repr__(self):
        return f"Scene({self.name!r}, kind={self.kind!r}, parts={list(self.parts)})"


def _roughness_overrides(scene, overrides):
    """Overrides with the roughness given the way the scene gives it: a combined ``roughness.sigma`` turned
    into ``sigma_1``/``sigma_2`` of the same ratio where the scene gives the surfaces, and the scene's
    ``sigma`` removed where the overrides give both surfaces."""
    per_surface = ("roughness.sigma_1", "roughness.sigma_2")
    if (all(overrides.get(k) is not None for k in per_surface) and "roughness.sigma" not in overrides
            and scene.get("roughness.sigma_1") is None):
        return {**overrides, "roughness.sigma": None}
    if (overrides.get("roughness.sigma") is None or any(k in overrides for k in per_surface)
            or scene.get("roughness.sigma_1") is None or scene.get("roughness.sigma_2") is None):
        return overrides
    sigma = parse_field("roughness.sigma", overrides["roughness.sigma"], PARTS["roughness"].fields["sigma"])
    scale = sigma / scene.value("roughness.sigma") if scene.value("roughness.sigma") > 0 else None
    if scale is None:
        raise SceneError("roughness.sigma: this scene gives sigma_1 = sigma_2 = 0; set roughness.sigma_1 and "
                         "roughness.sigma_2 instead")
    out = {k: v for k, v in overrides.items() if k != "roughness.sigma"}
    out.update({k: scene.value(k) * scale for k in per_surface})
    return out


def validate(raw, base_dir, notes=None):
    """Validate a parsed scene dictionary; return {part: {key: SI value}}.

    Values outside their key's typical span (:class:`~clutchocp.scene.schema.Span`) add a line to the
    list ``notes``; values outside its limits are refused.
    """
    if not isinstance(raw, dict):
        raise ParameterTypeError("scene: expected TOML tables")
    raw = {part: table for part, table in raw.items() if part != UNCERTAINTY}
    for part in raw:
        if part not in PARTS:
            raise UnknownKeyError(f"[{part}]: unknown part{suggest(part, PARTS)} "
                                  f"(allowed: {', '.join(PARTS)}, {UNCERTAINTY})")
    if "scene" not in raw:
        raise MissingParameterError("[scene]: missing part (name, source and kind are required)")
    values = {part: _validate_part(part, table, notes) for part, table in raw.items()}
    _cross_check(values, base_dir)
    return values


def parse_override(text):
    """Parse ``"part.key=value"`` from the command line; the value is read as TOML if it can be."""
    name, eq, value = text.partition("=")
    if not eq or not name.strip():
        raise UnknownKeyError(f"--set {text}: write part.key=value (e.g. oil.viscosity='0.04 Pa s')")
    try:
        parsed = tomllib.loads(f"v = {value.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        parsed = value.strip()
    return name.strip(), parsed


def load_scene(name_or_path, overrides=None):
    """Load a scene by built-in name (see :func:`list_scenes`) or by file path.

    Parameters
    ----------
    name_or_path : str or pathlib.Path
        A built-in scene name such as ``"bao2020"`` or a path to a TOML file.
    overrides : dict, optional
        ``{"part.key": value}`` replacing values of the file.

    Returns
    -------
    Scene
        Its values outside what wet clutches have are in ``Scene.warnings`` and issued as
        :class:`~clutchocp.errors.PlausibilityWarning`.
    """
    path, raw = read_toml(name_or_path, "models", "scene")
    scene = Scene(raw, path)
    scene = scene.with_overrides(overrides) if overrides else scene
    for note in scene.warnings:
        warnings.warn(f"{scene.name}: {note}", PlausibilityWarning, stacklevel=2)
    return scene


def list_scenes():
    """All built-in scenes, sorted by name."""
    return [load_scene(p) for p in sorted(builtin_scene_dir().glob("*.toml"))]


def default_scene():
    """The built-in scene marked ``default = true`` (the engagement-optimisation default)."""
    defaults = [s for s in list_scenes() if s.value("scene.default")]
    if len(defaults) != 1:
        raise SceneError(f"built-in scenes: expected exactly one default scene, found {len(defaults)}")
    return defaults[0]
