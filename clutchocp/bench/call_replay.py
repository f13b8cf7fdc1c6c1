"""The calls a run makes into compiled code, recorded on one run and made again back to back.

A whole engagement run is its calls into compiled code (the integrator calls and the reading of
their statistics, outputs and event functions on the grid or at one sample, other CasADi functions
such as the consistent-initialisation Newton solve) and the Python around them (the hybrid loop's
planning and decisions, the setup, the result assembly, the summary's arithmetic). Replaying the
calls with nothing between them times the first part alone: what an engine written in Python that
makes the same calls, and so gives the same results, costs at the very least.
"""

import functools

import numpy as np

from .turns import wall


class Patches:
    """Wrappers installed on classes or modules until :meth:`remove`."""

    def __init__(self):
        self._undo = []

    def _wrap(self, owner, name, make):
        inner = getattr(owner, name)
        setattr(owner, name, functools.wraps(inner)(make(inner)))
        self._undo.append((owner, name, inner))

    def remove(self):
        for owner, name, inner in reversed(self._undo):
            setattr(owner, name, inner)
        self._undo = []


class CallRecorder(Patches):
    """Records the calls into compiled code made while it is installed (until :meth:`remove`).

    Only the outermost call counts: a column function whose numpy form calls the maps of its tables
    is one call. ``calls`` holds ``(kind, function, self, args, kwargs)`` with array arguments copied
    as they were at the call; :meth:`replay` makes the same calls again.
    """

    def __init__(self):
        import casadi

        from ..simulation import compiled, idas_path

        super().__init__()
        self.calls, self._depth = [], 0
        self._wrap(idas_path._Integrator, "__call__", self._recording("integrator"))
        self._wrap(idas_path._Integrator, "stats", self._recording("integrator_stats"))
        for name in ("__call__", "on_numpy"):
            self._wrap(compiled.ColumnFunction, name, self._recording("column_function"))
        self._wrap(casadi.Function, "__call__", self._recording("casadi_function"))

    def _recording(self, kind):
        def make(inner):
            def recorded(owner, *args, **kwargs):
                if self._depth == 0:
                    copied = [np.array(a, copy=True) if isinstance(a, np.ndarray) else a for a in args]
                    self.calls.append((kind, inner, owner, copied, dict(kwargs)))
                self._depth += 1
                try:
                    return inner(owner, *args, **kwargs)
                finally:
                    self._depth -= 1
            return recorded
        return make

    def counts(self):
        """Number of recorded calls by kind (``integrator``, ``integrator_stats``, ``column_function``,
        ``casadi_function``)."""
        out = {}
        for kind, *_ in self.calls:
            out[kind] = out.get(kind, 0) + 1
        return out

    def replay(self):
        """Make the recorded calls again, back to back."""
        for _, inner, owner, args, kwargs in self.calls:
            inner(owner, *args, **kwargs)


def recorded_calls(scene, model, method, rtol):
    """The calls of one engagement run of ``method`` at ``rtol``, its summary included.

    Returns
    -------
    CallRecorder
        Removed from the classes it watched; its ``calls`` are the run's.
    """
    from .workprecision import run_method

    recorder = CallRecorder()
    try:
        run_method(scene, model, method, rtol)
    finally:
        recorder.remove()
    return recorder


def replay_time(recorder, repeats=5):
    """Best wall time [s] of ``repeats`` replays of the recorded calls (after one untimed replay)."""
    task = wall(recorder.replay)
    task()
    return min(task()[0] for _ in range(max(1, repeats)))


def run_replay_time(scene, model, method, rtol, repeats=5):
    """Best wall time [s] of the calls one run of ``method`` at ``rtol`` makes into compiled code,
    replayed back to back (:func:`recorded_calls`, :func:`replay_time`)."""
    return replay_time(recorded_calls(scene, model, method, rtol), repeats)

