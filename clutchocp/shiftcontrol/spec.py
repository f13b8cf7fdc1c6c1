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
    correction_rate_tolerance = 0.05 # kalman: change of the correction per sample, fraction of the pressure range
    terminal_weight = 10.0           # the state weights at lock-up are this many times larger
    terminal_slip_tolerance = 0.002  # kalman, optional with the next: the weights at lock-up on their own,
    terminal_slip_rate_tolerance = 0.05   # slip and slip rate at the nominal lock-up (instead of terminal_weight)

    [anti_windup]
    method = "clamping"              # or "none"

    [estimator]                      # the command rescaled to the clutch met (torque gain and load from the speeds)
    enabled = true
    method = "difference"            # or "kalman": a Kalman filter on the linearised engagement (below)
    activation = 0.5                 # difference: adapt while the nominal clutch torque exceeds this share of its peak
    gain_limit = 1.5                 # difference: largest ratio of nominal to estimated torque gain (and its inverse)
    torque_noise = "5 N m"           # kalman: unmodelled torque on each rotor (standard deviation over a sample)
    pressure_noise = "5 kPa"         # kalman: unmodelled valve pressure per sample (standard deviation)
    parameter_drift = 0.002          # kalman: relative drift of an estimated parameter per sample
    [estimator.parameters]           # kalman: scene fields estimated, with the half-width of their prior spread
    "friction.mu" = "15 %"

    [sensors.input_speed]            # also [sensors.output_speed]; without them: the exact speeds
    method = "edge_timing"           # "ideal", "edge_timing" or "counting"
    teeth = 60
    timer_resolution = "1 us"
    pitch_error = "0.5 %"            # half-width of each tooth's pitch error (uniform)
    dropout = 0.0                    # probability that an edge is missed
    noise = "0 rad/s"                # white noise on a reading (standard deviation)
    learned_revolutions = 0          # the TCU learned its tooth pitches over this many steady revolutions
    [sensors.pressure]               # with measure_pressure: without it, the exact valve pressure
    noise = "5 kPa"                  # standard deviation
    offset = "10 kPa"                # half-width of the unit's offset (uniform, per clutch)
    lag = "2 ms"                     # sensor time constant
    [sensors.sump_temperature]       # the schedule's viscosity read through the sump temperature
    error_C = 3.0                    # half-width of the temperature error [deg C] (uniform, per clutch)
    oil_viscosity_40C = "80.12 cSt"  # the oil's datasheet (default: the scene's Walther oil, else these)
    oil_viscosity_100C = "9.5 cSt"
    [sensors.engine_torque]
    source = "nominal"               # "nominal": the nominal scene's torque; "plant": the plant's, with
    error = "0 %"                    # this half-width of relative error (uniform, per clutch)
    delay = "10 ms"                  # and this age (CAN)

    [valve]
    dead_time = "0 ms"               # the plant's: the valve follows the command this much later
    assumed_dead_time = "0 ms"       # the TCU's (default: dead_time); its feedforward is sent this much early

    [acceptance]                     # the targets `clutchocp robust` checks the closed loop against
    lock_by_t_max = 1.01             # every draw locks by this x t_max
    jump_p95_pct = 3.0               # |torque jump at lock-up| [% of the locked torque]: 95th percentile
    jump_worst_pct = 6.0             # and largest
    jerk_ratio = 1.15                # nominal clutch's jerk integral over the nominal optimum's

    [lock]                           # lock-up is detected from the measured slip
    slip = "auto"                    # |slip| below this [rad/s] ("auto": 4 x the sensors' standard deviation)
    samples = 2                      # for this many samples in a row; the command is held from the first

    [feedforward]
    curve = "nominal"                # the curve the loop tracks: "nominal" optimum or "robust" feedforward
    t_max_fraction = 1.0             # the nominal optimum is solved with t_max x this (a time margin)
    pressure_reserve = "0 MPa"       # and with the pressure limit lowered by this (headroom for the loop)
    lock_margin = 0.005              # and landing this fraction above the locked torque (its jump: -this)

    [schedule]                       # the TCU measures this field (the oil viscosity, from its temperature)
    field = "oil.viscosity"          # feedforward and gains designed at `points` values over its spread
    points = 5
