"""clutchocp.bench.call_replay: the calls a run makes into compiled code, recorded and made again;
and the summary's arithmetic timed apart from its evaluations (clutchocp.bench.summary_work)."""

import casadi
import pytest

from clutchocp.bench.call_replay import CallRecorder, recorded_calls, replay_time
from clutchocp.bench.summary_work import summary_arithmetic_time, summary_time
from clutchocp.bench.workprecision import run_method
from clutchocp.engagement.model import EngagementModel
from clutchocp.scene import load_scene
from clutchocp.simulation.compiled import ColumnFunction
from clutchocp.simulation.idas_path import _Integrator


@pytest.fixture(scope="module")
def zhang():
    scene = load_scene("zhang2021")
    model = EngagementModel(scene)
    run_method(scene, model, "idas", 1e-5)                       # builds and caches the integrators
    return scene, model


def _watched():
    return (_Integrator.__call__, _Integrator.stats, ColumnFunction.__call__, ColumnFunction.on_numpy,
            casadi.Function.__call__)


def test_recorded_calls_are_the_runs_own_and_the_recorder_is_removed(zhang):
    scene, model = zhang
    before = _watched()
    recorder = recorded_calls(scene, model, "idas", 1e-5)
    assert _watched() == before
    counts = recorder.counts()
    # every integrator call reads its statistics once; the summary evaluates outputs on the grid
    assert counts["integrator"] == counts["integrator_stats"] > 0 and counts["column_function"] > 0
    assert sum(counts.values()) == len(recorder.calls)
    recorder.replay()
    # a recorded call redoes the run's work: its last integration ends on the run's last state, bit for bit
    last = max(i for i, call in enumerate(recorder.calls) if call[0] == "integrator")
    _, call, integrator, args, kwargs = recorder.calls[last]
    last_state = call(integrator, *args, **kwargs)[0][:, -1]
    seg = run_method(scene, model, "idas", 1e-5).result.segments[-1]
    cm = model.hybrid.compiled()[seg.mode]
    assert (last_state * cm.x_nominal).tolist() == [seg.x[name][-1] for name in cm.x_names]


def test_only_the_outermost_call_is_recorded_and_arrays_are_copied():
    import numpy as np

    x, z, pu, t = casadi.SX.sym("x"), casadi.SX.sym("z", 0), casadi.SX.sym("pu", 0), casadi.SX.sym("t")
    column = ColumnFunction(casadi.Function("f", [x, z, pu, t], [x * t]))
    n = 4000
    assert column.uses_numpy(n)                      # __call__ calls on_numpy: one call, the outer one
    xs, times = np.ones((1, n)), np.linspace(0.0, 1.0, n)
    recorder = CallRecorder()
    try:
        column(xs, np.zeros((0, n)), np.zeros(0), times)
        xs[0, 0] = 5.0                               # changed after the call: the record keeps 1
        column.function(2.0, [], [], 3.0)            # a CasADi function called directly
    finally:
        recorder.remove()
    assert recorder.counts() == {"column_function": 1, "casadi_function": 1}
    kind, inner, owner, args, _ = recorder.calls[0]
    assert (kind, owner) == ("column_function", column) and inner is ColumnFunction.__call__
    assert args[0][0, 0] == 1.0


def test_summary_arithmetic_is_the_summary_without_its_evaluations(zhang):
    scene, model = zhang
    run = run_method(scene, model, "idas", 1e-5)
    arithmetic = summary_arithmetic_time(run, repeats=3)
    work, summary = summary_time(run, repeats=3)
    assert 0 < arithmetic < work
    assert summary["engagement_time_s"] == run.summary["engagement_time_s"]


def test_replay_time_is_the_best_of_its_timed_replays_after_an_untimed_one():
    class Recorder:
        durations = [0.03, 0.02, 0.005, 0.02]     # the first replay is untimed: best of the other three

        def __init__(self):
            self.replays = 0

        def replay(self):
            import time
            time.sleep(self.durations[self.replays])
            self.replays += 1

    recorder = Recorder()
    best = replay_time(recorder, repeats=3)
    assert recorder.replays == 4
    assert 0.005 <= best < 0.02
