"""Outputs evaluated when first read: the same values as evaluating every output at the end of the run,
each output evaluated once, results that still pickle, stitched results included."""

import pickle

import casadi as ca
import numpy as np
import pytest

from clutchocp.engagement.measures import summarize, summary_outputs
from clutchocp.engagement.model import EngagementModel
from clutchocp.engagement.run import simulate_engagement
from clutchocp.scene import load_scene
from clutchocp.simulation import SimulationOptions, simulate
from clutchocp.simulation.compiled import ColumnFunction
from clutchocp.simulation.result import LazyOutputs, SimulationResult


def _eager(cm, seg):
    """Every output of a segment evaluated at once, as every run did before outputs were lazy: the mode's
    full output function on each run of samples with equal inputs, from the scaled samples the run kept
    (``seg.x`` divided by its nominal values may differ from them by an ulp). Read before the outputs
    are all evaluated (the segment then lets go of its samples)."""
    kept = seg.outputs._evaluate
    assert sum(count for _, count, _ in kept.runs) == seg.t.size
    parts, start = [], 0
    for pu, count, _ in kept.runs:
        parts.append(cm.outputs_on(kept.xs[:, start:start + count], kept.zs[:, start:start + count], pu,
                                   seg.t[start:start + count]))
        start += count
    y = np.concatenate(parts, axis=1) if parts else np.zeros((len(cm.output_names), 0))
    return {name: y[i] for i, name in enumerate(cm.output_names)}


def _check_against_eager(model, result, read):
    """Every output of every segment, read lazily (``read(seg, names)`` decides the grouping), is bit for
    bit the eager evaluation: a subset of the outputs is the same operations on the same numbers."""
    compiled = model.compiled()
    expected = [_eager(compiled[seg.mode], seg) for seg in result.segments]
    lengths = []
    for seg, values in zip(result.segments, expected):
        cm = compiled[seg.mode]
        assert isinstance(seg.outputs, LazyOutputs)
        read(seg, cm.output_names)
        for name in cm.output_names:
            assert np.array_equal(seg.outputs[name], values[name], equal_nan=True), (seg.mode, name)
        lengths.append(seg.t.size)
    return lengths


def _one_by_one(seg, names):
    for name in names:
        seg.outputs[name]


def _in_halves(seg, names):
    seg.outputs.load(names[1::2])
    seg.outputs.load(names)


@pytest.fixture(scope="module")
def driveline():
    scene = load_scene("default_driveline")
    model = EngagementModel(scene)
    return model, simulate_engagement(scene, model=model)


@pytest.mark.parametrize("read", [_one_by_one, _in_halves])
def test_lazy_outputs_equal_eager_evaluation_slip_and_locked(driveline, read):
    """default_driveline: a short slipping segment (CasADi's map) and a long locked one (numpy form);
    the summary has read its outputs as one subset, the rest are read one by one or in two groups."""
    model, _ = driveline
    run = simulate_engagement(model.scene, model=model)
    modes = [seg.mode for seg in run.result.segments]
    assert any(m.endswith("locked") for m in modes) and any(not m.endswith("locked") for m in modes)
    for seg in run.result.segments:
        cm = model.hybrid.compiled()[seg.mode]
        assert set(seg.outputs.evaluated()) == set(summary_outputs(model)) & set(cm.output_names)
    lengths = _check_against_eager(model.hybrid, run.result, read)
    assert max(lengths) >= 600 and min(lengths) < 600      # both sides of the numpy form's threshold


@pytest.mark.parametrize("scene_name", ["zhang2021", "default_driveline_thermal", "bao2020"])
def test_lazy_outputs_on_other_scenes(scene_name):
    scene = load_scene(scene_name)
    model = EngagementModel(scene)
    options = SimulationOptions(rtol=scene.value("simulation.rtol"), atol=scene.value("simulation.atol"))
    grid = np.linspace(0.0, scene.value("simulation.t_end"), scene.value("simulation.output_points"))
    result = simulate(model.hybrid, dict(zip(model.state_names, model.initial_state)), grid,
                      mode=model.initial_mode(), options=options)
    assert all(seg.outputs.evaluated() == [] for seg in result.segments)
    _check_against_eager(model.hybrid, result, _in_halves)


def test_each_output_is_evaluated_once_and_the_summary_in_one_call_per_segment(driveline, monkeypatch):
    from clutchocp.simulation import driver

    model, _ = driveline
    calls = []
    original = driver._SegmentOutputs.__call__

    def counted(self, names):
        calls.append(tuple(names))
        return original(self, names)

    scene = model.scene
    options = SimulationOptions(rtol=scene.value("simulation.rtol"), atol=scene.value("simulation.atol"))
    grid = np.linspace(0.0, scene.value("simulation.t_end"), scene.value("simulation.output_points"))
    result = simulate(model.hybrid, dict(zip(model.state_names, model.initial_state)), grid,
                      mode=model.initial_mode(), options=options)
    monkeypatch.setattr(driver._SegmentOutputs, "__call__", counted)
    summarize(model, result, 0.0, options, "idas")
    assert len(calls) == len(result.segments)                        # the summary read nothing it did not load
    for seg in result.segments:                                       # and left the other outputs alone
        assert set(seg.outputs.evaluated()) == set(summary_outputs(model)) & set(seg.outputs)
    calls.clear()
    first = result["w_in_rad_s"]
    assert calls == [("w_in_rad_s",)] * len(result.segments)
    calls.clear()
    again = result["w_in_rad_s"]
    result["total_torque_Nm"]                                        # loaded by the summary
    result.load(summary_outputs(model))
    assert calls == []
    assert np.array_equal(first, again)
    seg = result.segments[0]
    assert seg.outputs["w_in_rad_s"] is seg.outputs["w_in_rad_s"]      # kept, not evaluated again