"""

from dataclasses import dataclass, field
from pathlib import Path

from ..control.spec import check_tables, parse_table, read_spec
from ..optimal.problem import LOCK_MARGIN
from ..errors import MissingParameterError, ParameterTypeError, PhysicalRangeError

TYPES = ("slip_lqi",)
ESTIMATORS = ("difference", "kalman")
SPEED_METHODS = ("ideal", "edge_timing", "counting")
TORQUE_SOURCES = ("nominal", "plant")
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
    "correction_rate_tolerance": ("1", "positive", None),
    "terminal_weight": ("1", "nonnegative", 10.0),
    "terminal_slip_tolerance": ("1", "positive", None),
    "terminal_slip_rate_tolerance": ("1", "positive", None),
}
_ANTI_WINDUP = {"method": ("choice", ANTI_WINDUP, "clamping")}
_ESTIMATOR = {"enabled": ("bool", None, False), "method": ("choice", ESTIMATORS, "difference"),
              "activation": ("1", "positive", 0.3), "gain_limit": ("1", "positive", 1.5),
              "torque_noise": ("N m", "nonnegative", 5.0), "pressure_noise": ("Pa", "nonnegative", 5e3),
              "parameter_drift": ("1", "nonnegative", 0.002)}
_SPEED = {"method": ("choice", SPEED_METHODS, "ideal"), "teeth": ("1", "positive", 60.0),
          "timer_resolution": ("s", "positive", 1e-6), "pitch_error": ("1", "nonnegative", 0.0),
          "dropout": ("1", "nonnegative", 0.0), "noise": ("rad/s", "nonnegative", 0.0),
          "learned_revolutions": ("1", "nonnegative", 0.0)}
_PRESSURE = {"noise": ("Pa", "nonnegative", 0.0), "offset": ("Pa", "nonnegative", 0.0),
             "lag": ("s", "nonnegative", 0.0)}
_SUMP = {"error_C": ("1", "nonnegative", 0.0), "oil_viscosity_40C": ("m^2/s", "positive", None),
         "oil_viscosity_100C": ("m^2/s", "positive", None)}
_TORQUE = {"source": ("choice", TORQUE_SOURCES, "nominal"), "error": ("1", "nonnegative", 0.0),
           "delay": ("s", "nonnegative", 0.0)}
_SENSORS = {"input_speed": _SPEED, "output_speed": _SPEED, "pressure": _PRESSURE, "sump_temperature": _SUMP,
            "engine_torque": _TORQUE}
_VALVE = {"dead_time": ("s", "nonnegative", 0.0), "assumed_dead_time": ("s", "nonnegative", None)}
_LOCK = {"slip": ("rad/s", "nonnegative", None), "samples": ("1", "positive", 2.0)}
_ACCEPTANCE = {"lock_by_t_max": ("1", "positive", 1.01), "jump_p95_pct": ("1", "positive", 3.0),
               "jump_worst_pct": ("1", "positive", 6.0), "jerk_ratio": ("1", "positive", 1.15)}
_FEEDFORWARD = {"curve": ("choice", CURVES, "nominal"), "t_max_fraction": ("1", "positive", 1.0),
                "pressure_reserve": ("Pa", "nonnegative", 0.0), "lock_margin": ("1", "nonnegative", LOCK_MARGIN)}
_SCHEDULE = {"field": ("str", None, ""), "points": ("1", "positive", 1.0)}
_TABLES = {"controller": _CONTROLLER, "lqi": _LQI, "anti_windup": _ANTI_WINDUP, "estimator": _ESTIMATOR,
           "feedforward": _FEEDFORWARD, "schedule": _SCHEDULE, "sensors": _SENSORS, "valve": _VALVE, "lock": _LOCK,
           "acceptance": _ACCEPTANCE}
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
    pressure_reserve: float = 0.0
    lock_margin: float = LOCK_MARGIN
    schedule_field: str = ""
    schedule_points: int = 1
    sensors: dict = field(default_factory=dict)           # [sensors.*] tables given (SI), by sub-table
    valve: dict = field(default_factory=lambda: {"dead_time": 0.0, "assumed_dead_time": 0.0})
    lock: dict = field(default_factory=lambda: {"slip": None, "samples": 2})
    estimated_parameters: dict = field(default_factory=dict)   # kalman: scene field -> prior half-width (fraction)
    acceptance: dict = field(default_factory=lambda: {k: v[2] for k, v in _ACCEPTANCE.items()})
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
    raw = dict(raw)
    estimator_raw = dict(raw.get("estimator", {})) if isinstance(raw.get("estimator", {}), dict) else raw["estimator"]
    priors = estimator_raw.pop("parameters", {}) if isinstance(estimator_raw, dict) else {}
    raw["estimator"] = estimator_raw
    sensors = _sensor_tables(raw.pop("sensors", {}))
    values = {name: parse_table(name, raw.get(name, {}), schema) for name, schema in _TABLES.items()
              if name != "sensors"}
    c = values["controller"]
    if c["pressure_min"] is not None and c["pressure_max"] is not None and c["pressure_min"] >= c["pressure_max"]:
        raise PhysicalRangeError(f"controller.pressure_min = {c['pressure_min']:g} Pa must be below "
                                 f"controller.pressure_max = {c['pressure_max']:g} Pa")
    fraction = values["feedforward"]["t_max_fraction"]
    if fraction > 1.0:
        raise PhysicalRangeError(f"feedforward.t_max_fraction = {fraction:g}: must be in (0, 1] (the closed loop's "
                                 "feedforward locks at this fraction of t_max or earlier)")
    reserve = values["feedforward"]["pressure_reserve"]
    if reserve > 0 and values["feedforward"]["curve"] == "robust":
        raise PhysicalRangeError(f"feedforward.pressure_reserve = {reserve:g} Pa needs feedforward.curve = "
                                 "\"nominal\" (the reserve lowers the nominal optimum's pressure limit)")
    lock_margin = values["feedforward"]["lock_margin"]
    if lock_margin >= 0.5:
        raise PhysicalRangeError(f"feedforward.lock_margin = {lock_margin:g}: must be in [0, 0.5) (the nominal "
                                 "optimum's slipping torque at lock-up over the locked torque, minus one)")
    if lock_margin != LOCK_MARGIN and values["feedforward"]["curve"] == "robust":
        raise PhysicalRangeError(f"feedforward.lock_margin = {lock_margin:g} needs feedforward.curve = \"nominal\" "
                                 "(the margin is the nominal optimum's)")
    estimator = values["estimator"]
    weights = values["lqi"]
    terminal = [key for key in ("terminal_slip_tolerance", "terminal_slip_rate_tolerance") if weights[key] is not None]
    if len(terminal) == 1:
        raise MissingParameterError(f"lqi.{terminal[0]}: give lqi.terminal_slip_tolerance and "
                                    "lqi.terminal_slip_rate_tolerance together (the weights at lock-up) or neither")
    if terminal and estimator["method"] != "kalman":
        raise PhysicalRangeError("lqi.terminal_slip_tolerance and terminal_slip_rate_tolerance need estimator.method "
                                 "= \"kalman\" (the difference design weighs lock-up with terminal_weight)")
    schedule = values["schedule"]
    points = schedule["points"]
    if points != int(points) or points > 25:
        raise PhysicalRangeError(f"schedule.points = {points:g}: must be a whole number from 1 to 25 (one design "
                                 "per point)")
    if schedule["field"] and values["feedforward"]["curve"] == "robust":
        raise PhysicalRangeError(f"schedule.field = {schedule['field']!r} needs feedforward.curve = \"nominal\" (the "
                                 "robust feedforward is one curve for every clutch); remove [schedule] or use the "
                                 "nominal curve")
    if not 0.0 < estimator["activation"] < 1.0:
        raise PhysicalRangeError(f"estimator.activation = {estimator['activation']:g}: must be in (0, 1) (a fraction "
                                 "of the nominal clutch torque's peak)")
    if estimator["gain_limit"] <= 1.0:
        raise PhysicalRangeError(f"estimator.gain_limit = {estimator['gain_limit']:g}: must be above 1 (the largest "
                                 "ratio of nominal to estimated torque gain)")
    if estimator["enabled"] and not c["measure_pressure"]:
        raise PhysicalRangeError("estimator.enabled = true needs controller.measure_pressure = true (the torque gain "
                                 "is the estimated clutch torque over the measured pressure)")
    parameters = _priors(priors)
    if estimator["method"] == "kalman":
        if c["progress"] != "time":
            raise PhysicalRangeError("estimator.method = \"kalman\" needs controller.progress = \"time\" (the filter "
                                     "runs on the sample clock of its design)")
        if not estimator["enabled"]:
            raise PhysicalRangeError("estimator.method = \"kalman\" needs estimator.enabled = true")
    elif parameters or any(k in estimator_raw for k in ("torque_noise", "pressure_noise", "parameter_drift")):
        raise PhysicalRangeError("estimator.parameters, torque_noise, pressure_noise and parameter_drift need "
                                 "estimator.method = \"kalman\"")
    if sensors.get("pressure") is not None and not c["measure_pressure"]:
        raise PhysicalRangeError("[sensors.pressure] needs controller.measure_pressure = true")
    valve = values["valve"]
    if valve["assumed_dead_time"] is None:
        valve["assumed_dead_time"] = valve["dead_time"]
    for key in ("dead_time", "assumed_dead_time"):
        if valve[key] >= c["sample_time"]:
            raise PhysicalRangeError(f"valve.{key} = {valve[key]:g} s: must be below controller.sample_time = "
                                     f"{c['sample_time']:g} s")
    if (valve["dead_time"] or valve["assumed_dead_time"] or sensors) and estimator["method"] != "kalman":
        raise PhysicalRangeError("[sensors] and [valve] need estimator.method = \"kalman\" (the difference "
                                 "estimator reads the exact signals)")
    if values["acceptance"]["lock_by_t_max"] < 1.0:
        raise PhysicalRangeError(f"acceptance.lock_by_t_max = {values['acceptance']['lock_by_t_max']:g}: must be "
                                 ">= 1 (a multiple of t_max)")
    lock = values["lock"]
    if lock["samples"] != int(lock["samples"]) or lock["samples"] > 10:
        raise PhysicalRangeError(f"lock.samples = {lock['samples']:g}: must be a whole number from 1 to 10")
    lock["samples"] = int(lock["samples"])
    return SlipControlSpec(sample_time=c["sample_time"], name=c["name"], description=c["description"],
                           pressure_min=c["pressure_min"], pressure_max=c["pressure_max"],
                           rate_limit_time=c["rate_limit_time"], measure_pressure=c["measure_pressure"],
                           progress=c["progress"], max_delay=c["max_delay"],
                           lqi=weights, anti_windup=values["anti_windup"]["method"], estimator=estimator,
                           feedforward_curve=values["feedforward"]["curve"], t_max_fraction=fraction,
                           pressure_reserve=reserve, lock_margin=lock_margin,
                           schedule_field=schedule["field"], schedule_points=int(points), sensors=sensors,
                           valve=valve, lock=lock, estimated_parameters=parameters,
                           acceptance=values["acceptance"])


def _sensor_tables(raw):
    """The [sensors.*] sub-tables in SI (only those given)."""
    if not isinstance(raw, dict):
        raise ParameterTypeError(f"[sensors]: expected sub-tables like [sensors.input_speed], got {raw!r}")
    check_tables(raw, _SENSORS, "[sensors]")
    out = {}
    for name, table in raw.items():
        out[name] = parse_table(f"sensors.{name}", table, _SENSORS[name])
    for name in ("input_speed", "output_speed"):
        if name in out:
            teeth = out[name]["teeth"]
            if teeth != int(teeth) or teeth < 2:
                raise PhysicalRangeError(f"sensors.{name}.teeth = {teeth:g}: must be a whole number >= 2")
            out[name]["teeth"] = int(teeth)
            revolutions = out[name]["learned_revolutions"]
            if revolutions != int(revolutions) or revolutions > 10000:
                raise PhysicalRangeError(f"sensors.{name}.learned_revolutions = {revolutions:g}: must be a whole "
                                         "number from 0 to 10000")
            out[name]["learned_revolutions"] = int(revolutions)
            if out[name]["dropout"] >= 0.5:
                raise PhysicalRangeError(f"sensors.{name}.dropout = {out[name]['dropout']:g}: must be below 0.5 "
                                         "(a probability per edge)")
            if out[name]["pitch_error"] >= 0.2:
                raise PhysicalRangeError(f"sensors.{name}.pitch_error = {out[name]['pitch_error']:g}: must be "
                                         "below 20 %")
    sump = out.get("sump_temperature")
    if sump is not None and (sump["oil_viscosity_40C"] is None) != (sump["oil_viscosity_100C"] is None):
        raise MissingParameterError("sensors.sump_temperature: give both oil_viscosity_40C and oil_viscosity_100C "
                                    "(the oil's Walther line) or neither")
    if "engine_torque" in out and out["engine_torque"]["error"] >= 1.0:
        raise PhysicalRangeError(f"sensors.engine_torque.error = {out['engine_torque']['error']:g}: must be below "
                                 "100 %")
    return out


def _priors(raw):
    """[estimator.parameters]: scene field -> half-width of its prior spread (a fraction)."""
    if not isinstance(raw, dict):
        raise ParameterTypeError(f"estimator.parameters: expected a table of scene fields like "
                                 f"\"friction.mu\" = \"15 %\", got {raw!r}")
    out = {}
    for key, text in raw.items():
        if not isinstance(key, str) or key.count(".") != 1:
            raise ParameterTypeError(f"estimator.parameters.{key}: expected a scene field \"part.key\"")
        value = parse_table("estimator.parameters", {key: text}, {key: ("1", "positive", None)})[key]
        if value >= 1.0:
            raise PhysicalRangeError(f"estimator.parameters.\"{key}\" = {text!r}: the prior half-width must be "
                                     "below 100 %")
        out[key] = value
    return out
