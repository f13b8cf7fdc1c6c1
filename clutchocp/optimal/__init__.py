"""Optimal engagement pressure by direct collocation (CasADi + IPOPT), verified with IDAS.

* :class:`EngagementOCP` — the optimal-control problem of a scene's engagement (fill and slip phases); ``solve()``;
* :func:`verify` — IDAS replay of an optimum against the collocation prediction;
* :func:`simulate_baselines` — step, ramp and first-order-lag baselines;
* :func:`jerk_lower_bound` — the kinematic lower bound of the jerk integral (closed form);
* :class:`DirectCollocation`, :class:`StagedProblem`, :func:`nlp_solver` — the generic transcription;
* :class:`PhasedNLP`, :class:`Phase`, :func:`phased_derivatives` — a sequence of phases in one NLP;
* :func:`run_optimize` — the ``clutchocp optimize`` command (files and figures).
"""

from .baselines import simulate_baselines
from .bound import jerk_lower_bound, minimum_jerk_slip
from .collocation import DirectCollocation, StagedProblem, collocation_coefficients
from .derivatives import nlp_solver, structured_derivatives
from .phases import Phase, PhasedNLP, phased_derivatives
from .problem import DEFAULT_WEIGHTS, OBJECTIVE_TERMS, EngagementOCP, OptimalEngagement
from .report import run_optimize
from .verify import verify

__all__ = [
    "DEFAULT_WEIGHTS",
    "OBJECTIVE_TERMS",
    "DirectCollocation",
    "EngagementOCP",
    "OptimalEngagement",
    "Phase",
    "PhasedNLP",
    "StagedProblem",
    "collocation_coefficients",
    "jerk_lower_bound",
    "minimum_jerk_slip",
    "nlp_solver",
    "phased_derivatives",
    "run_optimize",
    "simulate_baselines",
    "structured_derivatives",
    "verify",
]
