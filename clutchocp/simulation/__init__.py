"""Hybrid (multi-mode) DAE simulation engine on CasADi IDAS, with a scipy cross-check path.

A model is a :class:`HybridModel` of :class:`Mode` objects (semi-explicit index-1 DAEs in
CasADi SX with named, scaled states) linked by :class:`Event` objects with reset maps;
:func:`simulate` integrates it over an output grid and returns a :class:`SimulationResult`.
See ``README-engine.md`` in this folder.
"""

from clutchocp.simulation.driver import simulate
from clutchocp.simulation.derivative import time_derivative
from clutchocp.simulation.model import Event, HybridModel, Mode, PiecewiseConstant
from clutchocp.simulation.options import METHODS, SimulationOptions
from clutchocp.simulation.result import EventRecord, Segment, SimulationResult

__all__ = [
           "METHODS",
           "Event",
           "EventRecord",
           "HybridModel",
           "Mode",
           "PiecewiseConstant",
           "Segment",
           "SimulationOptions",
           "SimulationResult",
           "simulate",
           "time_derivative",
]
