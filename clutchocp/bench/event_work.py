"""The event work: the event detection a whole engine run does on the samples it keeps.

The engine finds its events on the output grid: each mode's scaled event functions are evaluated on
the samples of every integrator call, and a sign change between two samples starts the location
(:mod:`clutchocp.simulation.events`). However the hybrid loop around the calls is made, the samples a
run keeps have been checked for events; the floor (:mod:`clutchocp.bench.floor`) knows its events and
checks none. CasADi's own event handling, the one alternative inside the integrator, costs more per
step than it would save (``benchmarks/bench_first_call_stop.py``).

:func:`event_work_time` times that check on a finished run: the event functions of each segment's
mode on the segment's samples, one evaluation per stretch of samples with equal inputs, by the
evaluator the run itself uses (:meth:`~clutchocp.simulation.compiled.CompiledMode.event_values`).
"""

import math
import time

from ..errors import ClutchocpError
from ..simulation.driver import _SegmentOutputs
from .summary_work import evaluators


def event_checks(run, kept=None):
    """The event evaluations of an engine run's kept samples, as ``(evaluate, xs, zs, pu, t)`` tuples.

    Parameters
    ----------
    run : clutchocp.engagement.run.EngagementResult
        A run of the engine (``method="idas"``).
    kept : list, optional
        The evaluators of its segments (:func:`~clutchocp.bench.summary_work.evaluators`), by default
        those the run still holds.

    Returns
    -------
    list of tuple
        Per stretch of samples with equal inputs in a mode with events: the column function of the
        mode's scaled event functions and its arguments (scaled states and algebraic variables
        (rows, n), inputs, times [s] (n,)).
    """
    compiled = run.model.hybrid.compiled()
    kept = evaluators(run.result) if kept is None else kept
    checks = []
    for seg, evaluator in zip(run.result.segments, kept):
        cm = compiled[seg.mode]
        if not cm.events:
            continue
        if not isinstance(evaluator, _SegmentOutputs):
            raise ClutchocpError(f"segment in mode '{seg.mode}' let its samples go (every output read): pass the "
                                 "evaluators taken before its summary")
        evaluate, start = cm.event_values(evaluator.native), 0
        for pu, count, _ in evaluator.runs:
            part = slice(start, start + count)
            checks.append((evaluate, evaluator.xs[:, part], evaluator.zs[:, part], pu, evaluator.t[part]))
            start += count
    return checks


def event_work_time(run, repeats=5, kept=None):
    """Best wall time [s] of ``repeats`` evaluations of :func:`event_checks` (after one untimed
    evaluation, which builds the maps of these sample counts)."""
    checks = event_checks(run, kept)
    best = math.inf
    for attempt in range(repeats + 1):
        start = time.perf_counter()
        for evaluate, xs, zs, pu, t in checks:
            evaluate(xs, zs, pu, t)
        if attempt:
            best = min(best, time.perf_counter() - start)
    return best
