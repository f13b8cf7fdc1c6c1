"""One engagement model for all points of a sweep: the swept scene values as CasADi parameters.

The engagement model writes scene values into its equations as numbers, so every point of a sweep
is a new model to assemble, compile and give integrators (measured: 95-99 % of a new point's time
is spent outside the integrator calls). Here the model is assembled once per worker from a view
of the scene (:class:`SymbolicScene`) in which the swept fields are CasADi symbols; the symbols
become parameters of the hybrid model, and each point runs the same compiled functions and
cached integrators with its own values.

This works for a field the model only uses inside its equations (viscosity, friction
coefficients, load torque, pressures, time constants ...). A field that also sets a state's
scale, an initial state or a mode decision (speeds, gaps, the plate count) cannot be a symbol:
assembling the model then fails (CasADi refuses the truth value of a symbol) and the sweep falls
back to one model per point. The first point each worker runs is also run the usual way and the
two runs compared (:data:`AGREEMENT`), so a field whose symbolic use would differ is caught too.
Results agree with the usual runs to the integration tolerance, not bit for bit: constants are
folded in a different order.
"""

import copy


from ..engagement.model import EngagementModel
from ..scene.symbolic import SymbolicScene
from ..simulation.model import HybridModel

AGREEMENT = 1e-6        # relative: the first parametric run against the usual run of the same point
COMPARED = ("engagement_time_s", "peak_torque_Nm", "dissipated_energy_J")


class ParametricModel:
    """An :class:`EngagementModel` of ``scene`` with the fields ``names`` as parameters.

    Raises whatever assembling the model raises when a field cannot be a symbol (see the module
    notes); :func:`build` turns that into None.
    """

    def __init__(self, scene, names):
        symbolic = SymbolicScene(scene, names)
        self.names = tuple(names)
        self.model = EngagementModel(symbolic)
        [float(b) for b in self.model.actuation.breakpoints()]     # the output grid must not depend on them
        hybrid = self.model.hybrid
        self.hybrid = HybridModel(list(hybrid.modes.values()), p=symbolic.symbols, u=hybrid.u or None, t=hybrid.t)

    def for_point(self, scene):
        """The model as :func:`~clutchocp.engagement.run.simulate_engagement` takes it for one point
        (its scene, for the summary, is the point's), and the parameter values [SI]."""
        view = copy.copy(self.model)
        view.scene = scene
        view.hybrid = self.hybrid
        return view, {name: float(scene.value(name)) for name in self.names}


def build(scene, names):
    """A :class:`ParametricModel`, or None if a field cannot be a parameter of this scene's model."""
    try:
        return ParametricModel(scene, names)
    except Exception:                      # a symbol where the model needs a number: one model per point
        return None


def agrees(summary, reference):
    """True if a parametric run's summary matches the usual run's (:data:`COMPARED`, :data:`AGREEMENT`)."""
    for key in COMPARED:
        a, b = summary[key], reference[key]
        if (a is None) != (b is None):
            return False
        if a is not None and abs(a - b) > AGREEMENT * max(abs(b), 1e-12):
            return False
    return summary["final_mode"] == reference["final_mode"]
