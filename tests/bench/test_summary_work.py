"""clutchocp.bench.summary_work: the summary computed from a run's samples alone is the run's own, and
nothing the run evaluated is carried over."""

import pytest

from clutchocp.bench.summary_work import summary_time, unevaluated
from clutchocp.errors import ClutchocpError


def _without_timing(summary):
    return {k: v for k, v in summary.items() if k not in ("wall_time_s", "solver")}   # solver: options, statistics


def test_summary_from_the_samples_alone_is_the_runs_own(zhang_run):
    _, _, run = zhang_run
    seconds, summary = summary_time(run, repeats=2)
    assert seconds > 0
    assert _without_timing(summary) == _without_timing(run.summary)


def test_fresh_outputs_start_unevaluated_and_equal_the_runs(zhang_run):
    _, _, run = zhang_run
    fresh = unevaluated(run)
    assert all(not seg.outputs.evaluated() for seg in fresh.segments)
    for name in ("total_torque_Nm", "output_jerk_rad_s3", "film_1_fluid_force_N"):
        assert (fresh[name] == run.result[name]).all()
    assert all(seg.outputs.evaluated() for seg in fresh.segments)


def test_a_run_that_let_its_samples_go_needs_the_evaluators_taken_before(zhang_run_let_go):
    run, kept = zhang_run_let_go
    with pytest.raises(ClutchocpError, match="let its samples go"):
        unevaluated(run)
    assert _without_timing(summary_time(run, repeats=1, kept=kept)[1]) == _without_timing(run.summary)
