"""The slip-feedback specification (controllers/slip_lqr.toml): TCU sampling, limits, LQI weights.

Validated like the speed-controller specs of :mod:`clutchocp.hvd.spec` (:mod:`clutchocp.control.spec`); every
mistake raises a :class:`~clutchocp.errors.SceneError` subclass whose one-line message names the
field::

    [controller]
    type = "slip_lqi"
    sample_time = "10 ms"            # TCU sample time: the correction is held between samples
    pressure_min = "0 MPa"           # command limits (default: 0 .. actuation.max_pressure)
    rate_limit_time = "10 ms"        # the command may cross its whole range in this time, no faster
    measure_pressure = true          # the TCU reads the clutch pressure (else speeds only)
    progress = "slip"                # reference read at the slip reached ("slip") or at the clock ("time")
    max_delay = "50 ms"              # with "slip": the reference lags the clock by at most this

    [lqi]                            # Bryson's rule: each weight is 1 / tolerance^2
    slip_tolerance = 0.003           # slip error, fraction of the initial slip
    slip_rate_tolerance = 0.1        # slip-rate error, fraction of initial slip / nominal lock time
    integral_tolerance = 0.01        # slip-error integral, fraction of initial slip x nominal lock time
    correction_tolerance = 0.3       # feedback correction, fraction of the pressure range
    terminal_weight = 10.0           # the state weights at lock-up are this many times larger

    [anti_windup]
    method = "clamping"              # or "none"

    [estimator]                      # the command rescaled to the clutch met (torque gain and load from the speeds)
    enabled = true
    activation = 0.5                 # adapt while the nominal clutch torque is above this fraction of its peak
    gain_limit = 1.5                 # largest ratio of nominal to estimated torque gain (and its inverse)

    [feedforward]
    curve = "nominal"                # the curve the loop tracks: "nominal" optimum or "robust" feedforward
    t_max_fraction = 1.0             # the nominal optimum is solved with t_max x this (a time margin)

    [schedule]                       # the TCU measures this field (the oil viscosity, from its temperature)
    field = "oil.viscosity"          # feedforward and gains designed at `points` values over its spread
    points = 5
"""

from dataclasses import dataclass, field
from pathlib import Path

from ..control.spec import check_tables, parse_table, read_spec
from ..errors import MissingParameterError, PhysicalRangeError

TYPES = ("slip_lqi",)
ANTI_WINDUP = ("clamping", "none")
PROGRESS = ("slip", "time")
CURVES = ("nominal", "robust")

_CONTROLLER = {
    "name": ("str", None, ""),
    "type": ("choice", TYPES, None),
    "description": ("str", None, ""),
    "sample_time": ("s", "positive", None),
    "pressure_min": ("Pa", "nonnegative", None),
    "pressure_max": ("Pa", "positive", None),
    "rate_limit_time": ("s", "positive", 0.01),
    "measure_pressure": ("bool", None, True),
    "progress": ("choice", PROGRESS, "slip"),
    "max_delay": ("s", "nonnegative", 0.05),
}
_LQI = {
    "slip_tolerance": ("1", "positive", 0.003),
    "slip_rate_tolerance": ("1", "positive", 0.1),
    "integral_tolerance": ("1", "positive", 0.01),
    "correction_tolerance": ("1", "positive", 0.3),
    "terminal_weight": ("1", "nonnegative", 10.0),
}
_ANTI_WINDUP = {"method": ("choice", ANTI_WINDUP, "clamping")}
_ESTIMATOR = {"enabled": ("bool", None, False), "activation": ("1", "positive", 0.3),
              "gain_limit": ("1", "positive", 1.5)}
_FEEDFORWARD = {"curve": ("choice", CURVES, "nominal"), "t_max_fraction": ("1", "positive", 1.0)}
_SCHEDULE = {"field": ("str", None, ""), "points": ("1", "positive", 1.0)}
_TABLES = {"controller": _CONTROLLER, "lqi": _LQI, "anti_windup": _ANTI_WINDUP, "estimator": _ESTIMATOR,
           "feedforward": _FEEDFORWARD, "schedule": _SCHEDULE}
_REQUIRED = ("type", "sample_time")