def test_results_pickle_with_every_output(driveline):
    model, _ = driveline
    run = simulate_engagement(model.scene, model=model)
    copy = pickle.loads(pickle.dumps(run.result))
    assert isinstance(copy, SimulationResult) and copy.names() == run.result.names()
    for seg in copy.segments:
        assert type(seg.outputs) is dict
    for name in run.result.names():
        assert np.array_equal(copy[name], run.result[name], equal_nan=True), name


def test_stitched_closed_loop_result_equals_eager_evaluation():
    """A closed-loop run (pieces of a few samples under a command that changes every controller sample,
    stitched with ``SimulationResult.from_segments``): its outputs equal the eager evaluation, and the
    summary of the stitched result is the one of its values."""
    from clutchocp.shiftcontrol.closed_loop import run_closed_loop
    from clutchocp.shiftcontrol.controller import SlipFeedback
    from clutchocp.optimal.replay import CommandModel

    scene = load_scene("default_driveline").without_uncertainty()
    N = 25                  # 0.25 s of 10 ms samples; no gains: the command is the feedforward ramp, in pieces
    feedback = SlipFeedback(sample_time=0.01, gains=np.zeros((N, 3)), integral_gains=np.zeros(N),
                            reference=np.zeros((N + 1, 3)), slip_reference=np.zeros(N + 1),
                            measured=("slip_rate", "w_in", "w_out"), feedforward=([0.0, 0.03], [0.0, 8e5]),
                            p_min=0.0, p_max=2e6, rate_limit=1e9)
    model = CommandModel(scene, "linear")
    run, tcu = run_closed_loop(scene, feedback, 0.2, model=model)
    result = run.result
    assert len(result.segments) > 10 and tcu["handover_s"] is not None and result.final_mode.endswith("locked")
    _check_against_eager(model.hybrid, result, _one_by_one)
    summary = summarize(model.engagement, result, 0.0, SimulationOptions(), "idas")
    for key in ("peak_torque_Nm", "peak_jerk_rad_s3", "dissipated_energy_J", "min_film_pressure_Pa"):
        assert summary[key] == run.summary[key], key


def test_a_subset_takes_the_numpy_form_only_where_the_full_function_does():
    """A subset of the outputs is evaluated the way all of them would be: by numpy only if the full
    function has a numpy form (here it has none: erfinv), so its values are bit for bit the full ones."""
    xs, zs, pu, t = ca.SX.sym("xs", 2), ca.SX.sym("zs", 0), ca.SX.sym("pu", 0), ca.SX.sym("t")
    first = ca.exp(-xs[0]) * xs[1] + ca.sin(t)
    args = [xs, zs, pu, t]
    samples = (np.vstack([np.linspace(0, 1, 700), np.linspace(1, 2, 700)]), np.zeros((0, 700)), np.zeros(0),
               np.linspace(0, 3, 700))
    for second, numpy_form in ((ca.erfinv(xs[0] / 2), False), (ca.erf(xs[0] / 2), True)):
        full = ColumnFunction(ca.Function("f_outputs", args, [ca.vertcat(first, second)]))
        subset = ColumnFunction(ca.Function("f_outputs_1", args, [first]), like=full)
        assert np.array_equal(subset(*samples)[0], full(*samples)[0])
        assert (subset._numpy is not None) == numpy_form and (full._numpy is not None) == numpy_form


def test_events_and_outputs_evaluated_together_change_nothing(driveline, monkeypatch):
    """On the locked segment's grid (numpy form) the event functions are evaluated with the outputs in one
    function: the same event values (so the same run) and the same outputs as apart."""
    from clutchocp.simulation.compiled import CompiledMode

    model, _ = driveline
    compiled = model.hybrid.compiled()
    locked, slipping = compiled["pressing_locked"], compiled["pressing_slip_forward"]
    together = simulate_engagement(model.scene, model=model)
    seg = next(s for s in together.result.segments if s.mode == "pressing_locked")
    # used on this run, the samples before the first call's (the segment's start) in the same call
    assert all(b[4] is not None for run in seg.outputs._evaluate.runs for b in run[2])
    merged = locked.events_outputs(seg.t.size)
    assert merged is not None and slipping.events_outputs(200) is None                   # slipping: CasADi's map
    kept = seg.outputs._evaluate
    pu = kept.runs[0][0]
    both = merged.on_numpy(kept.xs, kept.zs, pu, seg.t)
    n_events = len(locked.events)
    assert np.array_equal(both[:n_events], locked.events_on(kept.xs, kept.zs, pu, seg.t), equal_nan=True)
    assert np.array_equal(both[n_events:], locked.outputs_on(kept.xs, kept.zs, pu, seg.t), equal_nan=True)
    monkeypatch.setattr(CompiledMode, "events_outputs", lambda self, n: None)
    apart = simulate_engagement(model.scene, model=EngagementModel(model.scene))
    assert together.summary["solver"]["statistics"]["n_steps"] == apart.summary["solver"]["statistics"]["n_steps"]
    a, b = together.series(), apart.series()
    for name in a:
        if name != "mode":
            assert np.array_equal(a[name], b[name], equal_nan=True), name
