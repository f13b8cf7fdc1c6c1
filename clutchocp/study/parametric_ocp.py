"""One collocation problem per worker for the points of an optimize sweep: the swept scene values
as parameters of the NLP.

An ordinary optimize point builds its :class:`~clutchocp.optimal.problem.EngagementOCP`: the
engagement model with the point's values as numbers, the scaled NLP, its exact derivatives and
IPOPT solvers, and the same again for the polish stage on the exact switching laws. Here a worker
builds that once (:class:`SweepOCP`, at its first point) with the swept fields as a parameter
vector theta of the NLP functions (a :class:`~clutchocp.optimal.parametric.ParametricOCP`, the
problem the robust scenarios use too), and at every further
point only sets the point's values (:meth:`SweepOCP.set_point`) and solves again, starting from the
neighbour's optimum.

Scales. The ordinary problem scales time, energy, jerk and lock-up torque by references from the
point's own baseline run (``EngagementOCP._references``: t_ref, E_ref, J_ref, T_ref). The reused problem
keeps the first point's references (index 0) for its variables -- a change of variables, the same
physical problem -- and moves the point's references into the objective weights, so that its
objective is the ordinary one term by term (problem.py module notes, J):

    w_jerk' = w_jerk J_ref0 / J_ref      (int jerk^2 dt / J_ref)
    w_energy' = w_energy E_ref0 / E_ref  (E / E_ref)
    w_time' = w_time t_ref0 / t_ref      (t_f / t_ref)
    w_jump' = w_jump (T_ref0 / T_ref)^2  ((jump / T_ref)^2)
    w_smooth' = w_smooth t_ref / t_ref0  (int (dp/dt)^2 dt t_ref / p_ref^2)

The optimum is the ordinary build's to IPOPT's tolerance, not bit for bit (the NLP is scaled
differently); the objective value is the ordinary one.

A point is solved on the reused problem only where nothing else of the problem depends on the
swept fields: one slip phase (no fill phase), a lock that carries torque (its end condition is then
free of the torque reference), and the same initial state, state scales, merged films, pressure
limit, initial pressure and heat limits (:meth:`SweepOCP.structure`, checked at every point).
Elsewhere, and for a field the model cannot take as a symbol, :func:`build` gives None or
:meth:`SweepOCP.set_point` raises :class:`NotReusable`, and the point gets its own problem.
The time cap of a solve stays 20 first-point lock times (``t_max`` above it is not the binding
bound on either problem).
"""

import copy
import time

import numpy as np

from ..engagement.model import EngagementModel
from ..engagement.run import EngagementResult, simulate_engagement, summarize
from ..optimal.bound import output_jerk_share
from ..optimal.heat import heat_limits
from ..optimal.models import SceneModels, quasi_static_scene
from ..optimal.objective import OBJECTIVE_TERMS
from ..optimal.parametric import ParametricOCP
from ..optimal.replay import CommandModel
from ..scene.symbolic import SymbolicScene
from ..simulation import HybridModel, SimulationOptions, simulate
from . import parametric


class NotReusable(Exception):
    """This point's problem differs from the reused one in more than the swept values."""


def field_values(scene, names):
    """The point's values of the swept fields [SI], as theta."""
    return np.array([float(scene.value(name)) for name in names])


