"""The engagement problem with some scene values as a parameter vector theta of its NLP functions.

The functions are built on the engagement model of a
:class:`~clutchocp.scene.symbolic.SymbolicScene` (those values as CasADi symbols, theta), which the
problem receives as the model it transcribes; every other part of the problem (state groups and
scales, initial state, baseline, bounds) is that of the numeric scene. One set of functions then
serves every value of theta: the scenarios of a robust problem (:mod:`clutchocp.optimal.robust`)
and the points of an optimize sweep (:mod:`clutchocp.study.parametric_ocp`).
"""

import casadi as ca
import numpy as np

from ..engagement.model import EngagementModel
from ..errors import ModelError
from ..scene.symbolic import SymbolicScene
from .models import quasi_static_scene
from .problem import EngagementOCP


class ParametricOCP(EngagementOCP):
    """The engagement problem of a scene with the scene values ``names`` as a parameter vector theta.

    ``dynamics_fn``, ``objective_fn`` and ``end_fn`` take ``[weights; theta]`` as their parameter,
    ``outputs_fn`` and ``jump_fn`` take theta as a third input; :attr:`theta_value` holds the scene's
    values (the NLP parameter of a solve, the default of :meth:`outputs_at` and :meth:`lockup_jump`).

    Parameters
    ----------
    scene : clutchocp.scene.Scene
    names : sequence of str
        Scene fields (numeric, ``"part.key"``) that become theta.
    **options
        As for :class:`~clutchocp.optimal.problem.EngagementOCP`.

    Raises
    ------
    ModelError
        A field that is not numeric, or one the engagement model cannot take as a symbol.
    """

    def __init__(self, scene, names, **options):
        self.parameter_names = tuple(names)
        self.theta = ca.SX.sym("theta", len(self.parameter_names))
        self.theta_value = self.nominal_theta(scene)
        super().__init__(scene, **options)

    def nominal_theta(self, scene):
        """theta of a scene (its SI values of the parameter names)."""
        values = []
        for name in self.parameter_names:
            value = scene.value(name)
            if not isinstance(value, (int, float, np.floating, np.integer)) or isinstance(value, bool):
                raise ModelError(f"{name}: a robust scenario may vary numeric scene values only (got {value!r})")
            values.append(float(value))
        return np.array(values)

    def transcribed_model(self):
        """The engagement model of the scene (plate masses taken as massless as in the numeric model)
        with the parameter values as the symbols theta."""
        scene = quasi_static_scene(self.scene) if self.quasi_static_plates else self.scene
        symbols = dict(zip(self.parameter_names, ca.vertsplit(self.theta)))
        return EngagementModel(SymbolicScene(scene, symbols), smooth=self.smooth, pressure_command=self.u)

    def _phase_functions(self):
        try:
            return super()._phase_functions()
        except (TypeError, RuntimeError, NotImplementedError) as exc:
            raise ModelError(f"{', '.join(self.parameter_names)}: the engagement model cannot take these values as "
                             f"symbols of one collocation problem ({type(exc).__name__}: {str(exc).splitlines()[0]})"
                             ) from None

    def parameter_values(self, weights):
        """The NLP parameter vector of a solve: the objective weights, then theta."""
        return super().parameter_values(weights) + list(self.theta_value)

    @property
    def exact(self):
        """The twin problem on the exact forms (the polish stage), with the same parameters."""
        if self._exact is None:
            self._exact = type(self)(self.scene, self.parameter_names, smooth=False, polish=False,
                                     baseline=self.baseline, transcription=self.transcription, models=self.models,
                                     **self.options)
        return self._exact
