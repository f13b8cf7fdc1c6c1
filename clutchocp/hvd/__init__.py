"""Hydro-viscous drive speed regulation: model, operating points, linearisation, control design, closed loop.

Typical use::

    from clutchocp.hvd import run_control
    summary = run_control("liao2021_hvd", "pi", out_dir="out/control")
"""

from .closed_loop import Scenario, make_scenario, simulate_closed_loop
from .controller import ScheduledController
from .design import design, loop_margins
from .linearize import describe, finite_difference, linearize
from .model import HvdModel
from .report import run_control
from .spec import ControllerSpec, load_controller, parse_controller
from .steady import OperatingPoint, operating_point, rest_state, static_map

__all__ = [
           "ControllerSpec",
           "HvdModel",
           "OperatingPoint",
           "Scenario",
           "ScheduledController",
           "describe",
           "design",
           "finite_difference",
           "linearize",
           "load_controller",
           "loop_margins",
           "make_scenario",
           "operating_point",
           "parse_controller",
           "rest_state",
           "run_control",
           "simulate_closed_loop",
           "static_map",
]
