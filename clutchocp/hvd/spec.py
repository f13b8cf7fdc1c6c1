"""Controller specifications (TOML files in controllers/): what to design and how to test it.

A spec has a ``[controller]`` table (type, sample time, setpoint filter, feedforward, scheduled
speeds, limits), one table for its type (``[lqi]`` or ``[pi]``), an optional ``[anti_windup]``
and an optional ``[scenario]`` (the closed-loop test on the nonlinear plant). Quantities may carry
units (``"10 ms"``, ``"60 deg"``); speeds are fractions of the load's rated speed. Every mistake
raises a :class:`~clutchocp.errors.SceneError` subclass whose one-line message names the field::

    [controller]
    type = "lqi"                       # "lqi" or "pi"
    sample_time = "10 ms"
    reference_time_constant = "0.5 s"  # setpoint filter (two first-order stages); 0: none
    feedforward = true                 # add the scheduled steady pressure u_op(r)
    schedule = [0.4, 0.5, 0.6, 0.7, 0.8, 0.9]

    [lqi]                              # weights on scaled deviations (Bryson's rule)
    speed_weight = 100.0               # (w - w_op) / rated speed
    integral_weight = 1000.0           # integral of the speed error / (rated speed x 1 s)
    input_weight = 1.0                 # (p_cmd - p_op) / valve pressure range

    [pi]
    method = "pole_placement"          # SIMC, or "loop_shaping"
    closed_loop_time_constant = "0.5 s"
    phase_margin = "45 deg"            # targets every scheduled point must meet
    gain_margin_dB = 10.0
"""

import math
from dataclasses import dataclass, field
from pathlib import Path

from ..control.spec import check_tables, parse_table, read_spec
from ..errors import MissingParameterError, PhysicalRangeError, SceneError, UnknownKeyError
from ..scene.loader import builtin_dir

TYPES = ("lqi", "pi")
ANTI_WINDUP = ("back_calculation", "clamping", "none")

# table -> key -> (dimension, check or choices, default); see clutchocp.control.spec
_CONTROLLER = {
    "name": ("str", None, ""),
    "type": ("choice", TYPES, None),
    "description": ("str", None, ""),
    "sample_time": ("s", "positive", None),
    "reference_time_constant": ("s", "nonnegative", 0.0),
    "feedforward": ("bool", None, True),
    "schedule": ("fractions", "fraction", None),
    "pressure_min": ("Pa", "nonnegative", None),
    "pressure_max": ("Pa", "positive", None),
}
_LQI = {
    "speed_weight": ("1", "weight", 1.0),
    "pressure_weight": ("1", "weight", 0.0),
    "film_weight": ("1", "weight", 0.0),
    "integral_weight": ("1", "positive_weight", 1.0),
    "input_weight": ("1", "positive_weight", 1.0),
}
_PI = {
    "method": ("choice", ("loop_shaping", "pole_placement"), "loop_shaping"),
    "closed_loop_time_constant": ("s", "positive", 0.5),
    "phase_margin": ("1", "angle", math.radians(60.0)),
    "gain_margin_dB": ("1", "positive", 10.0),
    "max_sensitivity": ("1", "above_one", 1.6),
    "integral_ratio": ("1", "positive", 4.0),
}
_ANTI_WINDUP = {
    "method": ("choice", ANTI_WINDUP, "back_calculation"),
    "tracking_time": ("s", "positive", None),
}
_SCENARIO = {
    "setpoints": ("fractions", "fraction", (0.4, 0.6, 0.9)),
    "soft_start_time": ("s", "positive", 5.0),
    "step_duration": ("s", "positive", 10.0),
    "load_step": ("1", "fraction", 0.2),
}
_TABLES = {"controller": _CONTROLLER, "lqi": _LQI, "pi": _PI, "anti_windup": _ANTI_WINDUP, "scenario": _SCENARIO}
_REQUIRED = ("type", "sample_time", "schedule")
@dataclass
class ControllerSpec:
    """A validated controller specification (SI units, speeds as fractions of the rated speed)."""

    type: str
    sample_time: float
    schedule: tuple
    name: str = ""
    description: str = ""
    reference_time_constant: float = 0.0
    feedforward: bool = True
    pressure_min: float | None = None
    pressure_max: float | None = None
    lqi: dict = field(default_factory=dict)
    pi: dict = field(default_factory=dict)
    anti_windup: dict = field(default_factory=dict)
    scenario: dict = field(default_factory=dict)
    path: Path | None = None

    @property
    def label(self):
        return self.name or self.type


def builtin_controller_dir():
    """Folder of the built-in specs (controllers/)."""
    return builtin_dir("controllers")


def load_controller(name_or_path):
    """Load a controller spec by built-in name (``"lqi"``, ``"pi"``) or TOML file path.

    Returns
    -------
    ControllerSpec

    Raises
    ------
    SceneError subclasses with a one-line message naming the field.
    """
    return read_spec(name_or_path, parse_controller)


def parse_controller(raw):
    """Validate a parsed controller spec (a dict of TOML tables); return a :class:`ControllerSpec`."""
    check_tables(raw, _TABLES, "controller spec")
    if "controller" not in raw:
        raise MissingParameterError("[controller]: missing table (type, sample_time and schedule are required)")
    values = {name: parse_table(name, raw.get(name, {}), schema, _REQUIRED if name == "controller" else ())
              for name, schema in _TABLES.items()}
    c = values["controller"]
    other = "pi" if c["type"] == "lqi" else "lqi"
    if other in raw:
        raise UnknownKeyError(f"[{other}]: a table for controller type '{other}', but controller.type = '{c['type']}'")
    schedule = tuple(sorted(c["schedule"]))
    if len(set(schedule)) != len(schedule):
        raise SceneError(f"controller.schedule: speeds must differ, got {list(c['schedule'])}")
    if c["pressure_min"] is not None and c["pressure_max"] is not None and c["pressure_min"] >= c["pressure_max"]:
        raise PhysicalRangeError(f"controller.pressure_min = {c['pressure_min']:g} Pa must be below "
                                 f"controller.pressure_max = {c['pressure_max']:g} Pa")
    aw = values["anti_windup"]
    if aw["tracking_time"] is None:
        aw["tracking_time"] = 10 * c["sample_time"]
    return ControllerSpec(type=c["type"], sample_time=c["sample_time"], schedule=schedule, name=c["name"],
                          description=c["description"], reference_time_constant=c["reference_time_constant"],
                          feedforward=c["feedforward"],
                          pressure_min=c["pressure_min"], pressure_max=c["pressure_max"],
                          lqi=values["lqi"], pi=values["pi"], anti_windup=aw, scenario=values["scenario"])
