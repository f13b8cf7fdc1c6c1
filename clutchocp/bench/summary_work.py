"""The summary work: what every whole engagement run does after its integration, whatever integrated it.

A run's summary (:func:`clutchocp.engagement.measures.summarize`) evaluates the ~15 outputs it reads
on all the run's samples (the jerk alone is ~1 700 instructions on default_driveline) and then its
crossings, peaks and energy balance. IDAS's and the scipy integrators' whole runs pay it alike, so
it is part of what any IDAS run costs beyond its integrator floor, however its hybrid loop is made.

:func:`summary_time` times it on a finished run: the run's scaled samples, outputs evaluated afresh
(none carried over from the run, where some are evaluated with the event functions) the way the
run's own lazy outputs evaluate them, then the summary, which is the run's own bit for bit.
:func:`summary_arithmetic_time` times the summary alone, its outputs evaluated beforehand.
"""

import copy
import math
import time

import numpy as np

from ..engagement.measures import summarize
from ..errors import ClutchocpError
from ..simulation.driver import _SegmentOutputs
from ..simulation.options import SimulationOptions
from ..simulation.result import LazyOutputs, Segment


def evaluators(result):
    """The lazy-output evaluators of a hybrid result's segments (each keeps its segment's scaled
    samples until every output is read; a run with ``native=True`` reads them all in its summary, so
    take them before it: :func:`clutchocp.engagement.run.summarize` is the place)."""
    return [getattr(seg.outputs, "_evaluate", None) for seg in result.segments]


def unevaluated(run, kept=None):
    """A copy of the engagement run's hybrid result whose outputs are evaluated afresh when read.

    Parameters
    ----------
    run : clutchocp.engagement.run.EngagementResult
    kept : list, optional
        The evaluators of its segments (:func:`evaluators`), by default those the run still holds
        (a run on CasADi's virtual machine holds them after its summary).

    Returns
    -------
    clutchocp.simulation.result.SimulationResult
        The same samples, events and statistics; no output evaluated yet.
    """
    compiled = run.model.hybrid.compiled()
    kept = evaluators(run.result) if kept is None else kept
    segments = []
    for seg, evaluator in zip(run.result.segments, kept):
        if not isinstance(evaluator, _SegmentOutputs):
            raise ClutchocpError(f"segment in mode '{seg.mode}' let its samples go (every output read): pass the "
                                 "evaluators taken before its summary")
        cm = compiled[seg.mode]
        block = (evaluator.t, evaluator.xs, evaluator.zs, np.zeros(0), None)   # the model's values are built in
        outputs = LazyOutputs(cm.output_names, _SegmentOutputs(cm, [block], evaluator.t, evaluator.xs, evaluator.zs,
                                                               evaluator.native))
        segments.append(Segment(seg.mode, seg.t, seg.x, seg.z, outputs))
    fresh = copy.copy(run.result)
    fresh.segments = segments
    return fresh


def summary_time(run, repeats=5, method="idas", kept=None):
    """Best wall time [s] of ``repeats`` summaries of ``run`` computed from its samples alone (``kept``:
    see :func:`unevaluated`), and the last summary (the run's own but for ``wall_time_s`` and the
    solver block, which take what is passed here: zero and default options)."""
    best, summary = math.inf, None
    for attempt in range(repeats + 1):           # the first builds the output functions of this subset
        fresh = unevaluated(run, kept)
        start = time.perf_counter()
        summary = summarize(run.model, fresh, 0.0, SimulationOptions(), method)
        if attempt:
            best = min(best, time.perf_counter() - start)
    return best, summary


def summary_arithmetic_time(run, repeats=5, method="idas", kept=None):
    """Best wall time [s] of ``repeats`` summaries of ``run`` with every output already evaluated: the
    summary's own arithmetic (crossings, peaks, energy balance), without the evaluations
    :func:`summary_time` includes (``kept``: see :func:`unevaluated`)."""
    fresh = unevaluated(run, kept)
    fresh.load(fresh.names())                    # every output, outside the timed summaries
    summarize(run.model, fresh, 0.0, SimulationOptions(), method)
    best = math.inf
    for _ in range(max(1, repeats)):
        start = time.perf_counter()
        summarize(run.model, fresh, 0.0, SimulationOptions(), method)
        best = min(best, time.perf_counter() - start)
    return best