class SweepOCP(ParametricOCP):
    """A :class:`~clutchocp.optimal.parametric.ParametricOCP` of ``scene`` with the swept fields
    ``names`` as NLP parameters, set to one point of the sweep after another.

    Parameters
    ----------
    scene : clutchocp.scene.Scene
        The first point's scene (its references scale the NLP, see the module notes).
    names : sequence of str
        The swept fields (numeric ``"part.key"``).
    **options
        As for :class:`~clutchocp.optimal.problem.EngagementOCP`.

    Raises
    ------
    NotReusable
        A fill phase, or a lock that carries no torque.
    Exception
        Whatever assembling the model raises for a field that cannot be a symbol.
    """

    def __init__(self, scene, names, **options):
        super().__init__(scene, names, **options)
        if len(self.phase_modes) != 1 or not self.holds_torque:
            raise NotReusable("a fill phase or a lock that carries no torque")
        self.point_scales = self.scales
        self._structure = self.structure(self.model)

    def structure(self, model):
        """What the reused problem takes from its first point besides the swept values, for ``model``
        (the numeric model of a point): a point is reusable if this is the first point's."""
        groups = self._state_groups(model)
        phys = [model.index[n] for n in groups]
        scene = model.scene
        return (model.initial_mode(), tuple(model.state_names), tuple(map(tuple, groups.values())),
                tuple(model.initial_state[phys]), tuple(model.nominal[phys]),
                scene.get("actuation.max_pressure"), scene.value("actuation.initial_pressure"),
                scene.value("driveline.input_speed"), scene.get("driveline.output_speed", 0.0),
                bool(not model.output_inertia and model.input_inertia),
                tuple(heat_limits(model, self.options["max_temperature_C"],
                                  self.options["max_specific_power_W_mm2"])))

    def set_point(self, scene, baseline=None, point_scales=None, models=None):
        """Make this the problem of ``scene`` (a point of the sweep): its values, baseline run and
        references; raises :class:`NotReusable` where it differs in more (the module notes).

        ``baseline``, ``point_scales`` and ``models`` are given by the smooth problem to its polish twin
        (which then takes the smooth model's references, as the ordinary twin takes the baseline)."""
        if point_scales is None:
            model = EngagementModel(quasi_static_scene(scene) if self.quasi_static_plates else scene,
                                    smooth=self.smooth, pressure_command=self.u)
            if self.structure(model) != self._structure:
                raise NotReusable("the point changes more than the swept values")
        if baseline is None:
            baseline = self.baseline_run(scene)
        self.scene, self.baseline, self._fastest = scene, baseline, None
        self.models = SceneModels(scene) if models is None else models
        self.reference_run = baseline if baseline.summary["engagement_time_s"] is not None else self.fastest_run()
        self.output_jerk_share = 1.0 if self.output_held else output_jerk_share(scene)
        if point_scales is None:
            self.model = model
            point_scales, holds = self._references(model)   # the point's references (the ordinary build's scales)
            if not holds:
                raise NotReusable("the lock carries no torque at this point")
        self.point_scales = point_scales
        self.theta_value = field_values(scene, self.parameter_names)
        if self._exact is not None:
            self._exact.set_point(scene, baseline, point_scales, self.models)

    def baseline_run(self, scene):
        """The IDAS run of the point's own profile (the ordinary build's baseline): on one model with
        the swept fields as parameters (:mod:`clutchocp.study.parametric`) where that agrees with
        the ordinary run at the first point, else the ordinary run."""
        if not hasattr(self, "_baseline_model"):
            first = self.baseline
            self._baseline_model = parametric.build(self.scene, self.parameter_names)
            if self._baseline_model is not None:
                view, values = self._baseline_model.for_point(self.scene)
                try:
                    run = simulate_engagement(self.scene, model=view, parameters=values)
                    agree = parametric.agrees(run.summary, first.summary)
                except Exception:
                    agree = False
                self._baseline_model = self._baseline_model if agree else None
        if self._baseline_model is None:
            return simulate_engagement(scene)
        view, values = self._baseline_model.for_point(scene)
        return simulate_engagement(scene, model=view, parameters=values)

    def fastest_run(self):
        """The IDAS run of a step to :attr:`apply_pressure` at this point (as the ordinary
        ``fastest_run``), on one command model with the swept fields as parameters where that
        agrees with the ordinary run at the first point."""
        if self._fastest is None:
            if not hasattr(self, "_step_model"):
                self._step_model = StepRuns(self.scene, self.parameter_names)
                try:
                    agree = parametric.agrees(self._step_model.run(self.scene, self.apply_pressure).summary,
                                              super().fastest_run().summary)
                except Exception:
                    agree = False
                self._step_model = self._step_model if agree else None
            if self._step_model is None:
                return super().fastest_run()
            run = self._step_model.run(self.scene, self.apply_pressure)
            if run.summary["engagement_time_s"] is None:
                return super().fastest_run()                    # its error message
            self._fastest = run
        return self._fastest

    def parameter_values(self, weights):
        """The weights moved onto the first point's scales (module notes), then theta."""
        sc, pt = self.scales, self.point_scales
        w = dict(weights)
        w["jerk"] *= sc.jerk_integral / pt.jerk_integral
        w["energy"] *= sc.energy_J / pt.energy_J
        w["time"] *= sc.time_s / pt.time_s
        w["jump"] *= (sc.torque_Nm / pt.torque_Nm) ** 2
        w["smooth"] *= pt.time_s / sc.time_s
        return [w[k] for k in OBJECTIVE_TERMS] + list(self.theta_value)

    def check_feasible_time(self, t_max, t_ref=None):
        """As the ordinary problem's, against the point's own lock time."""
        super().check_feasible_time(t_max, self.point_scales.time_s if t_ref is None else t_ref)


class StepRuns:
    """IDAS runs of a constant pressure command on the exact model of a scene with the fields
    ``names`` as parameters: :func:`clutchocp.optimal.replay.simulate_command` of a step, for every
    point of a sweep on one model (its integrators built once)."""

    def __init__(self, scene, names):
        symbolic = SymbolicScene(scene, names)
        self.names = tuple(names)
        self.model = CommandModel(symbolic)
        hybrid = self.model.hybrid
        self.hybrid = HybridModel(list(hybrid.modes.values()), p=symbolic.symbols, u=hybrid.u or None, t=hybrid.t)

    def run(self, scene, value):
        """The step to ``value`` [Pa] at t = 0 until simulation.t_end, at the point ``scene``
        (the options and output grid of ``simulate_command``)."""
        eng = copy.copy(self.model.engagement)
        eng.scene = scene
        t_end = scene.value("simulation.t_end")
        options = SimulationOptions(rtol=scene.value("simulation.rtol"), atol=scene.value("simulation.atol"),
                                    chunk=32, chunk_growth=2.0)
        grid = np.unique(np.concatenate([np.linspace(0.0, t_end, 2001), [0.0]]))
        x0 = dict(zip(eng.state_names, eng.initial_state))
        start = time.perf_counter()
        result = simulate(self.hybrid, x0, grid, mode=eng.initial_mode(), u=self.model.inputs([0.0], [value]),
                          p={name: float(scene.value(name)) for name in self.names}, options=options)
        return EngagementResult(eng, result, summarize(eng, result, time.perf_counter() - start, options, "idas"))


def build(scene, names, **options):
    """A :class:`SweepOCP` at ``scene`` (the first point) with its polish twin, or None where the
    problem cannot be reused (module notes)."""
    try:
        ocp = SweepOCP(scene, names, **options)
        if ocp.polish:
            ocp.exact.solver(True)                    # the twin, built with the first point's scales
        ocp.baseline_run(scene)                       # the baseline model, checked at the first point
        return ocp
    except Exception:                  # a symbol where the model needs a number, a fill phase ...
        return None