@dataclass
class SlipControlSpec:
    """A validated slip-feedback spec (SI units)."""

    sample_time: float
    name: str = ""
    description: str = ""
    pressure_min: float | None = None
    pressure_max: float | None = None
    rate_limit_time: float = 0.01
    measure_pressure: bool = True
    progress: str = "slip"
    max_delay: float = 0.05
    lqi: dict = field(default_factory=lambda: {k: v[2] for k, v in _LQI.items()})
    anti_windup: str = "clamping"
    estimator: dict = field(default_factory=lambda: {k: v[2] for k, v in _ESTIMATOR.items()})
    feedforward_curve: str = "nominal"
    t_max_fraction: float = 1.0
    schedule_field: str = ""
    schedule_points: int = 1
    path: Path | None = None

    @property
    def label(self):
        return self.name or "slip_lqi"


def load_slip_spec(name_or_path="slip_lqr"):
    """Load a slip-feedback spec by built-in name (``"slip_lqr"``) or TOML file path.

    Returns
    -------
    SlipControlSpec

    Raises
    ------
    SceneError subclasses with a one-line message naming the file and the field.
    """
    return read_spec(name_or_path, parse_slip_spec)


def parse_slip_spec(raw):
    """Validate a parsed slip-feedback spec (a dict of TOML tables); return a :class:`SlipControlSpec`."""
    check_tables(raw, _TABLES, "slip feedback spec")
    if "controller" not in raw:
        raise MissingParameterError("[controller]: missing table (type and sample_time are required)")
    for key in _REQUIRED:
        if isinstance(raw["controller"], dict) and key not in raw["controller"]:
            raise MissingParameterError(f"controller.{key}: missing required parameter")
    values = {name: parse_table(name, raw.get(name, {}), schema) for name, schema in _TABLES.items()}
    c = values["controller"]
    if c["pressure_min"] is not None and c["pressure_max"] is not None and c["pressure_min"] >= c["pressure_max"]:
        raise PhysicalRangeError(f"controller.pressure_min = {c['pressure_min']:g} Pa must be below "
                                 f"controller.pressure_max = {c['pressure_max']:g} Pa")
    fraction = values["feedforward"]["t_max_fraction"]
    if fraction > 1.0:
        raise PhysicalRangeError(f"feedforward.t_max_fraction = {fraction:g}: must be in (0, 1] (the closed loop's "
                                 "feedforward locks at this fraction of t_max or earlier)")
    weights = values["lqi"]
    schedule = values["schedule"]
    points = schedule["points"]
    if points != int(points) or points > 25:
        raise PhysicalRangeError(f"schedule.points = {points:g}: must be a whole number from 1 to 25 (one design "
                                 "per point)")
    if schedule["field"] and values["feedforward"]["curve"] == "robust":
        raise PhysicalRangeError(f"schedule.field = {schedule['field']!r} needs feedforward.curve = \"nominal\" (the "
                                 "robust feedforward is one curve for every clutch); remove [schedule] or use the "
                                 "nominal curve")
    estimator = values["estimator"]
    if not 0.0 < estimator["activation"] < 1.0:
        raise PhysicalRangeError(f"estimator.activation = {estimator['activation']:g}: must be in (0, 1) (a fraction "
                                 "of the nominal clutch torque's peak)")
    if estimator["gain_limit"] <= 1.0:
        raise PhysicalRangeError(f"estimator.gain_limit = {estimator['gain_limit']:g}: must be above 1 (the largest "
                                 "ratio of nominal to estimated torque gain)")
    if estimator["enabled"] and not c["measure_pressure"]:
        raise PhysicalRangeError("estimator.enabled = true needs controller.measure_pressure = true (the torque gain "
                                 "is the estimated clutch torque over the measured pressure)")
    return SlipControlSpec(sample_time=c["sample_time"], name=c["name"], description=c["description"],
                           pressure_min=c["pressure_min"], pressure_max=c["pressure_max"],
                           rate_limit_time=c["rate_limit_time"], measure_pressure=c["measure_pressure"],
                           progress=c["progress"], max_delay=c["max_delay"],
                           lqi=weights, anti_windup=values["anti_windup"]["method"], estimator=estimator,
                           feedforward_curve=values["feedforward"]["curve"], t_max_fraction=fraction,
                           schedule_field=schedule["field"], schedule_points=int(points))
